"""The fault matrix: every fault, in every host, ends in a failure the user is told of.

Faults, from 5 s of a 10 s run (1000 s for signals and hangs, so that a host that
ignored one would be seen finishing; the fault FMU, ``tests/faulty/fault_slave.py``,
as component "fault", drives the ship's rudder and propeller): a NaN input, an input
out of its range, an invalid parameter (the ship's Hs = -1, at t = 0), an exception
in a model, SIGINT and SIGTERM arriving while FMU code runs (the fault FMU signals
its own process), a corrupt (truncated) FMU or package, and a step that never
returns, looping in Python ('loop') or waiting in C ('block'): only our master has
a step time limit (``cosim.core.watchdog``), so the hangs are its cells alone.

Hosts: our master (FMI and in-process backends), fmpy's command line, its Python
API and its SSP runner, libcosim (a libcosimpy script, and ``cosim.engines``), ecos
(an ecospy script, ``cosim.engines``, and the ``ecos`` program with LD_PRELOAD as
README says).

FMI 3.0: the same faults but the corrupt file (``FMI3_FAULTS``), with the ship's twin and
the fault FMU built as FMI 3.0, in every host that runs FMI 3.0 FMUs (``FMI3_HOSTS``: not
fmpy's SSP runner nor libcosim); cells named fmi3-<host>-<fault>. The same must show, a
refused step being fmi3Error where FMI 2.0's is fatal; an invalid parameter's message
names exitInitializationMode where FMI 2.0's names t = 0 (pythonfmu3 drops the start time).

What every cell must show, without any flag or environment variable set: no crash
(no SIGSEGV, SIGABRT...) and no hang; a non-success (exit status, exception, or a
failed libcosim step), except where the host ignores FMI statuses (an ecospy
script, the ``ecos`` program), whose trace must then read NaN; a message naming the
FMU, the variable (or the model's error) and the time. A signal ends the host as
that signal does: our commands with 130 or 143 and "interrupted", other hosts
killed by it (or, Python's way, by the KeyboardInterrupt). A corrupt file is the
host's own error, naming the file where the host does. docs/robustness.md has the
table. Each cell is a child process with a time limit; the selected cells run two
at a time, once per session (``outcomes``).

The quick suite (without ``pytest --long``) runs every host and every fault at least once in
each FMI version (``QUICK``): host k of HOSTS with the fault it runs that the fewest cells
so far have run (fault k of FAULTS first), then each fault no host has run yet (the hangs,
which only our master has a limit for) with one of the hosts that run it. ``pytest --long``
runs every cell.
"""
from __future__ import annotations

import json
import os
import re
import signal
import subprocess
import sys
import sysconfig
import time
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass, field
from pathlib import Path
from typing import Callable

import pytest

from cosim.core.ssd import Component, Connection, SystemDescription, write_ssd
from cosim.interop.ssp import export
from fmubuild.project import ROOT

FAULTS = ("nan", "range", "parameter", "exception", "sigint", "sigterm", "corrupt", "loop",
          "block")
HOSTS = ("master-fmi", "master-inprocess", "fmpy-cli", "fmpy-api", "fmpy-ssp",
         "libcosim-script", "libcosim-cli", "ecos-script", "ecos-cli", "ecos-program")
OURS = ("master-fmi", "master-inprocess", "libcosim-cli", "ecos-cli")
IGNORES_STATUS = ("ecos-script", "ecos-program")
NOT_APPLICABLE = {   # the in-process backend runs this project's own FMU classes only
    ("master-inprocess", "exception"): "runs only this project's FMU classes",
    ("master-inprocess", "corrupt"): "loads no FMU file",
}
HANGS = ("loop", "block")
NOT_APPLICABLE.update({(host, fault): "has no time limit: waits as long as the FMU computes"
                       for host in HOSTS if not host.startswith("master") for fault in HANGS})
FMI3_HOSTS = ("master-fmi", "master-inprocess", "fmpy-cli", "fmpy-api", "ecos-script",
              "ecos-cli", "ecos-program")
"""The hosts that run FMI 3.0 FMUs (fmpy's SSP runner and libcosim run FMI 2.0 only:
docs/interop.md)."""
FMI3_FAULTS = tuple(f for f in FAULTS if f != "corrupt")
"""The faults repeated with the FMI 3.0 twins: all but a corrupt file, which every host fails
to unzip before it could read the FMI version."""
MATRIX = {2: (HOSTS, FAULTS), 3: (FMI3_HOSTS, FMI3_FAULTS)}
"""FMI version: its hosts and faults."""
CELLS = [(h, f, fmi) for fmi, (hosts, faults) in MATRIX.items() for h in hosts
         for f in faults if (h, f) not in NOT_APPLICABLE]
IDS = [f"{h}-{f}" if fmi == 2 else f"fmi3-{h}-{f}" for h, f, fmi in CELLS]


def _covering(fmi: int) -> list[tuple[str, str, int]]:
    """The quick suite's cells of one FMI version: host k with the fault it runs that the
    cells so far have run least (the k-th of FAULTS first, then the next), then each fault
    no host has run yet with one of the hosts that run it."""
    hosts, faults = MATRIX[fmi]
    runs = [(h, f, fmi) for h in hosts for f in faults if (h, f) not in NOT_APPLICABLE]
    cells: list[tuple[str, str, int]] = []
    for k, host in enumerate(hosts):
        used = [f for _, f, _ in cells]
        cells.append(min((c for c in runs if c[0] == host), key=lambda c: (
            used.count(c[1]), (faults.index(c[1]) - k) % len(faults))))
    for k, fault in enumerate(faults):
        if fault not in {f for _, f, _ in cells}:
            cells.append([c for c in runs if c[1] == fault][k % 2])
    return cells


QUICK = _covering(2) + _covering(3)
KIND = {"nan": 1, "range": 2, "parameter": 0, "exception": 3, "sigint": 4, "sigterm": 5,
        "loop": 6, "block": 7}
STEP_TIMEOUT = "2"
CRASHES = {signal.SIGSEGV, signal.SIGABRT, signal.SIGBUS, signal.SIGILL, signal.SIGFPE}
FAULT_TIME = 5.0
T5 = r"t = (5(\.0*)?|4\.9999\d*)( s)?\b"       # ecos's time is a sum of floats
T0 = r"t = 0(\.0*)?( s)?\b"
FMI3_REFUSED_STEP = {"master-fmi": r"FMU '\w+': doStep at t = [\d.]+ s returned error\b",
                     "fmpy-cli": r"fmi3DoStep failed with status 3 \(error\)",
                     "fmpy-api": r"fmi3DoStep failed with status 3 \(error\)"}
"""How a host that shows statuses tells a twin's refused step: fmi3Error, not fatal."""
AT_INITIALISATION = r"\bexitInitializationMode: "
"""What an FMI 3.0 twin's invalid parameter names in place of t = 0: pythonfmu3 drops the
start time fmi3EnterInitializationMode gives."""
# What the message must name, on one line: the FMU, the variable or error, the time.
NAMES = {"nan": ("ship", "delta_c", T5), "range": ("ship", "n1", T5),
         "parameter": ("ship", "Hs", T0), "exception": ("fault", "injected fault", T5)}
INPROCESS_SET = {"nan": "ship.n3=nan", "range": "ship.n1=100", "parameter": "ship.Hs=-1"}
BEFORE = r"is (not a number|outside its declared range)"  # checked before any FMU call
INPROCESS_NAMES = {"nan": ("ship", "n3", BEFORE), "range": ("ship", "n1", BEFORE),
                   "parameter": ("ship", "Hs", BEFORE)}
TIME_LIMIT = 120.0
FAULTY = Path(__file__).parent / "faulty"
PY = sys.executable

FMPY_API = """import sys, json, numpy as np
from fmpy import simulate_fmu
fmu, options = sys.argv[1], json.loads(sys.argv[2])
if "input" in options:
    options["input"] = np.genfromtxt(options["input"], delimiter=",", names=True)
result = simulate_fmu(fmu, stop_time=float(sys.argv[3]), **options)
print("last row:", result[-1])
"""
FMPY_SSP = """import sys, json
from fmpy.ssp.simulation import simulate_ssp
from fmpy.ssp.ssd import Parameter, ParameterSet
parameters = ParameterSet()
for name, value in json.loads(sys.argv[2]).items():
    parameters.parameters.append(Parameter(name=name, type=type(value).__name__, value=value))
result = simulate_ssp(sys.argv[1], stop_time=float(sys.argv[3]), step_size=0.1,
                      parameter_set=parameters)
print("last row:", result[-1])
"""
LIBCOSIM = """import sys
from libcosimpy.CosimExecution import CosimExecution
execution = CosimExecution.from_ssp_file(sys.argv[1])
for k in range(round(float(sys.argv[2]) * 10)):
    if not execution.step():
        sys.exit(f"libcosim: the step from t = {k / 10} s failed")
print("done")
"""
ECOS = """import sys
from ecospy import EcosSimulation
sim = EcosSimulation(step_size=0.1, ssp_path=sys.argv[1])
sim.init(parameter_set="scenario")
for _ in range(round(float(sys.argv[2]) * 10)):
    sim.step()
print("ship psi =", sim.get_real("ship::psi"))
"""


@dataclass
class Cell:
    """One child process: its command, and when to signal it (for the in-process cells)."""
    argv: list[str]
    cwd: Path
    env: dict[str, str] = field(default_factory=dict)
    signal_after: Callable[[], bool] | None = None    # send the fault's signal once true
    fault_signal: signal.Signals | None = None


@dataclass
class Outcome:
    returncode: int
    output: str             # standard output and error
    files: str              # the CSV files the host wrote, for NaN


@dataclass
class Files:
    """What the cells run: a system per fault, as .ssd and as package, and fmpy inputs, of
    FMUs of FMI version ``fmi``."""
    root: Path
    fmus: dict[str, Path]
    fmi: int

    def ssd(self, fault: str) -> Path:
        return self.root / f"{fault}.ssd"

    def package(self, fault: str) -> Path:
        return self.root / "packages" / f"{fault}.ssp"


def _system(ship: Path, fault_fmu: Path, fault: str) -> SystemDescription:
    ship_parameters = {"Hs": -1.0} if fault == "parameter" else {}
    return SystemDescription(
        fault, {"fault": Component("fault", str(fault_fmu),
                                   {"psi": ("input", "Real"), "delta_c": ("output", "Real"),
                                    "n1": ("output", "Real")},
                                   {"fault_time": FAULT_TIME, "fault": KIND[fault]}),
                "ship": Component("ship", str(ship),
                                  {"delta_c": ("input", "Real"), "n1": ("input", "Real"),
                                   "psi": ("output", "Real")}, ship_parameters)},
        [Connection("ship", "psi", "fault", "psi"),
         Connection("fault", "delta_c", "ship", "delta_c"),
         Connection("fault", "n1", "ship", "n1")],
        stop_time=_stop_time(fault), report="none", description=f"fault matrix: {fault}")


def _stop_time(fault: str) -> float:
    return 1000.0 if fault.startswith("sig") or fault in HANGS else 10.0


def _truncated(source: Path, target: Path) -> Path:
    data = source.read_bytes()
    target.write_bytes(data[: len(data) // 2])
    return target


def _files(ship: Path, root: Path, fmi: int, faulty_fmu) -> Files:
    """The systems of FMI version ``fmi``: this ship, and the fault FMU built as that version."""
    fault_fmu = faulty_fmu("fault", fmi)
    (root / "packages").mkdir()
    for fault in KIND:
        write_ssd(_system(ship, fault_fmu, fault), root / f"{fault}.ssd")
        export(root / f"{fault}.ssd", root / "packages")
    fmus = {"ship": ship, "fault": fault_fmu}
    if "corrupt" in MATRIX[fmi][1]:
        fmus["corrupt"] = _truncated(ship, root / "corrupt_ship.fmu")
        write_ssd(_system(fmus["corrupt"], fault_fmu, "exception"), root / "corrupt.ssd")
        _truncated(root / "packages" / "exception.ssp", root / "packages" / "corrupt.ssp")
    for fault, column, value in (("nan", "delta_c", "nan"), ("range", "n1", "100")):
        row = {"delta_c": "0.1", "n1": "8.13"}
        lines = ["time,delta_c,n1"]
        for t in (0.0, FAULT_TIME - 0.01):
            lines.append(f"{t},{row['delta_c']},{row['n1']}")
        row[column] = value
        for t in (FAULT_TIME, 10.0):
            lines.append(f"{t},{row['delta_c']},{row['n1']}")
        (root / f"{fault}.csv").write_text("\n".join(lines) + "\n")
    return Files(root, fmus, fmi)


@pytest.fixture(scope="session")
def files(fmu_paths, tmp_path_factory, faulty_fmu) -> Files:
    """The FMI 2.0 systems."""
    return _files(fmu_paths["ship"], tmp_path_factory.mktemp("fault_matrix"), 2, faulty_fmu)


@pytest.fixture(scope="session")
def files3(fmi3_paths, tmp_path_factory, faulty_fmu) -> Files:
    """The FMI 3.0 systems: the twins."""
    return _files(fmi3_paths["ship"], tmp_path_factory.mktemp("fault_matrix_fmi3"), 3,
                  faulty_fmu)


def _libpython() -> str:
    return os.path.join(sysconfig.get_config_var("LIBDIR"), sysconfig.get_config_var("LDLIBRARY"))


def _ecos_program() -> Path:
    import ecospy
    return Path(ecospy.__file__).parent / "binaries" / "ecos"


def _fmu_and_options(files: Files, fault: str) -> tuple[Path, dict]:
    """What a single-FMU host (fmpy) runs for a fault: the FMU and its options."""
    if fault in ("nan", "range"):
        return files.fmus["ship"], {"input": str(files.root / f"{fault}.csv")}
    if fault == "parameter":
        return files.fmus["ship"], {"start_values": {"Hs": -1.0}}
    if fault == "corrupt":
        return files.fmus["corrupt"], {}
    return files.fmus["fault"], {"start_values": {"fault": KIND[fault],
                                                  "fault_time": FAULT_TIME}}


def _parameters(fault: str) -> dict:
    """fmpy's SSP runner applies no bindings of its own: the package's values."""
    values = {"fault.fault": KIND.get(fault, 0), "fault.fault_time": FAULT_TIME}
    return {**values, "ship.Hs": -1.0} if fault == "parameter" else values


def cell(host: str, fault: str, files: Files, out: Path) -> Cell:
    """The command a user of ``host`` would run, for ``fault``."""
    package, stop = files.package(fault), f"{_stop_time(fault):g}"
    if host == "master-fmi" or (host == "master-inprocess" and fault in HANGS):
        ssd = files.root / ("corrupt.ssd" if fault == "corrupt" else f"{fault}.ssd")
        argv = [PY, "-m", "cosim.run", str(ssd), "--out", str(out), "--no-plot"]
        if fault in HANGS:          # the fault FMU's class importable: in-process too
            backend = host.split("-")[1]
            return Cell(argv + ["--step-timeout", STEP_TIMEOUT, "--backend", backend], ROOT,
                        env={"PYTHONPATH": os.pathsep.join([str(ROOT), str(FAULTY)])})
        return Cell(argv, ROOT)
    if host == "master-inprocess":
        argv = [PY, "-m", "cosim.run", "calm_pd", "--backend", "inprocess", "--out", str(out),
                "--no-plot", *(["--fmi", "3"] if files.fmi == 3 else [])]
        if fault in INPROCESS_SET:
            return Cell(argv + ["--stop-time", "10", "--set", INPROCESS_SET[fault]], ROOT)
        # a signal from outside, once rows are being written (into the run's hidden stage)
        return Cell(argv + ["--stop-time", "100000", "--stream"], ROOT,
                    signal_after=lambda: any(csv.stat().st_size > 2000 for csv in
                                             out.glob(".partial-calm_pd-*/calm_pd.csv")),
                    fault_signal=signal.Signals[f"SIG{fault[3:].upper()}"])
    if host in ("fmpy-cli", "fmpy-api"):
        fmu, options = _fmu_and_options(files, fault)
        if host == "fmpy-api":
            return Cell([PY, "-c", FMPY_API, str(fmu), json.dumps(options), stop], out)
        argv = [str(Path(PY).parent / "fmpy"), "simulate", str(fmu), "--stop-time", stop,
                "--output-file", str(out / "result.csv")]
        if "input" in options:
            argv += ["--input-file", options["input"]]
        if "start_values" in options:
            argv += ["--start-values", *(str(x) for item in options["start_values"].items()
                                         for x in item)]
        return Cell(argv, out)
    if host == "fmpy-ssp":
        return Cell([PY, "-c", FMPY_SSP, str(package), json.dumps(_parameters(fault)), stop],
                    out)
    if host == "libcosim-script":
        return Cell([PY, "-c", LIBCOSIM, str(package), stop], out)
    if host == "ecos-script":
        return Cell([PY, "-c", ECOS, str(package), stop], out)
    if host in ("libcosim-cli", "ecos-cli"):
        return Cell([PY, "-m", "cosim.engines", host.split("-")[0], str(package), "--out",
                     str(out / "trace.npz")], ROOT)
    if host == "ecos-program":
        site = sysconfig.get_paths()["purelib"]
        return Cell([str(_ecos_program()), "simulate", "--path", str(package), "--stepSize",
                     "0.1", "--stopTime", stop, "--parameterSet", "scenario"], out,
                    env={"LD_PRELOAD": _libpython(), "PYTHONPATH": site})
    raise ValueError(f"unknown host {host!r}")


def run_cell(spec: Cell) -> Outcome:
    """Run one cell in a child process, within TIME_LIMIT; what it printed and wrote."""
    spec.cwd.mkdir(parents=True, exist_ok=True)
    env = {**os.environ, **spec.env}
    with subprocess.Popen(spec.argv, cwd=spec.cwd, env=env, stdout=subprocess.PIPE,
                          stderr=subprocess.STDOUT, text=True,
                          start_new_session=True) as child:
        deadline = time.monotonic() + TIME_LIMIT
        if spec.signal_after is not None:
            while not spec.signal_after() and child.poll() is None \
                    and time.monotonic() < deadline:
                time.sleep(0.05)
            child.send_signal(spec.fault_signal)
        try:
            output, _ = child.communicate(timeout=max(1.0, deadline - time.monotonic()))
        except subprocess.TimeoutExpired:
            os.killpg(child.pid, signal.SIGKILL)
            output, _ = child.communicate()
            pytest.fail(f"{spec.argv[:4]}... still running after {TIME_LIMIT:g} s:\n{output}")
    written = "".join(p.read_text(errors="replace") for p in spec.cwd.glob("*.csv"))
    return Outcome(child.returncode, output, written)


def _cells(session: pytest.Session) -> list[tuple[str, str, int]]:
    """The (host, fault, FMI version) cells this session runs."""
    chosen = []
    for item in session.items:
        if item.originalname == "test_fault_matrix" and hasattr(item, "callspec"):
            chosen.append(tuple(item.callspec.params[k] for k in ("host", "fault", "fmi")))
    return chosen


@pytest.fixture(scope="session")
def outcomes(request, tmp_path_factory) -> dict[tuple[str, str, int], Outcome]:
    """Every selected cell, run two at a time (each is a child process)."""
    cells = _cells(request.session)
    systems = {fmi: request.getfixturevalue("files" if fmi == 2 else "files3")
               for fmi in sorted({c[2] for c in cells})}
    specs = {c: cell(c[0], c[1], systems[c[2]], tmp_path_factory.mktemp("-".join(map(str, c))))
             for c in cells}
    with ThreadPoolExecutor(max_workers=2) as pool:
        futures = {c: pool.submit(run_cell, spec) for c, spec in specs.items()}
        return {c: future.result() for c, future in futures.items()}


def _status(returncode: int) -> str:
    return (f"killed by {signal.Signals(-returncode).name}" if returncode < 0
            else f"exit status {returncode}")


def _named(output: str, fmu: str, what: str, when: str) -> bool:
    """Whether one line of the output names the FMU, the variable or error, and the time."""
    return any(fmu in line and what in line and re.search(when, line)
               for line in output.splitlines())


@pytest.mark.parametrize("host, fault, fmi", [
    pytest.param(*c, id=i, marks=() if c in QUICK else pytest.mark.long)
    for c, i in zip(CELLS, IDS)])
def test_fault_matrix(host, fault, fmi, outcomes):
    result = outcomes[(host, fault, fmi)]
    said = f"{host} / {fault} / FMI {fmi}: {_status(result.returncode)}\n{result.output[-3000:]}"
    code = result.returncode
    assert -code not in CRASHES and code - 128 not in CRASHES, said
    if fault.startswith("sig"):
        number = signal.Signals[f"SIG{fault[3:].upper()}"]
        if host in OURS:
            assert code == 128 + number and "interrupted" in result.output, said
            if host.startswith("master"):
                assert re.search(r"interrupted at t = [\d.]+ s, \d+ rows kept", result.output)
        else:                              # Python re-raises an uncaught KeyboardInterrupt
            assert code == -number, said
        return
    if fault in HANGS:                     # ends at the step time limit, rows and all
        assert code == 1 and "Traceback" not in result.output, said
        assert re.search(rf"error: the step at {T5} did not end within the step time limit of "
                         rf"{STEP_TIMEOUT} s \(in FMU 'fault'\)", result.output), said
        assert re.search(r"the 50 rows recorded (before the error )?are in \S+\.csv",
                         result.output), said
        assert host == "master-fmi" or "runs through FMI" not in result.output, said
        return
    if host in IGNORES_STATUS and code == 0:
        assert "nan" in (result.output + result.files).lower(), said
    else:
        assert code != 0, said
    if fmi == 3 and host in FMI3_REFUSED_STEP and not (host == "master-fmi" and
                                                       fault == "parameter"):
        assert re.search(FMI3_REFUSED_STEP[host], result.output), said
    if fault == "corrupt":
        if host in OURS:
            assert "corrupt" in result.output, said
        return
    fmu, what, when = (INPROCESS_NAMES if host == "master-inprocess" else NAMES)[fault]
    if host == "master-fmi" and fault == "parameter":      # the master checks it first
        when = BEFORE
    elif fmi == 3 and when == T0:
        when = AT_INITIALISATION
    assert _named(result.output, fmu, what, when), said
