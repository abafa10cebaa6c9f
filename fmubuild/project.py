"""This project's FMUs (where their sources are, where they are built to, who made them) and
the FMI versions fmubuild builds, each by the one pythonfmu version its adapter knows."""
from __future__ import annotations

from dataclasses import asdict, dataclass
from importlib import metadata
from pathlib import Path

from fmukit.manifest import DISTRIBUTION, Manifest

ROOT = Path(__file__).resolve().parent.parent
FMU_DIR = ROOT / "fmus"
FMU_DIRS = {2: FMU_DIR, 3: FMU_DIR / "fmi3"}       # by FMI version, the same names in each
FMUS: dict[str, str] = {                          # name: its slave script, whose imports it carries
    "ship": "ship_fmu/ship_slave.py",
    "manoeuvre": "ship_fmu/manoeuvre_slave.py",
    "environment": "ship_fmu/environment_slave.py",     # current and wind, into the ship
    "sensors": "ship_fmu/sensors_slave.py",             # between the ship and its controllers
    "pd_autopilot": "autopilot_fmu/pd_autopilot_slave.py",
    "smc_autopilot": "autopilot_fmu/smc_autopilot_slave.py",
    "guidance": "autopilot_fmu/guidance_slave.py",
    "los_guidance": "autopilot_fmu/los_guidance_slave.py",     # in eq (18)'s guidance's place
    "observer": "autopilot_fmu/observer_slave.py",      # between the compass and the autopilot
    # Written as a user's own autopilot is (docs/own_autopilot.md): one file and fmukit.
    "pid_autopilot": "autopilot_fmu/pid_autopilot_slave.py",
    # Trained by cosim.train (docs/rl.md); its weights in its resources.
    "policy_autopilot": "autopilot_fmu/policy_autopilot_slave.py",
}
DATA = {"policy_autopilot": ("autopilot_fmu/policy_autopilot.json",)}   # files an FMU reads
SLAVE_MODULES = frozenset(".".join(Path(script).with_suffix("").parts) for script in FMUS.values())
C_FMUS = {"pd_autopilot_c": "autopilot_fmu/pd_autopilot_c"}       # name: its sources' folder
BUILD_HINT = "build the FMUs with: python -m fmukit.build"


def project_identity() -> dict[str, str]:
    """Its FMUs' author (with none in pyproject.toml, its authors), version, copyright, license."""
    meta = metadata.metadata(DISTRIBUTION)
    author = meta.get("Author") or meta.get("Author-email") or f"the {DISTRIBUTION} authors"
    return {"author": author, "version": meta["Version"], "copyright": f"Copyright (c) {author}",
            "license": meta.get("License-Expression") or meta["License"]}


_ENTRY = '''"""The FMI {fmi}.0 entry of the FMU {model_name}, written by fmubuild.project: {cls}
of {module} as an FMI {fmi}.0 co-simulation FMU of {pythonfmu} {known}."""
from {pythonfmu} import Fmi{fmi}Slave

from {adapter}.slave import {imported}
from {module} import {cls} as _Model
{calls}

class {cls}(Fmi{fmi}Entry, _Model, Fmi{fmi}Slave):
    """{cls} of {module}, on FMI {fmi}.0."""
'''


@dataclass(frozen=True)
class Route:
    """How an FMU of one FMI version is built."""
    fmi: int
    pythonfmu: str                  # the package that builds it (its import name)
    known: str                      # the one version of it that the adapter knows
    adapter: str                    # fmukit's adapter package
    options: dict[str, bool]        # the builder's options (FMI 2.0 and 3.0 spell them apart)
    linux: str                      # the platform folder of the FMU's Linux binary
    namespace_calls: tuple[str, ...] = ()   # the entry module calls them on its globals()

    def entry_source(self, model_name: str, module: str, cls: str) -> str:
        """The entry module's source: ``cls`` of ``module`` composed for this version."""
        return _ENTRY.format(**asdict(self), model_name=model_name, module=module, cls=cls,
                             imported=", ".join([f"Fmi{self.fmi}Entry", *self.namespace_calls]),
                             calls="".join(f"{f}(globals())\n" for f in self.namespace_calls))


ROUTES = {
    # pythonfmu 0.7 releases the entry module's namespace once per instantiation.
    2: Route(2, "pythonfmu", "0.7.0", "fmukit.pythonfmu07",
             {"canGetAndSetFMUstate": True, "canSerializeFMUstate": True}, "linux64",
             ("hold_namespace",)),
    # canHandleVariableCommunicationStepSize given, else pythonfmu3 0.3.4 writes a stale value.
    3: Route(3, "pythonfmu3", "0.3.4", "fmukit.pythonfmu3_03",
             {"canGetAndSetFMUState": True, "canSerializeFMUState": True,
              "canHandleVariableCommunicationStepSize": True}, "x86_64-linux"),
}


def entry_source(manifest: Manifest) -> str:
    """The entry module this build writes for ``manifest``'s FMU."""
    module = Path(manifest.modules[manifest.slave_module]["file"]).stem
    return ROUTES[manifest.fmi].entry_source(manifest.model_name, module, manifest.slave_class)
