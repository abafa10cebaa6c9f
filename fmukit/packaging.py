"""Building FMUs: this project's FMUs (``FMUS``) and any slave script written with fmukit.

Each FMU carries in its resources the project packages it imports (Python
sources only) and a requirements.txt, so a host needs only Python with numpy
(``pythonfmu deploy -f fmus/ship.fmu`` installs it). After building, the
binary gets ``fmukit.exit_fix`` (pythonfmu 0.7.0 corrupts its host's heap at
exit) and the modelDescription.xml is checked with fmpy's validator; a problem
fails the build.
"""
from __future__ import annotations

import shutil
import tempfile
from pathlib import Path

from . import exit_fix

ROOT = Path(__file__).resolve().parent.parent
FMU_DIR = ROOT / "fmus"

# FMU name: (slave script, packages it needs at run time)
FMUS: dict[str, tuple[str, tuple[str, ...]]] = {
    "ship": ("ship_fmu/ship_slave.py", ("fmukit", "ship_fmu")),
    "manoeuvre": ("ship_fmu/manoeuvre_slave.py", ("fmukit", "ship_fmu")),
    "pd_autopilot": ("autopilot_fmu/pd_autopilot_slave.py", ("fmukit", "autopilot_fmu")),
    # design_model 'ship' linearises the vessel model, and the guidance's circle of
    # acceptance is two ship lengths: both carry ship_fmu too.
    "smc_autopilot": ("autopilot_fmu/smc_autopilot_slave.py",
                      ("fmukit", "autopilot_fmu", "ship_fmu")),
    "guidance": ("autopilot_fmu/guidance_slave.py", ("fmukit", "autopilot_fmu", "ship_fmu")),
    # Written as a user's own autopilot is (docs/own_autopilot.md): one file and fmukit.
    "pid_autopilot": ("autopilot_fmu/pid_autopilot_slave.py", ("fmukit",)),
}

RUNTIME_REQUIREMENTS = "numpy\n"
BUILD_HINT = "build the FMUs with: python -m fmukit.build"


def build(name: str, dest: Path = FMU_DIR) -> Path:
    """Build one FMU of this project to dest/name.fmu, validate it, and return its path."""
    script, packages = FMUS[name]
    return build_script(ROOT / script, packages, dest / f"{name}.fmu")


def build_script(script: Path, packages: tuple[str, ...], fmu_path: Path) -> Path:
    """Build the slave in ``script`` with this project's ``packages`` into ``fmu_path``."""
    from fmpy.validation import validate_fmu
    from pythonfmu import FmuBuilder

    name, dest = fmu_path.stem, fmu_path.parent
    dest.mkdir(parents=True, exist_ok=True)
    with tempfile.TemporaryDirectory(prefix=f"build_{name}_") as tmp:
        stage = Path(tmp)
        shutil.copy2(script, stage)
        for package in packages:
            shutil.copytree(ROOT / package, stage / package,
                            ignore=shutil.ignore_patterns("__pycache__", "*.pyc"))
        (stage / "requirements.txt").write_text(RUNTIME_REQUIREMENTS)
        fmu = FmuBuilder.build_FMU(
            stage / Path(script).name, dest=fmu_path,
            project_files=[stage / p for p in packages] + [stage / "requirements.txt"],
            canGetAndSetFMUstate=True, canSerializeFMUstate=True)
    exit_fix.fix_fmu(Path(fmu))
    problems = validate_fmu(str(fmu))
    if problems:
        raise RuntimeError(f"{fmu} does not validate:\n" + "\n".join(problems))
    return Path(fmu)
