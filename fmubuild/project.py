"""This project's FMUs: where their sources are, where they are built to, and who made them."""
from __future__ import annotations

from importlib import metadata
from pathlib import Path

from fmukit.manifest import DISTRIBUTION

ROOT = Path(__file__).resolve().parent.parent
FMU_DIR = ROOT / "fmus"
FMU_DIRS = {2: FMU_DIR, 3: FMU_DIR / "fmi3"}       # by FMI version, the same names in each
FMUS: dict[str, str] = {                          # name: its slave script, whose imports it carries
    "ship": "ship_fmu/ship_slave.py",
    "manoeuvre": "ship_fmu/manoeuvre_slave.py",
    "pd_autopilot": "autopilot_fmu/pd_autopilot_slave.py",
    "smc_autopilot": "autopilot_fmu/smc_autopilot_slave.py",
    "guidance": "autopilot_fmu/guidance_slave.py",
    # Written as a user's own autopilot is (docs/own_autopilot.md): one file and fmukit.
    "pid_autopilot": "autopilot_fmu/pid_autopilot_slave.py",
}
SLAVE_MODULES = frozenset(".".join(Path(script).with_suffix("").parts) for script in FMUS.values())
C_FMUS = {"pd_autopilot_c": "autopilot_fmu/pd_autopilot_c"}       # name: its sources' folder
BUILD_HINT = "build the FMUs with: python -m fmukit.build"


def project_identity() -> dict[str, str]:
    """Its FMUs' author (with none in pyproject.toml, its authors), version, copyright, license."""
    meta = metadata.metadata(DISTRIBUTION)
    author = meta.get("Author") or meta.get("Author-email") or f"the {DISTRIBUTION} authors"
    return {"author": author, "version": meta["Version"], "copyright": f"Copyright (c) {author}",
            "license": meta.get("License-Expression") or meta["License"]}
