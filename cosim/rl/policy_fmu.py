"""A trained policy as an autopilot FMU, FMI 2.0 or 3.0: ``policy_autopilot_slave`` built
with fmukit around the policy's JSON, carried in the FMU's resources, its model (and so its
Python modules in a host's one interpreter) named for it."""
from __future__ import annotations

import tempfile
from pathlib import Path

from autopilot_fmu.policy import Policy
from fmubuild.packaging import PROJECT_PACKAGES, build_script
from fmubuild.project import FMUS, ROOT, project_identity

SHIPPED = "policy_autopilot"


def checked_name(name: str) -> str:
    """``name`` if it can name a trained policy's model, else ValueError saying why."""
    if not name.isidentifier() or name == SHIPPED:
        raise ValueError(f"--name {name!r}: a trained policy's FMU is named by an identifier "
                         f"(letters, digits, _) other than {SHIPPED}, the shipped one's")
    return name


def build_policy_fmu(policy: Policy, dest: Path, fmi: int = 2, **about: object) -> Path:
    """``policy`` as the FMU ``dest`` (a .fmu path; its stem names the model), validated;
    ``about`` goes into its JSON."""
    name = checked_name(dest.stem)
    with tempfile.TemporaryDirectory(prefix="policy_") as tmp:
        script, weights = Path(tmp) / f"{name}.py", Path(tmp) / f"{name}.json"
        script.write_text((ROOT / FMUS[SHIPPED]).read_text().replace(SHIPPED, name))
        weights.write_text(policy.to_json(**about))
        return build_script(script, (*PROJECT_PACKAGES, weights), dest, project_identity(), fmi)
