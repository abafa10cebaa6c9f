"""An FMU instantiated once in a child process: does it start, here or away from the checkout?

Some FMUs take their host down when they cannot instantiate (pythonfmu 0.7's C++
dereferences a NULL class when its Python script fails to import), so the try is a
child's, and the caller lives to say what happened. ``isolated`` leaves this checkout
off the child's import path, as on a host that has only the FMU: a module the FMU
forgot to carry is missing there.
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
description = read_model_description(sys.argv[1])
unzipped = extract(sys.argv[1], os.path.abspath("unzipped"))  # in the child's folder: removed
slave = FMU2Slave(guid=description.guid, unzipDirectory=unzipped,
                  modelIdentifier=description.coSimulation.modelIdentifier,
                  instanceName="trial")
slave.instantiate(loggingOn=True)     # pythonfmu 0.7 logs only then
slave.freeInstance()
"""


class TrialFailed(RuntimeError):
    """The FMU did not instantiate, or took its host down: ``crashed`` names the signal
    (None if it failed), ``last_words`` are the child's last lines (the FMU's first)."""

    def __init__(self, fmu: Path, returncode: int, last_words: list[str]):
        self.fmu, self.last_words = fmu, last_words
        self.crashed = signal.Signals(-returncode).name if returncode < 0 else None
        how = f"crashed its host ({self.crashed})" if self.crashed else "failed"
        super().__init__(f"{fmu}: instantiating the FMU {how}"
                         + "".join(f"\n  {line}" for line in last_words))


def trial(fmu: str | Path, isolated: bool = False, timeout: float = 120.0) -> None:
    """Instantiate and free ``fmu`` in a child process; TrialFailed if that fails. The
    child is killed after ``timeout`` seconds (subprocess.TimeoutExpired)."""
    fmu = Path(fmu).resolve()
    with tempfile.TemporaryDirectory() as elsewhere:
        child = subprocess.run([sys.executable, "-c", _CHILD.format(root=str(ROOT)), str(fmu),
                                "isolated" if isolated else "here"],
                               cwd=elsewhere, capture_output=True, text=True, timeout=timeout)
    if child.returncode != 0:
        said = [line for line in child.stdout.splitlines() if line.strip()][-3:]  # the FMU's
        raise TrialFailed(fmu, child.returncode, said or [
            line for line in child.stderr.splitlines() if line.strip()][-3:])
