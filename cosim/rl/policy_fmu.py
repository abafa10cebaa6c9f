"""A trained policy as an autopilot FMU, FMI 2.0 or 3.0: ``policy_autopilot_slave`` built
with fmukit around the policy's JSON, carried in the FMU's resources."""
from __future__ import annotations

import tempfile
from pathlib import Path

from autopilot_fmu.policy import Policy
from fmubuild.packaging import PROJECT_PACKAGES, build_script
from fmubuild.project import DATA, FMUS, ROOT, project_identity

NAME = "policy_autopilot"


def build_policy_fmu(policy: Policy, dest: Path, fmi: int = 2, **about: object) -> Path:
    """``policy`` as the FMU ``dest`` (a .fmu path), validated; ``about`` goes into its JSON."""
    with tempfile.TemporaryDirectory(prefix="policy_") as tmp:
        weights = Path(tmp) / Path(DATA[NAME][0]).name
        weights.write_text(policy.to_json(**about))
        return build_script(ROOT / FMUS[NAME], (*PROJECT_PACKAGES, weights), dest,
                            project_identity(), fmi)
