"""Each compensation fmukit makes for a pythonfmu3 0.3.4 defect, and for the one pythonfmu 0.7
defect the entry modules meet, shown to be needed: the FMU as built behaves, and a variant
with the compensation switched off (its carried source edited, its binary unpatched, the
description pythonfmu3 writes itself) does not.

Every host is a child process under a hard timeout, with this checkout off its import
path, so that it runs the modules the FMU carries, a variant's edits included. The quick suite
runs the exit-time host with the ship as built; the search for a heap layout in which the
unfixed binary aborts is long (test_robustness shows FMI 2.0's abort in one layout).
"""
from __future__ import annotations

import os
import signal
import subprocess
import sys
import time
import zipfile
from pathlib import Path
from xml.etree.ElementTree import Element, fromstring, tostring

import pytest
from fmpy.validation import validate_fmu
from pythonfmu3 import Fmi3Slave
from pythonfmu3.builder import get_class_name

import fmukit.pythonfmu3_03 as adapter
from autopilot_fmu.pd_autopilot_slave import PDAutopilotSlave
from fmubuild.packaging import fix_exit
from fmubuild.packaging import build_script
from fmubuild.project import FMUS, ROOT
from fmubuild.instantiate import InstantiationFailed, instantiate_in_child
from fmukit.compose import fmu_class
from fmukit.pythonfmu3_03 import KNOWN_BINARIES
from fmukit.pythonfmu3_03.slave import Fmi3Entry
from fmukit.slave import DefaultExperiment, ModelSlave, Var

TIMEOUT = 120
"""Seconds a child host may take."""

_ISOLATED = f"""
import sys
sys.path = [p for p in sys.path if p not in ("", {str(ROOT)!r})]
sys.meta_path = [f for f in sys.meta_path if "editable" not in repr(f).lower()]
"""

HOST = _ISOLATED + r'''
import gc, os
from fmpy import extract, read_model_description
from fmpy.fmi1 import FMICallException
from fmpy.fmi2 import FMU2Slave
from fmpy.fmi3 import FMU3Slave

fmu, what = sys.argv[1], sys.argv[2]
described = read_model_description(fmu)
vr = {v.name: v.valueReference for v in described.modelVariables}
heard = []


def log(environment, status, category, message):
    heard.append(status)


def status(call, *args):
    try:
        call(*args)
        return 0
    except FMICallException as failed:
        return failed.status


def instance(name):
    fmi3 = described.fmiVersion.startswith("3")
    slave = (FMU3Slave if fmi3 else FMU2Slave)(
        guid=described.guid, modelIdentifier=described.coSimulation.modelIdentifier,
        unzipDirectory=extract(fmu, os.path.abspath(name)), instanceName=name)
    if fmi3:
        slave.instantiate(loggingOn=what != "quiet", logMessage=log)
        slave.enterInitializationMode()
    else:
        slave.instantiate()
        slave.setupExperiment(startTime=0.0)
        slave.enterInitializationMode()
    slave.exitInitializationMode()
    return slave


if what == "instances":                    # one after another, in one process
    for k in range(3):
        slave = instance(f"i{k}")
        slave.doStep(0.0, 0.1)
        slave.terminate()
        slave.freeInstance()
    print("instantiated 3", flush=True)
    sys.exit(0)
slave = instance("pd")
if what == "exceptions":                   # each one an exception in the FMU's Python
    print("statuses", [status(slave.setFloat64, [vr["delta_c"]], [1.0]) for _ in range(3)],
          flush=True)
else:                                      # "refused", "quiet": a NaN input, twice
    slave.setFloat64([vr["psi"]], [float("nan")])
    print("steps", [status(slave.doStep, 0.0, 0.1) for _ in range(2)], flush=True)
    print("reset", status(slave.reset), flush=True)
    slave.enterInitializationMode()
    slave.exitInitializationMode()
    slave.setFloat64([vr["psi"]], [0.1])
    print("after reset", status(slave.doStep, 0.0, 0.1), slave.getFloat64([vr["delta_c"]]),
          flush=True)
slave.freeInstance()
gc.collect()
print("heard", heard, flush=True)
'''
"""A host of one FMU: ``python -c HOST FMU WHAT``, WHAT one of instances, exceptions,
refused and quiet (refused with logging off)."""

STEPPER = _ISOLATED + r'''
import os
from fmpy import extract, read_model_description
from fmpy.fmi1 import FMICallException
from fmpy.fmi3 import FMU3Slave

described = read_model_description(sys.argv[1])
slave = FMU3Slave(guid=described.guid, modelIdentifier=described.coSimulation.modelIdentifier,
                  unzipDirectory=extract(sys.argv[1], os.path.abspath("x")), instanceName="ship")
slave.instantiate(loggingOn=True, logMessage=lambda *message: None)
slave.enterInitializationMode()
slave.exitInitializationMode()
try:
    for k in range(30):                    # each step some 0.5 s of the ship's RK4
        print("stepping", flush=True)
        try:
            slave.doStep(k * 4000.0, 4000.0)
        except FMICallException as failed:
            print("step failed", failed.status, flush=True)
    print("never interrupted", flush=True)
except KeyboardInterrupt:
    print("the host's KeyboardInterrupt", flush=True)
slave.freeInstance()
'''
"""A host stepping the ship with long steps, which the test interrupts (SIGINT) mid-step."""

EXIT_HOST = _ISOLATED + r'''
import ctypes, os
from fmpy import extract, read_model_description
from fmpy.fmi3 import FMU3Slave

described = read_model_description(sys.argv[1])
slave = FMU3Slave(guid=described.guid, modelIdentifier=described.coSimulation.modelIdentifier,
                  unzipDirectory=extract(sys.argv[1], os.path.abspath(sys.argv[3])),
                  instanceName="host")
ctypes.CDLL(sys.argv[2])                   # after the FMU library: its destructor runs later
libc = ctypes.CDLL(None)
libc.malloc.restype = ctypes.c_void_p
for _ in range(1000):                      # leaked on purpose (tests/exit_heap/host.py)
    libc.malloc(128)
slave.instantiate()
slave.enterInitializationMode()
slave.exitInitializationMode()
for k in range(10):
    slave.doStep(k * 0.1, 0.1)
slave.terminate()
slave.freeInstance()
'''
"""tests/exit_heap/host.py for FMI 3.0: load, step, free, exit, with allocator traffic after
the FMU library's exit code; the FMU is unpacked into the folder sys.argv[3]."""


def _child(script: str, *args: str | Path, cwd: Path, padding: int = 0,
           timeout: float = TIMEOUT) -> subprocess.CompletedProcess:
    """Run ``script`` from a file in ``cwd`` with ``args``, its environment this one's
    without PYTHONPATH, and ``padding`` characters more (which shift its heap's layout)."""
    host = cwd / "host.py"
    host.write_text(script)
    env = {k: v for k, v in os.environ.items() if k != "PYTHONPATH"}
    return subprocess.run([sys.executable, str(host), *map(str, args)], cwd=cwd,
                          capture_output=True, text=True, timeout=timeout,
                          env={**env, "PADDING": "x" * padding})


def _variant(fmu: Path, dest: Path, member: str, old: str | bytes, new: str | bytes) -> Path:
    """A copy of ``fmu`` at ``dest`` with ``old`` (there once) replaced by ``new`` in
    ``member``."""
    old, new = (s.encode() if isinstance(s, str) else s for s in (old, new))
    with zipfile.ZipFile(fmu) as package, zipfile.ZipFile(dest, "w") as out:
        for info in package.infolist():
            data = package.read(info)
            if info.filename == member:
                assert data.count(old) == 1, (member, old)
                data = data.replace(old, new)
            out.writestr(info, data)
    return dest


ADAPTER_SLAVE = "resources/fmukit/pythonfmu3_03/slave.py"


@pytest.fixture
def pd3(fmi3_paths) -> Path:
    return fmi3_paths["pd_autopilot"]


def test_exceptions_in_one_instance_leave_the_host_alive(pd3, tmp_path):
    survived = _child(HOST, pd3, "exceptions", cwd=tmp_path)
    assert survived.returncode == 0, survived.stderr
    assert "statuses [4, 4, 4]" in survived.stdout
    unprotected = _variant(pd3, tmp_path / "pd.fmu", ADAPTER_SLAVE,
                           "RELEASES_ON_EXCEPTION = ACTIVE", "RELEASES_ON_EXCEPTION = False")
    crashed = _child(HOST, unprotected, "exceptions", cwd=tmp_path)
    assert crashed.returncode == -signal.SIGSEGV, crashed.stdout + crashed.stderr


def test_a_refused_step_is_a_non_fatal_error_after_which_reset_works(pd3, tmp_path):
    refused = _child(HOST, pd3, "refused", cwd=tmp_path)
    assert refused.returncode == 0, refused.stderr
    assert "steps [3, 3]" in refused.stdout                    # fmi3Error, still failed
    assert "reset 0\nafter reset 0 [0.2]" in refused.stdout
    raised = _variant(pd3, tmp_path / "pd.fmu", ADAPTER_SLAVE,
                      "@fmi_entry(error_result=_refused_step)", "@fmi_entry")
    fatal = _child(HOST, raised, "refused", cwd=tmp_path)
    assert "steps [4, 4]" in fatal.stdout, fatal.stdout + fatal.stderr


def test_with_logging_off_the_host_is_sent_nothing(pd3, tmp_path):
    quiet = _child(HOST, pd3, "quiet", cwd=tmp_path)
    assert "heard []" in quiet.stdout, quiet.stdout + quiet.stderr
    assert quiet.stderr.count("pd: doStep at t = 0.0: input psi = nan is not finite") == 1
    forwarded = _variant(pd3, tmp_path / "pd.fmu", ADAPTER_SLAVE,
                         "if self.host_log.hears():", "if True:")
    told = _child(HOST, forwarded, "quiet", cwd=tmp_path)
    assert "heard [3, 3]" in told.stdout, told.stdout + told.stderr


def _interrupted(fmu: Path, cwd: Path) -> str:
    """What the stepping host prints when SIGINT arrives while the ship computes."""
    host = subprocess.Popen([sys.executable, "-c", STEPPER, str(fmu)], cwd=cwd, text=True,
                            stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                            env={k: v for k, v in os.environ.items() if k != "PYTHONPATH"})
    try:
        said = [host.stdout.readline(), host.stdout.readline()]
        assert said == ["stepping\n"] * 2, said
        time.sleep(0.2)                               # well inside the second step
        host.send_signal(signal.SIGINT)
        return host.communicate(timeout=TIMEOUT)[0]
    finally:
        host.kill()


def test_ctrl_c_reaches_the_hosts_own_code(fmi3_paths, tmp_path):
    said = _interrupted(fmi3_paths["ship"], tmp_path)
    assert "the host's KeyboardInterrupt" in said and "step failed" not in said, said
    undeferred = _variant(fmi3_paths["ship"], tmp_path / "ship.fmu", "resources/fmukit/slave.py",
                          "        hostsignals.defer_host_handlers()\n", "")
    said = _interrupted(undeferred, tmp_path)
    assert "step failed 3" in said and "never interrupted" in said, said   # the FMU failed


@pytest.fixture(scope="module")
def late_malloc(tmp_path_factory) -> Path:
    library = tmp_path_factory.mktemp("exit_heap") / "late_malloc.so"
    subprocess.run(["gcc", "-shared", "-fPIC", "-o", str(library),
                    str(ROOT / "tests" / "exit_heap" / "late_malloc.c")], check=True,
                   timeout=TIMEOUT)
    return library


@pytest.mark.parametrize("folder", ("x", "x" * 9, "x" * 17))
def test_a_host_exits_with_its_heap_intact(fmi3_paths, late_malloc, tmp_path, folder):
    """The ship as built, in one heap layout per length of the FMU folder's path (the long
    test below shows these checks can fail)."""
    intact = _child(EXIT_HOST, fmi3_paths["ship"], late_malloc, folder, cwd=tmp_path)
    assert intact.returncode == 0, (folder, intact.stderr)


@pytest.mark.long
def test_without_the_exit_fix_a_host_aborts_where_with_it_it_exits_cleanly(
        fmi3_paths, late_malloc, tmp_path):
    """Whether malloc notices the write into a freed block depends on the heap's layout,
    which the size of the environment and the length of the FMU folder's path shift (and
    the FMU's own Python code: any edit of it): the host is run with the environment padded
    more and more, in folders of six lengths, the FMU as built and its unfixed variant in
    each layout, until the variant aborts. The FMU as built must exit cleanly in every
    layout tried."""
    ship = fmi3_paths["ship"]
    known = next(iter(KNOWN_BINARIES.values()))
    with zipfile.ZipFile(ship) as package:
        binary = package.read("binaries/x86_64-linux/ship.so")
    unfixed = _variant(ship, tmp_path / "unfixed.fmu", "binaries/x86_64-linux/ship.so",
                       binary[known.offset - 8:known.offset + len(known.patched)],
                       binary[known.offset - 8:known.offset] + known.code)
    for padding in range(0, 4096, 64):
        for folder in ("x" * n for n in range(1, 24, 4)):   # 3 lengths once found none
            intact = _child(EXIT_HOST, ship, late_malloc, folder, cwd=tmp_path, padding=padding)
            assert intact.returncode == 0, (padding, folder, intact.stderr)
            aborted = _child(EXIT_HOST, unfixed, late_malloc, folder, cwd=tmp_path,
                             padding=padding)
            if aborted.returncode == -signal.SIGABRT:
                assert "corrupted" in aborted.stderr
                return
            assert aborted.returncode == 0, (padding, folder, aborted.stderr)
    pytest.fail("the unfixed binary never aborted: this test cannot tell the fix is needed")


def test_the_exit_fix_and_the_build_refuse_what_they_do_not_know(monkeypatch, tmp_path):
    with pytest.raises(RuntimeError, match="is not the pythonfmu3 0.3.4 x86_64-linux binary"):
        fix_exit(b"\x7fELF something else", "pd.fmu:binaries/x86_64-linux/pd.so", 3)
    monkeypatch.setattr(adapter, "PYTHONFMU_VERSION", "0.3.5")
    monkeypatch.setattr(adapter, "ACTIVE", False)
    with pytest.raises(RuntimeError, match=r"pythonfmu3 0\.3\.5 is installed; fmukit builds "
                                           r"FMI 3\.0 FMUs with pythonfmu3 0\.3\.4 only"):
        build_script(ROOT / FMUS["pd_autopilot"], ("fmukit", "autopilot_fmu"), tmp_path, fmi=3)
    assert not any(tmp_path.iterdir())


def test_an_fmu_that_cannot_import_kills_its_host_so_the_build_tries_it_in_a_child(
        pd3, tmp_path):
    broken = _variant(pd3, tmp_path / "pd.fmu", "resources/pd_autopilot_fmi3.py",
                      "from pythonfmu3 import Fmi3Slave\n",
                      "import not_in_this_fmu\nfrom pythonfmu3 import Fmi3Slave\n")
    with pytest.raises(InstantiationFailed) as failed:
        instantiate_in_child(broken, isolated=True, timeout=TIMEOUT)
    assert failed.value.crashed == "SIGSEGV"                   # the child, not this process


def test_pythonfmu07_instantiates_an_entry_module_three_times_in_one_process(fmu_paths,
                                                                               tmp_path):
    """pythonfmu 0.7 releases the entry module's namespace once per instantiation: without
    the hold, the child uses freed memory, and crashes or spins (undefined behaviour). A
    spinning child is stopped at 20 times what the held one took, plus 10 s."""
    pd2 = fmu_paths["pd_autopilot"]
    started = time.monotonic()
    held = _child(HOST, pd2, "instances", cwd=tmp_path)
    reference = time.monotonic() - started
    assert held.returncode == 0 and "instantiated 3" in held.stdout, held.stderr
    released = _variant(pd2, tmp_path / "pd.fmu", "resources/pd_autopilot_fmi2.py",
                        "hold_namespace(globals())\n", "")
    try:
        freed = _child(HOST, released, "instances", cwd=tmp_path, timeout=20 * reference + 10)
    except subprocess.TimeoutExpired as spun:
        assert b"instantiated 3" not in (spun.stdout or b"")      # bytes, even with text=True
    else:
        assert freed.returncode != 0 and "instantiated 3" not in freed.stdout


def test_the_entry_module_is_the_class_pythonfmu3_can_find(pd3):
    """pythonfmu3 finds the FMU's class by a regular expression wanting Fmi3Slave between the
    parentheses of its class line: a slave script's ``class X(ModelSlave)`` has none."""
    with pytest.raises(AttributeError):
        get_class_name(ROOT / FMUS["pd_autopilot"])
    with zipfile.ZipFile(pd3) as package:
        entry = package.read("resources/pd_autopilot_fmi3.py").decode()
    assert "\nclass PDAutopilotSlave(Fmi3Entry, _Model, Fmi3Slave):\n" in entry


class Sum(ModelSlave):
    """A model of one parameter whose start pythonfmu3 rounds (0.1 + 0.2)."""

    model_name = "sum"
    description = "y = u + a"
    default_experiment = DefaultExperiment(0.0, 10.0, 0.5)
    variables = (Var.input("u", 0.0, "rad"), Var.parameter("a", 0.1 + 0.2, "rad"),
                 Var.output("y", "rad", depends=("u", "a"), get=lambda s: s.u + s.a),
                 Var.output("n", kind=int, depends=("a",), get=lambda s: 1))


def _pythonfmu3s(slave: ModelSlave) -> Element:
    """The model description pythonfmu3 writes itself for ``slave``."""
    return super(ModelSlave, slave).to_xml()


def _validated(description: Element, like: Path, dest: Path) -> list[str]:
    """fmpy's problems with ``description`` in a copy of the FMU ``like``."""
    with zipfile.ZipFile(like) as package:
        built = package.read("modelDescription.xml")
    _variant(like, dest, "modelDescription.xml", built, tostring(description, "UTF-8"))
    return validate_fmu(str(dest))


def test_without_units_the_description_does_not_validate(pd3, tmp_path):
    slave = fmu_class(PDAutopilotSlave, 3)(instance_name="pd")
    assert validate_fmu(str(pd3)) == []
    problems = _validated(_pythonfmu3s(slave), pd3, tmp_path / "pd.fmu")
    assert any(p.startswith('The unit "rad" of variable "psi"') for p in problems), problems


def test_without_the_independent_time_the_description_does_not_validate(pd3, tmp_path):
    timeless = type("Timeless", (Fmi3Entry, PDAutopilotSlave, Fmi3Slave),
                    {"_before_variables": lambda self: None})
    problems = _validated(timeless(instance_name="pd").to_xml(), pd3, tmp_path / "pd.fmu")
    assert any("independent variable" in p for p in problems), problems


def test_the_completed_description_has_what_pythonfmu3_leaves_out():
    slave = fmu_class(Sum, 3)(instance_name="sum")
    raw, ours = _pythonfmu3s(slave), slave.to_xml()

    def variables(root: Element) -> dict[str, dict[str, str]]:
        return {v.get("name"): v.attrib for v in root.find("ModelVariables")}
    assert float(variables(raw)["a"]["start"]) != 0.1 + 0.2                # 16 digits: 0.3
    assert float(variables(ours)["a"]["start"]) == 0.1 + 0.2
    assert "displayUnit" not in variables(raw)["u"]
    assert variables(ours)["u"]["displayUnit"] == "deg"

    def outputs(root: Element) -> dict[str, str | None]:
        return {o.get("valueReference"): o.get("dependencies")
                for o in root.find("ModelStructure").iter("Output")}
    vr = {name: attributes["valueReference"] for name, attributes in variables(ours).items()}
    assert outputs(raw) == {vr["y"]: None, vr["n"]: None}    # each on every input, for a master
    assert outputs(ours) == {vr["y"]: vr["u"], vr["n"]: ""}  # n is no direct feedthrough
    assert raw.find("UnitDefinitions") is None and ours.find("UnitDefinitions") is not None
    # time at value reference 0 comes first, so no other's reference is its position
    assert [v.get("valueReference") for v in raw.find("ModelVariables")] == ["0", "1", "2", "3",
                                                                              "4"]
    assert [v.get("valueReference") for v in ours.find("ModelVariables")] == ["1", "2", "3", "4",
                                                                               "0"]


def test_description_and_default_experiment_come_from_the_class(pd3):
    class Described(Fmi3Slave):
        description = "the class's"
        default_experiment = DefaultExperiment(0.0, 10.0, 0.5)
    pythonfmu3s = Described(instance_name="d").to_xml()
    assert pythonfmu3s.get("description") is None and pythonfmu3s.find("DefaultExperiment") is None
    ours = fmu_class(Sum, 3)(instance_name="sum").to_xml()
    assert ours.get("description") == "y = u + a"
    assert ours.find("DefaultExperiment").attrib == {"startTime": "0.0", "stopTime": "10.0",
                                                     "stepSize": "0.5"}
    with zipfile.ZipFile(pd3) as package:
        built = fromstring(package.read("modelDescription.xml"))
    assert built.get("description") == PDAutopilotSlave.description


def test_variable_communication_steps_are_declared_as_the_build_gives_them(pd3):
    """pythonfmu3 writes another option's value for canHandleVariableCommunicationStepSize
    (a loop variable left over): false; the build gives it."""
    raw = _pythonfmu3s(fmu_class(Sum, 3)(instance_name="sum"))
    assert raw.find("CoSimulation").get("canHandleVariableCommunicationStepSize") == "false"
    with zipfile.ZipFile(pd3) as package:
        built = fromstring(package.read("modelDescription.xml"))
    assert built.find("CoSimulation").get("canHandleVariableCommunicationStepSize") == "true"
