"""Building FMUs written in C: compiled against the FMI 2.0 headers fmpy ships, then zipped.

Each C FMU is a folder with ``<name>.c`` (the FMI 2.0 co-simulation API) and a
hand-written ``modelDescription.xml``. The system C compiler (``$CC``, else ``cc``
or ``gcc``) builds the shared library for this platform, and where mingw-w64 is
installed (Debian's gcc-mingw-w64-x86-64) it cross-compiles the win64 DLL beside
it: one that needs only Windows' own DLLs (KERNEL32, msvcrt), with no time stamp
and a fixed image base, so that the FMU stays the same byte for byte. The FMU
carries the libraries, the model description and the source, and must pass fmpy's
validation. Without a C compiler the build says so (``NoCompiler``) and the Python
FMUs are unaffected; without mingw-w64 the FMU is built without its win64 binary,
with a note.
"""
from __future__ import annotations

import os
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

from . import documentation, reproducible
from .manifest import project_identity, version
from .project import C_FMUS, FMU_DIR, ROOT

C_HOSTS = {"linux64": "any FMI 2.0 co-simulation host; the library needs only libc and libm.",
           "win64": "any FMI 2.0 co-simulation host; the DLL needs only KERNEL32 and msvcrt."}
"""What a host needs for the C FMU, by platform (no Python: tests/test_windows.py reads the
DLL's imports)."""

_LIBRARY = {"linux64": ".so", "darwin64": ".dylib"}

WIN64_COMPILER = "x86_64-w64-mingw32-gcc"
"""mingw-w64's C compiler for 64-bit Windows (Debian: gcc-mingw-w64-x86-64)."""

_WIN64_FLAGS = ["-static-libgcc",        # no libgcc_s DLL for the host to find
                "-s",                    # strip: mingw-w64's start-up code brings debug sections
                "-Wl,--no-insert-timestamp,--disable-auto-image-base"]   # reproducible


class NoCompiler(RuntimeError):
    """No C compiler on this machine."""


def c_compiler() -> str | None:
    """The C compiler to use: $CC if set (and found), else cc or gcc; None if there is none."""
    if os.environ.get("CC"):
        return shutil.which(os.environ["CC"])
    return shutil.which("cc") or shutil.which("gcc")


def build_c(name: str, dest: Path = FMU_DIR) -> Path:
    """Compile the C FMU ``name`` into dest/name.fmu, for this platform and, with mingw-w64,
    win64, and validate it; its path."""
    import fmpy
    from fmpy.validation import validate_fmu

    compiler = c_compiler()
    if compiler is None:
        raise NoCompiler(f"no C compiler found (set CC, or install gcc): {name}.fmu, an "
                         "autopilot in C, is not built; everything else is")
    if fmpy.platform not in _LIBRARY:
        raise NoCompiler(f"{name}.fmu is built for Linux and macOS only, not {fmpy.platform}")
    targets = {fmpy.platform: ([compiler, "-fPIC"], _LIBRARY[fmpy.platform])}
    win64 = shutil.which(WIN64_COMPILER)
    if win64 is not None:
        targets["win64"] = ([win64, *_WIN64_FLAGS], ".dll")
    else:
        print(f"note: {WIN64_COMPILER} not found (apt-get install gcc-mingw-w64-x86-64): "
              f"{name}.fmu is built without a win64 binary", file=sys.stderr)
    folder, headers = ROOT / C_FMUS[name], Path(fmpy.__file__).parent / "c-code"
    source = folder / f"{name}.c"
    entries = {"modelDescription.xml": (folder / "modelDescription.xml").read_bytes(),
               f"sources/{source.name}": source.read_bytes()}
    with tempfile.TemporaryDirectory(prefix=f"build_{name}_") as tmp:
        for platform, (command, suffix) in targets.items():
            library = Path(tmp) / f"{name}{suffix}"
            compiled = subprocess.run([*command, "-std=c99", "-O2", "-Wall", "-shared",
                                       "-I", str(headers), str(source), "-o", str(library),
                                       "-lm"], capture_output=True, text=True)
            if compiled.returncode != 0:
                raise RuntimeError(f"{command[0]} could not compile {source} for {platform}:\n"
                                   f"{compiled.stderr}")
            entries[f"binaries/{platform}/{library.name}"] = library.read_bytes()
    entries = documentation.describe(entries, f"fmukit {version()} (fmubuild.cbuild)",
                                     project_identity(), "", {}, C_HOSTS)
    dest.mkdir(parents=True, exist_ok=True)
    fmu = dest / f"{name}.fmu"
    reproducible.write(fmu, entries)
    problems = validate_fmu(str(fmu))
    if problems:
        raise RuntimeError(f"{fmu} does not validate:\n" + "\n".join(problems))
    return fmu
