"""Run an SSP package in OMSimulator (a build folder), its command line or Python API, in a
child process with a time limit (docs/interop.md)."""
from __future__ import annotations

import os
import sys
import sysconfig
import tempfile
from pathlib import Path

import numpy as np

from .engines import child_trace, refuse_strings
from .ssp import read_package

_API = """import sys
from OMSimulator import SSP
ssp, result, step, temp = sys.argv[1:]
model = SSP(ssp, temp_dir=temp).instantiate()
model.setResultFile(result)
model.setFixedStepSize(float(step))
for call in (model.initialize, model.simulate, model.terminate, model.delete):
    call()
"""


def read_result(path: Path) -> dict[str, np.ndarray]:
    """'time' and each 'component.variable' of a result CSV, at each time its last row."""
    header = path.read_text().split("\n", 1)[0].replace('"', "").split(",")
    table = np.loadtxt(path, delimiter=",", skiprows=1, ndmin=2)
    last = np.append(table[1:, 0] != table[:-1, 0], True)      # the last row of each time
    return dict(zip(["time"] + [".".join(h.split(".")[-2:]) for h in header[1:]], table[last].T))


def run(ssp: str | Path, home: str | Path, interface: str = "cli",
        timeout: float = 600.0) -> dict[str, np.ndarray]:
    """The trace of ``ssp`` run in OMSimulator at ``home``, or EngineError with its output."""
    if interface not in ("cli", "api"):
        raise ValueError(f"interface must be one of cli, api, got {interface!r}")
    ssp, home = Path(ssp).resolve(), Path(home).resolve()
    refuse_strings(ssp, "OMSimulator")
    system, site = read_package(ssp), sysconfig.get_paths()["purelib"]
    with tempfile.TemporaryDirectory() as tmp:
        result = Path(tmp) / "result.csv"
        if interface == "cli":              # its Python FMUs need libpython loaded first
            argv = [str(home / "bin" / "OMSimulator"), f"--stopTime={system.stop_time!r}",
                    f"--startTime={system.start_time!r}", f"--resultFile={result}",
                    f"--tempDir={tmp}", str(ssp)]
            env = {"LD_PRELOAD": os.path.join(sysconfig.get_config_var("LIBDIR"),
                                              sysconfig.get_config_var("LDLIBRARY")),
                   "PYTHONPATH": site}
        else:
            argv = [sys.executable, "-c", _API, str(ssp), str(result), repr(system.step_size), tmp]
            env = {"PYTHONPATH": os.pathsep.join([str(home / "lib" / "x86_64-linux-gnu"), site])}
        return child_trace(f"OMSimulator ({interface})", ssp, argv, result, read_result,
                           timeout, cwd=tmp, env={**os.environ, **env})
