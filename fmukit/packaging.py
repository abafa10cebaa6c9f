"""Building FMUs: this project's FMUs (``FMUS``) and any slave script written with fmukit.

Each FMU carries in its resources the project packages it imports (Python
sources only) and a requirements.txt, so a host needs only Python with numpy
(``pythonfmu deploy -f fmus/ship.fmu`` installs it). After building, the
binary gets ``fmukit.exit_fix`` (pythonfmu 0.7.0 corrupts its host's heap at
exit) and the modelDescription.xml is checked with fmpy's validator; a problem
fails the build.
"""
from __future__ import annotations

import contextlib
import shutil
import subprocess
import sys
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


def build_script(script: Path, packages: tuple[str | Path, ...], dest: Path) -> Path:
    """Build the slave in ``script`` into ``dest`` (a .fmu path, or a folder where the FMU
    is named after the slave's model_name), carrying ``packages``: this project's package
    names, or paths of a user's modules and packages. Returns the FMU's path.

    ValueError naming the script if it cannot be built (no ModelSlave in it, or it
    does not import); RuntimeError if the result does not validate.
    """
    from fmpy.validation import validate_fmu
    from pythonfmu import FmuBuilder

    script, dest = Path(script), Path(dest)
    if script.suffix != ".py":
        raise ValueError(f"{script} is not a Python script (.py) to build an FMU from")
    if not script.is_file():
        raise ValueError(f"{script} does not exist")
    sources = [ROOT / p if isinstance(p, str) else Path(p) for p in packages]
    for source in sources:
        if not source.exists():
            raise ValueError(f"{source}, to be carried by {script.name}'s FMU, does not exist")
    (dest.parent if dest.suffix == ".fmu" else dest).mkdir(parents=True, exist_ok=True)
    with tempfile.TemporaryDirectory(prefix=f"build_{script.stem}_") as tmp, \
            _imports_undone(tmp):
        stage = Path(tmp)
        shutil.copy2(script, stage)
        for source in sources:
            if source.is_dir():
                shutil.copytree(source, stage / source.name,
                                ignore=shutil.ignore_patterns("__pycache__", "*.pyc"))
            else:
                shutil.copy2(source, stage)
        (stage / "requirements.txt").write_text(RUNTIME_REQUIREMENTS)
        try:
            fmu = Path(FmuBuilder.build_FMU(
                stage / script.name, dest=dest,
                project_files=[stage / s.name for s in sources] + [stage / "requirements.txt"],
                canGetAndSetFMUstate=True, canSerializeFMUstate=True))
        except Exception as error:      # the script's own import errors included
            why = str(error).replace(str(stage / script.name), str(script))
            raise ValueError(f"cannot build an FMU from {script}: "
                             f"{type(error).__name__}: {why}") from error
    exit_fix.fix_fmu(fmu)
    problems = validate_fmu(str(fmu))
    if problems:
        raise RuntimeError(f"{fmu} does not validate:\n" + "\n".join(problems))
    try:
        check_instantiates(fmu)
    except RuntimeError:
        fmu.unlink()
        raise
    return fmu


_TRIAL = """
import sys
sys.path = [p for p in sys.path if p not in ("", {root!r})]
sys.meta_path = [f for f in sys.meta_path if "editable" not in repr(f).lower()]
from fmpy import extract, read_model_description
from fmpy.fmi2 import FMU2Slave
description = read_model_description(sys.argv[1])
slave = FMU2Slave(guid=description.guid, unzipDirectory=extract(sys.argv[1]),
                  modelIdentifier=description.coSimulation.modelIdentifier,
                  instanceName="trial")
slave.instantiate(loggingOn=True)     # pythonfmu 0.7 logs only then
slave.freeInstance()
"""


def check_instantiates(fmu: Path) -> None:
    """Instantiate the FMU once in a fresh interpreter that cannot import this checkout:
    RuntimeError with its last words if it fails, as it would on a host without the
    modules the FMU forgot to carry."""
    with tempfile.TemporaryDirectory() as elsewhere:
        child = subprocess.run([sys.executable, "-c", _TRIAL.format(root=str(ROOT)), str(fmu)],
                               cwd=elsewhere, capture_output=True, text=True, timeout=120)
    if child.returncode != 0:
        log = [line for line in child.stdout.splitlines() if line.strip()][-3:]  # the FMU's
        words = log or [line for line in child.stderr.splitlines() if line.strip()][-3:]
        raise RuntimeError(f"{fmu.name} was built but does not instantiate without this "
                           "checkout, so it was removed; a module it imports is probably "
                           "missing from it (carry it with --include):\n  "
                           + "\n  ".join(words))


@contextlib.contextmanager
def _imports_undone(stage: str):
    """Forget what building imported from ``stage``: pythonfmu imports the script and the
    packages it carries from the temporary folder, and leaves that on sys.path. Left
    there, the next build in this process (or an in-process run) would find those stale
    modules. Modules imported from elsewhere (numpy, say) stay: they cannot be reloaded."""
    path, modules = list(sys.path), set(sys.modules)
    try:
        yield
    finally:
        sys.path[:] = path
        for name in set(sys.modules) - modules:
            if str(getattr(sys.modules[name], "__file__", None) or "").startswith(stage):
                del sys.modules[name]
