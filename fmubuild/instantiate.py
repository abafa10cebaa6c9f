"""An FMU instantiated once in a child process (pythonfmu's C++ takes its host down when the
script fails to import), with fmpy; ``isolated`` leaves this checkout off the child's path,
as on a host that has only the FMU.
"""
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
from fmpy import extract, read_model_description
from fmpy.fmi2 import FMU2Slave
from fmpy.fmi3 import FMU3Slave
description = read_model_description(sys.argv[1])
unzipped = extract(sys.argv[1], os.path.abspath("unzipped"))  # in the child's folder: removed
slave = (FMU3Slave if description.fmiVersion.startswith("3") else FMU2Slave)(
    guid=description.guid, unzipDirectory=unzipped,
    modelIdentifier=description.coSimulation.modelIdentifier, instanceName="trial")
slave.instantiate(loggingOn=True)     # pythonfmu 0.7 logs only then
slave.freeInstance()
"""


class InstantiationFailed(RuntimeError):
    """The FMU did not instantiate: ``crashed`` names the signal, ``timed_out`` the limit
    (s), ``last_words`` are the child's last lines (the FMU's, else Python's)."""

    def __init__(self, fmu: Path, returncode: int | None, out: str | bytes | None,
                 err: str | bytes | None, timed_out: float | None = None):
        self.last_words = _last_lines(out) or _last_lines(err)
        self.timed_out = timed_out
        self.crashed = signal.Signals(-returncode).name if returncode and returncode < 0 \
            else None
        how = (f"did not end within {timed_out:g} s (the child was killed)" if timed_out
               else f"crashed its host ({self.crashed})" if self.crashed else "failed")
        super().__init__(f"{fmu}: instantiating the FMU {how}"
                         + "".join(f"\n  {line}" for line in self.last_words))


def _last_lines(text: str | bytes | None) -> list[str]:
    if isinstance(text, bytes):
        text = text.decode(errors="replace")
    return [line for line in (text or "").splitlines() if line.strip()][-3:]


def instantiate_in_child(fmu: str | Path, isolated: bool = False, timeout: float = 120.0) -> None:
    """Instantiate and free ``fmu`` in a child process; InstantiationFailed if that fails,
    or if it has not ended after ``timeout`` seconds (the child is killed then)."""
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
