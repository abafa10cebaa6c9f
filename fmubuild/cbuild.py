"""FMUs written in C, compiled reproducibly with the system compiler and, where mingw-w64 is
installed, for 64-bit Windows; zipped with their sources and validated."""
from __future__ import annotations

import os
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

from fmukit.manifest import version

from . import documentation
from .packaging import write_fmu
from .project import C_FMUS, FMU_DIRS, ROOT, ROUTES, project_identity

WINDOWS = {2: "win64", 3: "x86_64-windows"}                # FMI version: the platform folder
C_HOSTS = {fmi: {ROUTES[fmi].linux: f"any FMI {fmi}.0 co-simulation host; the library needs "
                                    "only libc and libm.",
                 windows: f"any FMI {fmi}.0 co-simulation host; the DLL needs only KERNEL32 "
                          "and msvcrt."}      # tests/test_windows.py reads the DLL's imports
           for fmi, windows in WINDOWS.items()}
WIN64_COMPILER = "x86_64-w64-mingw32-gcc"          # mingw-w64's (Debian: gcc-mingw-w64-x86-64)
_WIN64_FLAGS = ["-static-libgcc",        # no libgcc_s DLL for the host to find
                "-s",                    # strip: mingw-w64's start-up code brings debug sections
                "-Wl,--no-insert-timestamp,--disable-auto-image-base"]   # reproducible
_LIBRARY = {"linux64": ".so", "darwin64": ".dylib"}     # fmpy's platform: a library's suffix
_BUILD_DESCRIPTION = """<?xml version="1.0" encoding="UTF-8"?>
<fmiBuildDescription fmiVersion="3.0">
  <BuildConfiguration modelIdentifier="{name}">
    <SourceFileSet language="C99">
      <SourceFile name="{source}"/>
    </SourceFileSet>
    <Library name="m" external="true" description="the C math library"/>
  </BuildConfiguration>
</fmiBuildDescription>
"""


class NoCompiler(RuntimeError):
    """No C compiler on this machine."""


def c_compiler() -> str | None:
    """$CC if set (and found), else cc or gcc; None if there is none."""
    if os.environ.get("CC"):
        return shutil.which(os.environ["CC"])
    return shutil.which("cc") or shutil.which("gcc")


def sources(name: str, fmi: int = 2) -> list[Path]:
    """The C FMU ``name``'s FMI ``fmi`` source, headers and model description."""
    folder, version_suffix = ROOT / C_FMUS[name], "" if fmi == 2 else "_fmi3"
    return [folder / f"{name}{version_suffix}.c", *sorted(folder.glob("*.h")),
            folder / f"modelDescription{version_suffix}.xml"]


def build_c(name: str, dest: Path | None = None, fmi: int = 2) -> Path:
    """The C FMU ``name`` as FMI ``fmi`` in dest/name.fmu; NoCompiler without a compiler."""
    import fmpy
    if (compiler := c_compiler()) is None:
        raise NoCompiler(f"no C compiler found (set CC, or install gcc): {name}.fmu, an "
                         "autopilot in C, is not built; everything else is")
    if fmpy.platform not in _LIBRARY:
        raise NoCompiler(f"{name}.fmu is built for Linux and macOS only, not {fmpy.platform}")
    here = fmpy.platform if fmi == 2 else fmpy.platform_tuple
    targets = {here: ([compiler, "-fPIC"], _LIBRARY[fmpy.platform])}
    if shutil.which(WIN64_COMPILER):
        targets[WINDOWS[fmi]] = ([shutil.which(WIN64_COMPILER), *_WIN64_FLAGS], ".dll")
    else:
        print(f"note: {WIN64_COMPILER} not found (apt-get install gcc-mingw-w64-x86-64): "
              f"{name}.fmu (FMI {fmi}.0) is built without its Windows binary "
              f"(binaries/{WINDOWS[fmi]})", file=sys.stderr)
    source, *headers, description = sources(name, fmi)
    entries = {"modelDescription.xml": description.read_bytes(),
               **{f"sources/{p.name}": p.read_bytes() for p in (source, *headers)}}
    if fmi == 3:
        entries["sources/buildDescription.xml"] = _BUILD_DESCRIPTION.format(
            name=name, source=source.name).encode()
    with tempfile.TemporaryDirectory(prefix=f"build_{name}_") as tmp:
        for platform, (command, suffix) in targets.items():
            library = Path(tmp) / f"{name}{suffix}"
            compiled = subprocess.run([*command, "-std=c99", "-O2", "-Wall", "-shared", "-I",
                                       str(Path(fmpy.__file__).parent / "c-code"), str(source),
                                       "-o", str(library), "-lm"],
                                      capture_output=True, text=True, timeout=120)
            if compiled.returncode != 0:
                raise RuntimeError(f"{command[0]} could not compile {source} for {platform}:\n"
                                   f"{compiled.stderr}")
            entries[f"binaries/{platform}/{library.name}"] = library.read_bytes()
    return write_fmu((dest or FMU_DIRS[fmi]) / f"{name}.fmu", documentation.describe(
        entries, f"fmukit {version()} (fmubuild.cbuild)", project_identity(), "", {}, C_HOSTS[fmi]))
