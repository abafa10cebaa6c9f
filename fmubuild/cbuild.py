"""Building FMUs written in C: compiled against the FMI 2.0 headers fmpy ships, then zipped.

Each C FMU is a folder with ``<name>.c`` (the FMI 2.0 co-simulation API) and a
hand-written ``modelDescription.xml``. The system C compiler (``$CC``, else ``cc``
or ``gcc``) builds the shared library for this platform; the FMU carries it, the
model description and the source, and must pass fmpy's validation. Without a
compiler the build says so (``NoCompiler``) and the Python FMUs are unaffected.
"""
from __future__ import annotations

import os
import shutil
import subprocess
import tempfile
from pathlib import Path

from . import reproducible
from .project import C_FMUS, FMU_DIR, ROOT

_LIBRARY = {"linux64": ".so", "darwin64": ".dylib"}


class NoCompiler(RuntimeError):
    """No C compiler on this machine."""


def c_compiler() -> str | None:
    """The C compiler to use: $CC if set (and found), else cc or gcc; None if there is none."""
    if os.environ.get("CC"):
        return shutil.which(os.environ["CC"])
    return shutil.which("cc") or shutil.which("gcc")


def build_c(name: str, dest: Path = FMU_DIR) -> Path:
    """Compile the C FMU ``name`` into dest/name.fmu and validate it; its path."""
    import fmpy
    from fmpy.validation import validate_fmu

    compiler = c_compiler()
    if compiler is None:
        raise NoCompiler(f"no C compiler found (set CC, or install gcc): {name}.fmu, an "
                         "autopilot in C, is not built; everything else is")
    if fmpy.platform not in _LIBRARY:
        raise NoCompiler(f"{name}.fmu is built for Linux and macOS only, not {fmpy.platform}")
    folder, headers = ROOT / C_FMUS[name], Path(fmpy.__file__).parent / "c-code"
    source = folder / f"{name}.c"
    dest.mkdir(parents=True, exist_ok=True)
    with tempfile.TemporaryDirectory(prefix=f"build_{name}_") as tmp:
        library = Path(tmp) / f"{name}{_LIBRARY[fmpy.platform]}"
        compiled = subprocess.run([compiler, "-std=c99", "-O2", "-Wall", "-shared", "-fPIC",
                                   "-I", str(headers), str(source), "-o", str(library), "-lm"],
                                  capture_output=True, text=True)
        if compiled.returncode != 0:
            raise RuntimeError(f"{compiler} could not compile {source}:\n{compiled.stderr}")
        fmu = dest / f"{name}.fmu"
        reproducible.write(fmu, {
            "modelDescription.xml": (folder / "modelDescription.xml").read_bytes(),
            f"binaries/{fmpy.platform}/{library.name}": library.read_bytes(),
            f"sources/{source.name}": source.read_bytes()})
    problems = validate_fmu(str(fmu))
    if problems:
        raise RuntimeError(f"{fmu} does not validate:\n" + "\n".join(problems))
    return fmu
