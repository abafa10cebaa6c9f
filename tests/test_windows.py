"""Windows hosts, without a Windows machine: the FMUs' Python on a faked Windows, their DLLs read.

A Python FMU's code runs in a host on Windows as it does on Linux but for what
Windows lacks: ``ctypes.CDLL(None)`` (a TypeError there), the POSIX-only functions of
``os`` and ``signal``, and modules such as ``fcntl`` and ``resource``. Each FMU, of
either FMI version, is unpacked and its own code (``resources/``) instantiated and
stepped, as pythonfmu and pythonfmu3 do, in a child process that lacks all of these
(``WINDOWS_HOST``), once as in a C++ host (Python embedded by pythonfmu) and once as
in a Python host. The DLLs are read with objdump: pythonfmu's win64 binary and
pythonfmu3's x86_64-windows one, which every Python FMU of that version carries, and
the C autopilot's of both versions, cross-compiled with mingw-w64
(``fmubuild.cbuild``).
"""
from __future__ import annotations

import json
import re
import shutil
import subprocess
import sys
import zipfile
from pathlib import Path

import pytest
from fmpy.validation import validate_fmu

import pythonfmu
import pythonfmu3
from fmubuild import cbuild
from fmukit.manifest import read
from fmubuild.project import FMUS
from test_c_fmi3 import FMI3_FUNCTIONS

WINDOWS_HOST = r'''
import ast, ctypes, importlib, json, os, signal, sys
from pathlib import Path

import numpy

resources, slave_class, host, fmi = sys.argv[1:]
c_calls = []
POSIX_MODULES = ("fcntl", "resource", "pwd", "grp", "termios", "tty", "pty", "syslog", "crypt",
                 "spwd")

# The host's own modules, Python's standard library and numpy, are imported before the
# platform is faked: they are Windows' own there. The FMU's code is imported after.
for source in Path(resources).rglob("*.py"):
    for node in ast.walk(ast.parse(source.read_bytes())):
        names = ([a.name for a in node.names] if isinstance(node, ast.Import) else
                 [node.module] if isinstance(node, ast.ImportFrom) and not node.level else [])
        for top in {n.partition(".")[0] for n in names}:
            if top in sys.stdlib_module_names and top not in POSIX_MODULES:
                importlib.import_module(top)


class WindowsCDLL:
    """ctypes.CDLL as on Windows: no handle of the process (None is a TypeError), only DLLs
    by name; the C runtime's functions record their calls."""

    def __init__(self, name, *args, **kwargs):
        if name is None:
            raise TypeError("LoadLibrary() argument 1 must be str, not None")
        self._name = os.path.basename(name).lower().removesuffix(".dll")
        if self._name not in ("ucrtbase", "msvcrt", "kernel32"):
            raise OSError(f"[WinError 126] The specified module could not be found: {name!r}")

    def __getattr__(self, function):
        library = self._name

        class Function:
            def __call__(self, *args):
                c_calls.append([library, function, *args])

        setattr(self, function, Function())
        return getattr(self, function)


WINDOWS_SIGNAL = {"SIGABRT", "SIGFPE", "SIGILL", "SIGINT", "SIGSEGV", "SIGTERM", "SIG_DFL",
                  "SIG_IGN", "NSIG", "Signals", "Handlers", "default_int_handler", "getsignal",
                  "signal", "raise_signal", "set_wakeup_fd", "strsignal", "valid_signals"}
POSIX_OS = ("getuid", "geteuid", "getgid", "getegid", "getgroups", "getpgid", "getpgrp",
            "getsid", "setsid", "setpgid", "killpg", "fork", "forkpty", "register_at_fork",
            "sched_getaffinity", "sched_setaffinity", "sched_yield", "getloadavg", "sysconf",
            "confstr", "pathconf", "fpathconf", "statvfs", "fstatvfs", "uname", "nice",
            "getpriority", "setpriority", "pipe2", "mkfifo", "mknod", "chown", "fchown",
            "lchown", "chroot", "sync", "wait", "wait3", "wait4", "ttyname", "openpty",
            "ctermid", "fchmod", "lchmod", "fchdir", "pread", "pwrite", "sendfile",
            "posix_spawn", "posix_spawnp", "O_CLOEXEC", "O_NONBLOCK", "WNOHANG")
for name in [n for n in vars(signal) if not n.startswith("_") and n not in WINDOWS_SIGNAL]:
    delattr(signal, name)
signal.SIGBREAK, signal.CTRL_C_EVENT, signal.CTRL_BREAK_EVENT = 21, 0, 1
for name in POSIX_OS:
    if hasattr(os, name):
        delattr(os, name)
for module in POSIX_MODULES:
    sys.modules[module] = None           # ImportError, as on Windows
ctypes.CDLL = WindowsCDLL
sys.platform = "win32"                   # os.name stays: pathlib picks its flavour by it
if host == "c++":
    sys.orig_argv = []                   # as pythonfmu's Py_Initialize leaves it

sys.path.insert(0, resources)            # as pythonfmu does
module = importlib.import_module(Path(resources, "slavemodule.txt").read_text().strip())
# A logger with the host's logging flag off where the binary's logger keeps it: pythonfmu's
# at byte 8; pythonfmu3's in the first byte of Settings, which byte 16 points to.
logger = ctypes.create_string_buffer(24)
settings = ctypes.create_string_buffer(1)
ctypes.c_void_p.from_buffer(logger, 16).value = ctypes.addressof(settings)
slave = getattr(module, slave_class)(instance_name="win", resources=resources,
                                     visible=False, logger=ctypes.addressof(logger))
if fmi == "2":
    slave.setup_experiment(0.0)
slave.enter_initialization_mode()
slave.exit_initialization_mode()
result = slave.do_step(0.0, 0.1)
stepped = result is True if fmi == "2" else (result.status == 0 and not any(result[1:]))
slave.terminate()
print(json.dumps({"fmukit": sys.modules["fmukit.slave"].__file__, "c_calls": c_calls,
                  "sigint": signal.getsignal(signal.SIGINT).__qualname__,
                  "stepped": stepped}))
'''
"""A child process's script: instantiate and step an FMU's slave class (of FMI version
sys.argv[4]) from its resources folder on a faked Windows; it prints what it saw as JSON."""

FMI2_COMMON = (
    "fmi2GetTypesPlatform", "fmi2GetVersion", "fmi2SetDebugLogging", "fmi2Instantiate",
    "fmi2FreeInstance", "fmi2SetupExperiment", "fmi2EnterInitializationMode",
    "fmi2ExitInitializationMode", "fmi2Terminate", "fmi2Reset", "fmi2GetReal",
    "fmi2GetInteger", "fmi2GetBoolean", "fmi2GetString", "fmi2SetReal", "fmi2SetInteger",
    "fmi2SetBoolean", "fmi2SetString", "fmi2GetFMUstate", "fmi2SetFMUstate",
    "fmi2FreeFMUstate", "fmi2SerializedFMUstateSize", "fmi2SerializeFMUstate",
    "fmi2DeSerializeFMUstate", "fmi2GetDirectionalDerivative")
FMI2_CO_SIMULATION = (
    "fmi2SetRealInputDerivatives", "fmi2GetRealOutputDerivatives", "fmi2DoStep",
    "fmi2CancelStep", "fmi2GetStatus", "fmi2GetRealStatus", "fmi2GetIntegerStatus",
    "fmi2GetBooleanStatus", "fmi2GetStringStatus")
"""The functions an FMI 2.0 co-simulation FMU exports (the standard, 2.1 and 4.2)."""

C_EXPORTS = {2: set(FMI2_COMMON + FMI2_CO_SIMULATION), 3: set(FMI3_FUNCTIONS)}
C_BINARIES = {2: ("linux64", "win64"), 3: ("x86_64-linux", "x86_64-windows")}
"""FMI version: the folders of the C autopilot's Linux and Windows binaries."""

PYTHONFMU_WIN64_IMPORTS = {
    "python3.dll", "MSVCP140.dll", "VCRUNTIME140.dll", "VCRUNTIME140_1.dll", "KERNEL32.dll",
    "api-ms-win-crt-runtime-l1-1-0.dll", "api-ms-win-crt-heap-l1-1-0.dll",
    "api-ms-win-crt-string-l1-1-0.dll", "api-ms-win-crt-stdio-l1-1-0.dll",
    "api-ms-win-crt-filesystem-l1-1-0.dll", "api-ms-win-crt-locale-l1-1-0.dll"}
"""The DLLs pythonfmu 0.7.0's win64 binary imports: Python's stable ABI (python3.dll, found
on PATH), the Visual C++ 2015-2022 runtime and the Universal CRT (what the host needs)."""

PYTHONFMU_WIN64 = (Path(pythonfmu.__file__).parent / "resources" / "binaries" / "win64"
                   / "pythonfmu-export.dll")

PYTHONFMU3_WIN64 = (Path(pythonfmu3.__file__).parent / "resources" / "binaries" /
                    "x86_64-windows" / "pythonfmu-export.dll")
"""pythonfmu3 0.3.4's binary for 64-bit Windows: it imports Python's stable ABI and
KERNEL32 alone (its C++ runtime linked in)."""

PYTHON_WIN64 = {2: ("win64", PYTHONFMU_WIN64), 3: ("x86_64-windows", PYTHONFMU3_WIN64)}
"""FMI version: the Windows binary folder of the Python FMUs and the binary they carry."""


def _objdump() -> str:
    """A program that reads PE files: mingw-w64's objdump, else the system's; else skip."""
    found = shutil.which("x86_64-w64-mingw32-objdump") or shutil.which("objdump")
    if found is None:
        pytest.skip("no objdump to read PE files (apt-get install binutils-mingw-w64-x86-64)")
    return found


def _pe(dll: Path) -> tuple[set[str], set[str]]:
    """The DLLs a PE file imports and the names it exports, as objdump reads them."""
    dump = subprocess.run([_objdump(), "-p", str(dll)], capture_output=True, text=True,
                          check=True).stdout
    assert "pei-x86-64" in dump, f"{dll} is not a 64-bit Windows DLL:\n{dump[:500]}"
    imports = set(re.findall(r"DLL Name: (\S+)", dump))
    table = dump.partition("[Ordinal/Name Pointer] Table")[2]
    exports = set(re.findall(r"^\s*\[\s*\d+\] (\S+)$", table, re.MULTILINE))
    return imports, exports


@pytest.fixture(scope="module")
def python_fmus(fmu_paths, fmi3_paths) -> dict[int, dict[str, Path]]:
    """FMI version: the Python FMUs of that version, current."""
    return {2: fmu_paths, 3: fmi3_paths}


@pytest.mark.parametrize("host", ["c++", "python"])
@pytest.mark.parametrize("name", list(FMUS))
@pytest.mark.parametrize("fmi", sorted(PYTHON_WIN64))
def test_each_python_fmu_instantiates_and_steps_on_windows(python_fmus, tmp_path, fmi, name,
                                                           host):
    fmu = python_fmus[fmi][name]
    with zipfile.ZipFile(fmu) as package:
        package.extractall(tmp_path / "fmu")
    resources = tmp_path / "fmu" / "resources"
    # Isolated (-I): this checkout's modules, on PYTHONPATH, would shadow the FMU's own.
    child = subprocess.run([sys.executable, "-I", "-c", WINDOWS_HOST, str(resources),
                            read(fmu).slave_class, host, str(fmi)], cwd=tmp_path,
                           capture_output=True, text=True, timeout=120)
    assert child.returncode == 0, child.stderr
    seen = json.loads(child.stdout)
    assert Path(seen["fmukit"]).is_relative_to(resources)     # the FMU's code, not ours
    assert seen["stepped"] is True
    if host == "c++":   # Ctrl-C ends the host: SIGINT's default action, in the UCRT
        assert seen["c_calls"] == [["ucrtbase", "signal", 2, None]]
        assert seen["sigint"] == "default_int_handler"   # Python's record unchanged
    else:               # the host's handler, deferred while FMU code runs
        assert seen["c_calls"] == []
        assert seen["sigint"] == "_deferring.<locals>.deferring_handler"


@pytest.mark.parametrize("name", list(FMUS))
@pytest.mark.parametrize("fmi", sorted(PYTHON_WIN64))
def test_each_python_fmu_carries_its_pythonfmus_windows_binary(python_fmus, fmi, name):
    folder, binary = PYTHON_WIN64[fmi]
    fmu = python_fmus[fmi][name]
    with zipfile.ZipFile(fmu) as package:
        model = read(fmu).model_name
        assert package.read(f"binaries/{folder}/{model}.dll") == binary.read_bytes()


def test_pythonfmus_win64_binary_needs_python_and_the_vc_runtime():
    imports, exports = _pe(PYTHONFMU_WIN64)
    assert imports == PYTHONFMU_WIN64_IMPORTS
    assert set(FMI2_COMMON + FMI2_CO_SIMULATION) <= exports


def test_pythonfmu3s_windows_binary_needs_python_alone():
    imports, exports = _pe(PYTHONFMU3_WIN64)
    assert imports == {"python3.dll", "KERNEL32.dll"}
    assert set(FMI3_FUNCTIONS) <= exports


@pytest.fixture(scope="module", params=sorted(C_BINARIES))
def c_fmu(request, tmp_path_factory) -> tuple[int, Path]:
    """The C autopilot of each FMI version, built here with its Windows binary; skipped
    where it cannot be."""
    if cbuild.c_compiler() is None or shutil.which(cbuild.WIN64_COMPILER) is None:
        pytest.skip(f"needs a C compiler and {cbuild.WIN64_COMPILER} "
                    "(apt-get install gcc-mingw-w64-x86-64)")
    fmi = request.param
    return fmi, cbuild.build_c("pd_autopilot_c", tmp_path_factory.mktemp(f"c{fmi}"), fmi=fmi)


def test_the_c_autopilots_windows_dll_exports_fmi_and_needs_only_windows(c_fmu, tmp_path):
    fmi, fmu = c_fmu
    linux, windows = C_BINARIES[fmi]
    with zipfile.ZipFile(fmu) as package:
        assert {n for n in package.namelist() if n.startswith("binaries/")} == {
            f"binaries/{linux}/pd_autopilot_c.so", f"binaries/{windows}/pd_autopilot_c.dll"}
        description = package.read("modelDescription.xml").decode()
        dll = tmp_path / "pd_autopilot_c.dll"
        dll.write_bytes(package.read(f"binaries/{windows}/pd_autopilot_c.dll"))
    assert f'fmiVersion="{fmi}.0"' in description
    assert "<CoSimulation" in description and "<ModelExchange" not in description
    imports, exports = _pe(dll)
    assert exports == C_EXPORTS[fmi]
    system = [i for i in imports if i.upper() in ("KERNEL32.DLL", "MSVCRT.DLL")
              or i.lower().startswith("api-ms-win-crt-")]
    assert sorted(imports) == sorted(system), f"not only Windows' own DLLs: {imports}"
    assert validate_fmu(str(fmu)) == []


@pytest.mark.parametrize("fmi", sorted(C_BINARIES))
def test_without_mingw_the_c_autopilot_is_built_for_linux_alone_with_a_note(
        monkeypatch, tmp_path, capsys, fmi):
    if cbuild.c_compiler() is None:
        pytest.skip("no C compiler on this machine (set CC or install gcc)")
    which = shutil.which
    monkeypatch.setattr(shutil, "which",
                        lambda name, *a, **k: None if name == cbuild.WIN64_COMPILER
                        else which(name, *a, **k))
    fmu = cbuild.build_c("pd_autopilot_c", tmp_path, fmi=fmi)
    linux, windows = C_BINARIES[fmi]
    with zipfile.ZipFile(fmu) as package:
        assert {n for n in package.namelist() if n.startswith("binaries/")} == {
            f"binaries/{linux}/pd_autopilot_c.so"}
    assert (f"note: {cbuild.WIN64_COMPILER} not found (apt-get install gcc-mingw-w64-x86-64): "
            f"pd_autopilot_c.fmu (FMI {fmi}.0) is built without its Windows binary "
            f"(binaries/{windows})") in capsys.readouterr().err
