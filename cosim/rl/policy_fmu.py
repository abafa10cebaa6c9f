"""A trained policy as an autopilot FMU, FMI 2.0 or 3.0: ``policy_autopilot_slave`` built
with fmukit around the policy's JSON, carried in the FMU's resources, its model (and so its
Python modules in a host's one interpreter) named for it."""
from __future__ import annotations

import importlib.util
import keyword
import tempfile
from pathlib import Path

from autopilot_fmu.policy import Policy
from fmubuild.packaging import PROJECT_PACKAGES, build_script
from fmubuild.project import C_FMUS, FMUS, ROOT, project_identity

SHIPPED = "policy_autopilot"


def checked_name(name: str) -> str:
    """``name`` if it can name a trained policy's model and its Python module, else
    ValueError saying why: its FMU's modules live in the host's one interpreter."""
    why = ("is not a Python identifier (letters, digits and _, not starting with a digit)"
           if not name.isidentifier() else "is a Python keyword" if keyword.iskeyword(name)
           else "is the name of one of this project's FMUs" if name in {*FMUS, *C_FMUS}
           else "is the name of a Python module here, which the FMU's would clash with"
           if importlib.util.find_spec(name) is not None else None)
    if why:
        raise ValueError(f"--name {name!r} {why}: a trained policy's FMU and its module are "
                         "named by it; choose another, e.g. learned")
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
