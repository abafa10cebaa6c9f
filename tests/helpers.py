"""Helpers shared by the tests."""
from __future__ import annotations

import csv
import ctypes.util
import importlib.util
import subprocess
import sys
import time
from pathlib import Path


WAVE_DIGESTS = {0: "8c8ded2e7a2092c0", 7: "f9203af72900f20e"}
"""SHA-256 (first 16 hex digits) of the sea of seeds 0 and 7 at Hs = 5 cm, T0 = 0.8 s."""


def wave_digest(seed: int) -> str:
    """The frequencies, wave numbers, amplitudes and phases of a seed's sea, by SHA-256."""
    import hashlib

    import numpy as np

    from ship_fmu.waves import WaveComponents

    c = WaveComponents.from_spectrum(0.05, 0.8, 50, seed)
    arrays = (c.omega, c.k, c.amplitude, c.phase)
    return hashlib.sha256(b"".join(np.asarray(a, "<f8").tobytes() for a in arrays)
                          ).hexdigest()[:16]


def ecos_missing() -> str | None:
    """Why the ecos tests cannot run here (None if they can)."""
    if importlib.util.find_spec("ecospy") is None:
        return "ecospy is not installed (pip install -e '.[engines]')"
    if ctypes.util.find_library("tbb") is None:
        return "ecos needs Debian's libtbb12 (setup.sh installs it where apt-get is available)"
    return None


def fmpy_cli(*args: str, cwd: Path) -> None:
    """Run fmpy's command line in a subprocess, isolated (``-I``): no PYTHONPATH or working
    folder on its path, so that a Python FMU runs the modules it carries, not a checkout's."""
    subprocess.run([sys.executable, "-I", "-m", "fmpy.cli", *args], cwd=cwd, check=True,
                   capture_output=True, text=True, timeout=120)


def read_csv(path: Path) -> list[dict[str, float]]:
    with open(path) as f:
        return [{k: float(v) for k, v in row.items()} for row in csv.DictReader(f)]


def fmu_variant(source: Path, dest: Path, xml=None, drop: tuple[str, ...] = (),
                edit: dict | None = None) -> Path:
    """A copy of an FMU with its modelDescription.xml passed through ``xml`` (text -> text),
    the members starting with any of ``drop`` left out, and members named in ``edit``
    passed through its function (text -> text)."""
    import zipfile

    edit = {**(edit or {}), **({"modelDescription.xml": xml} if xml is not None else {})}
    with zipfile.ZipFile(source) as original, zipfile.ZipFile(dest, "w") as copy:
        for info in original.infolist():
            if info.filename.startswith(drop):
                continue
            data = original.read(info)
            if info.filename in edit:
                data = edit[info.filename](data.decode("utf-8")).encode("utf-8")
            copy.writestr(info, data)
    return dest


def reference_seconds(folder: Path) -> float:
    """How long this machine takes now to start a child Python that runs calm_pd for 5 s
    and writes it: what every child of a timing test does besides the fault it tests.
    Bounds on wall time scale with it, so a busy machine widens them instead of failing."""
    started = time.monotonic()
    subprocess.run([sys.executable, "-m", "cosim.run", "calm_pd", "--stop-time", "5",
                    "--no-plot", "--backend", "inprocess", "--out", str(folder)],
                   check=True, capture_output=True, timeout=600)
    return time.monotonic() - started


def command(main, *args: str) -> subprocess.CompletedProcess:
    """A command's ``main(args)`` run in this process, as a child's result: its exit status
    and what it printed (for tests of what a command says, not of processes)."""
    import contextlib
    import io

    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        try:
            status = main(list(args))
        except SystemExit as exit_:           # argparse's refusals
            status = exit_.code if isinstance(exit_.code, int) else 1
    return subprocess.CompletedProcess(["main", *args], status, out.getvalue(), err.getvalue())


_recordings: dict = {}


def recorded(name: str, fmi: int = 2, coupling: str = "gauss-seidel", backend: str = "fmi",
             **master: object):
    """A scenario's run on this project's FMUs of FMI version ``fmi``, by the master with
    these settings, recorded once a test process (several test files look at the same runs;
    treat it as read-only)."""
    from cosim import scenarios
    from cosim.core.master import Master

    key = (name, fmi, coupling, backend, tuple(sorted(master.items())))
    if key not in _recordings:
        with Master(scenarios.load(name, fmi=fmi), coupling=coupling, backend=backend,
                    **master) as runner:
            recording = runner.run()
        assert recording.error is None, recording.error
        _recordings[key] = recording
    return _recordings[key]


def fault_system(path: Path, fault: Path, ship: Path, number: int, stop_time: float,
                 description: str) -> Path:
    """An .ssd at ``path``: the ship steered by the fault FMU (``faulty/fault_slave.py``),
    which goes wrong as ``fault`` ``number`` says at t = 5 s."""
    from cosim.core.ssd import Component, Connection, SystemDescription, write_ssd

    system = SystemDescription(
        path.stem, {"fault": Component("fault", str(fault),
                                       {"psi": ("input", "Real"), "delta_c": ("output", "Real"),
                                        "n1": ("output", "Real")},
                                       {"fault_time": 5.0, "fault": number}),
                    "ship": Component("ship", str(ship),
                                      {"delta_c": ("input", "Real"), "n1": ("input", "Real"),
                                       "psi": ("output", "Real")}, {})},
        [Connection("ship", "psi", "fault", "psi"),
         Connection("fault", "delta_c", "ship", "delta_c"),
         Connection("fault", "n1", "ship", "n1")],
        stop_time=stop_time, report="none", description=description)
    write_ssd(system, path)
    return path
