"""What a worker needs to run a sweep's controller, shipped from the client by content.

A worker needs only a Python environment with this project installed (a wheel: no
checkout, no build step). The client reads each controller's system (its scenario,
with a user's autopilot in place if given) and hashes every FMU it uses; a
``Bundle`` carries the system with each FMU named by its SHA-256, and the FMU
files travel once per worker as Dask data, addressed by that hash. A worker writes
each FMU once into its cache folder (``fmu_cache``) and points the system at it.

The same hashes make a run's identity (``Bundle.digest``): anything that changes an
FMU or the system changes the digest, and so every run id of that controller.
"""
from __future__ import annotations

import dataclasses
import hashlib
import json
import os
import tempfile
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from .. import scenarios
from ..core.ssd import SystemDescription


@dataclass(frozen=True)
class Bundle:
    """A controller's system as a worker rebuilds it."""
    system: SystemDescription          # component sources: "<sha256>.fmu"
    digest: str                        # SHA-256 of the system and its FMUs' contents

    def fmu_hashes(self) -> set[str]:
        return {Path(c.source).stem for c in self.system.components.values()}


def file_hash(path: Path) -> str:
    """SHA-256 of a file's content."""
    digest = hashlib.sha256()
    with open(path, "rb") as f:
        for block in iter(lambda: f.read(1 << 20), b""):
            digest.update(block)
    return digest.hexdigest()


def bundle(controller: dict[str, Any]) -> tuple[Bundle, dict[str, Path]]:
    """The bundle of a sweep controller (scenario, autopilot, map), and each of its FMUs'
    files by hash, for the client to ship."""
    system = scenarios.load(controller["scenario"], controller["autopilot"], controller["map"])
    files: dict[str, Path] = {}
    components = {}
    for name, component in system.components.items():
        path = system.fmu_path(name)
        sha = file_hash(path)
        files[sha] = path
        components[name] = dataclasses.replace(component, source=f"{sha}.fmu")
    shipped = dataclasses.replace(system, components=components, path=None)
    content = json.dumps(dataclasses.asdict(shipped), sort_keys=True, default=str)
    return Bundle(shipped, hashlib.sha256(content.encode()).hexdigest()), files


def fmu_cache() -> Path:
    """Where a worker keeps the FMUs it was sent: $COSIM_FMU_CACHE, or a folder in the
    temporary directory."""
    folder = Path(os.environ.get("COSIM_FMU_CACHE")
                  or Path(tempfile.gettempdir()) / f"cosim-fmus-{os.getuid()}")
    folder.mkdir(parents=True, exist_ok=True)
    return folder


def materialise(shipped: Bundle, blobs: dict[str, bytes]) -> SystemDescription:
    """The bundle's system with its FMUs in this machine's cache (written once, by hash)."""
    cache = fmu_cache()
    components = {}
    for name, component in shipped.system.components.items():
        sha = Path(component.source).stem
        target = cache / f"{sha}.fmu"
        if not target.exists():
            data = blobs[sha]
            if hashlib.sha256(data).hexdigest() != sha:
                raise ValueError(f"the FMU sent for component '{name}' does not match its "
                                 f"hash {sha[:12]}")
            temporary = target.with_name(f".{sha}.{os.getpid()}.tmp")
            temporary.write_bytes(data)
            os.replace(temporary, target)        # atomic: another worker may write it too
        components[name] = dataclasses.replace(component, source=str(target))
    return dataclasses.replace(shipped.system, components=components)
