"""Run an exported SSP package in OpenModelica's OMSimulator, and read its result file.

OMSimulator is used from a build folder ``home`` holding bin/OMSimulator (its command line)
and lib/x86_64-linux-gnu/OMSimulator (its Python API), each run in a child process with a
time limit. What each interface takes of a package, and why a String binding is refused:
docs/interop.md. The result CSV holds each communication point twice (after the step and
after the exchange of inputs); ``read_result`` keeps the last.
"""
from __future__ import annotations

import csv
import os
import subprocess
import sys
import sysconfig
import tempfile
from pathlib import Path

import numpy as np

from .engines import EngineError, log_summary
from .ssp import read_package, unapplied_strings

INTERFACES = ("cli", "api")

_API = """import sys
from OMSimulator import SSP
ssp, result, step, temp = sys.argv[1:]
model = SSP(ssp, temp_dir=temp).instantiate()
model.setResultFile(result)
model.setFixedStepSize(float(step))
model.initialize()
model.simulate()
model.terminate()
model.delete()
"""


def libpython() -> str:
    """The path of this interpreter's libpython, for a C++ host's LD_PRELOAD."""
    return os.path.join(sysconfig.get_config_var("LIBDIR"), sysconfig.get_config_var("LDLIBRARY"))


def command(home: Path, interface: str, ssp: Path, result: Path, temp: Path
            ) -> tuple[list[str], dict[str, str]]:
    """The child's command line and environment of a run of ``ssp`` writing ``result``."""
    system = read_package(ssp)
    site = sysconfig.get_paths()["purelib"]
    if interface == "cli":
        return ([str(home / "bin" / "OMSimulator"), f"--stopTime={system.stop_time!r}",
                 f"--startTime={system.start_time!r}", f"--resultFile={result}",
                 f"--tempDir={temp}", str(ssp)],
                {"LD_PRELOAD": libpython(), "PYTHONPATH": site})
    return ([sys.executable, "-c", _API, str(ssp), str(result), repr(system.step_size),
             str(temp)], {"PYTHONPATH": os.pathsep.join([str(home / "lib" / "x86_64-linux-gnu"),
                                                          site])})


def read_result(path: Path) -> dict[str, np.ndarray]:
    """An OMSimulator result CSV: 'time' and each variable as 'component.variable', one row
    per communication point (the last of the rows written at that time)."""
    with open(path, newline="") as f:
        rows = list(csv.reader(f))
    names = ["time"] + [".".join(h.split(".")[-2:]) for h in rows[0][1:]]
    last = {float(row[0]): row for row in rows[1:]}
    table = np.array([[float(v) for v in row] for row in last.values()])
    return dict(zip(names, table.T))


def run(ssp: str | Path, home: str | Path, interface: str = "cli",
        timeout: float = 600.0) -> dict[str, np.ndarray]:
    """Run the package ``ssp`` in OMSimulator at ``home`` through ``interface`` ('cli' or
    'api'); EngineError with its output if it fails, runs out of ``timeout`` seconds,
    or would drop a String binding; ValueError for an unknown interface."""
    if interface not in INTERFACES:
        raise ValueError(f"interface must be one of {', '.join(INTERFACES)}, got {interface!r}")
    ssp, home = Path(ssp).resolve(), Path(home).resolve()
    dropped = unapplied_strings(ssp)
    if dropped:
        raise EngineError("OMSimulator applies no String binding; it would run " + ", ".join(
            f"{v} = {default!r}, not {value!r}" for v, (value, default) in dropped.items()))
    with tempfile.TemporaryDirectory() as tmp:
        result = Path(tmp) / "result.csv"
        argv, env = command(home, interface, ssp, result, Path(tmp))
        try:
            child = subprocess.run(argv, cwd=tmp, env={**os.environ, **env}, timeout=timeout,
                                   capture_output=True, text=True, check=False)
        except subprocess.TimeoutExpired as expired:
            raise EngineError(f"OMSimulator ({interface}) did not finish {ssp.name} within "
                              f"{timeout:g} s") from expired
        log = log_summary(child.stdout + child.stderr)
        if child.returncode != 0 or not result.exists():
            raise EngineError(f"OMSimulator ({interface}) failed on {ssp.name} (exit status "
                              f"{child.returncode}):\n{log}")
        trace = read_result(result)
    bad = [name for name, values in trace.items() if not np.isfinite(values).all()]
    if bad:
        raise EngineError(f"OMSimulator ({interface}) reported success, but {', '.join(bad)} "
                          f"read NaN: an FMU failed.\n{log}")
    return trace
