"""An FMU instantiated once with fmpy in a child process, since pythonfmu's C++ takes its
host down when the script fails to import."""
from __future__ import annotations

import signal
import subprocess
import sys
import tempfile
from pathlib import Path

from .project import ROOT

_CHILD = """
import os
import sys
if sys.argv[2] == "isolated":
    sys.path = [p for p in sys.path if p not in ("", {root!r})]
    sys.meta_path = [f for f in sys.meta_path if "editable" not in repr(f).lower()]
from fmpy import extract, instantiate_fmu, read_model_description
unzipped = extract(sys.argv[1], os.path.abspath("unzipped"))  # in the child's folder: removed
instantiate_fmu(unzipped, read_model_description(sys.argv[1]), "CoSimulation",
                debug_logging=True).freeInstance()            # pythonfmu 0.7 logs only then
"""


class InstantiationFailed(RuntimeError):
    """The FMU did not instantiate: ``crashed`` names the signal, ``timed_out`` the limit
    (s), ``last_words`` are the child's last lines (the FMU's, else Python's)."""

    def __init__(self, fmu: Path, returncode: int | None, out: str | bytes | None,
                 err: str | bytes | None, timed_out: float | None = None):
        self.last_words, self.timed_out = _last_lines(out) or _last_lines(err), timed_out
        self.crashed = signal.Signals(-returncode).name if (returncode or 0) < 0 else None
        how = (f"did not end within {timed_out:g} s (the child was killed)" if timed_out
               else f"crashed its host ({self.crashed})" if self.crashed else "failed")
        super().__init__(f"{fmu}: instantiating the FMU {how}"
                         + "".join(f"\n  {line}" for line in self.last_words))


def _last_lines(text: str | bytes | None) -> list[str]:
    if isinstance(text, bytes):         # what a killed child had written
        text = text.decode(errors="replace")
    return [line for line in (text or "").splitlines() if line.strip()][-3:]


def instantiate_in_child(fmu: str | Path, isolated: bool = False, timeout: float = 120.0) -> None:
    """Instantiate and free ``fmu`` in a child process (``isolated``: without this checkout,
    as on a host); InstantiationFailed if that fails or outlasts ``timeout`` (s)."""
    fmu = Path(fmu).resolve()
    with tempfile.TemporaryDirectory() as elsewhere:
        try:
            child = subprocess.run([sys.executable, "-c", _CHILD.format(root=str(ROOT)),
                                    str(fmu), "isolated" if isolated else "here"],
                                   cwd=elsewhere, capture_output=True, text=True,
                                   timeout=timeout)
        except subprocess.TimeoutExpired as expired:
            raise InstantiationFailed(fmu, None, expired.stdout, expired.stderr,
                                      timeout) from None
    if child.returncode != 0:
        raise InstantiationFailed(fmu, child.returncode, child.stdout, child.stderr)
