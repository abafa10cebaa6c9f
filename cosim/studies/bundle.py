"""A sweep controller's system as a worker rebuilds it, each FMU named by its SHA-256: sent
once per worker, kept in its private cache (``fmu_cache``) and checked when used."""
from __future__ import annotations

import dataclasses
import hashlib
import json
import os
import stat
import sys
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from .. import scenarios
from ..core.files import write_atomically
from ..core.ssd import SystemDescription


class UnsafeCache(RuntimeError):
    """The FMU cache is not private: whoever else may write it could change the FMUs run."""


@dataclass(frozen=True)
class Bundle:
    """A controller's system as a worker rebuilds it."""
    system: SystemDescription          # component sources: "<sha256>.fmu"
    digest: str                        # SHA-256 of the system and its FMUs' contents

    def fmu_hashes(self) -> set[str]:
        return {Path(c.source).stem for c in self.system.components.values()}


def file_hash(path: Path) -> str:
    with open(path, "rb") as f:
        return hashlib.file_digest(f, "sha256").hexdigest()


def bundle(controller: dict[str, Any]) -> tuple[Bundle, dict[str, Path], SystemDescription]:
    """A sweep controller's bundle, its FMUs' files by hash, and its system as loaded here."""
    system = scenarios.load(controller["scenario"], controller["autopilot"], controller["map"])
    hashes = {name: file_hash(system.fmu_path(name)) for name in system.components}
    files = {sha: system.fmu_path(name) for name, sha in hashes.items()}
    components = {name: dataclasses.replace(component, source=f"{hashes[name]}.fmu")
                  for name, component in system.components.items()}
    shipped = dataclasses.replace(system, components=components, path=None, fmus=None)
    content = json.dumps(dataclasses.asdict(shipped), sort_keys=True, default=str)
    return Bundle(shipped, hashlib.sha256(content.encode()).hexdigest()), files, system


def fmu_cache() -> Path:
    """Where a worker keeps the FMUs it was sent: $COSIM_FMU_CACHE, else cosim-fmus in
    $XDG_CACHE_HOME or ~/.cache, made 0o700; UnsafeCache unless only this user may write it."""
    folder = Path(os.environ.get("COSIM_FMU_CACHE")
                  or Path(os.environ.get("XDG_CACHE_HOME") or Path.home() / ".cache")
                  / "cosim-fmus")
    folder.mkdir(mode=0o700, parents=True, exist_ok=True)
    facts = os.lstat(folder)
    if not stat.S_ISDIR(facts.st_mode):
        raise UnsafeCache(f"the FMU cache {folder} is not a folder (a symbolic link?); remove "
                          "it, or set COSIM_FMU_CACHE to a folder of your own")
    if facts.st_uid != os.getuid() or facts.st_mode & 0o022:
        whose = (f"belongs to another user (uid {facts.st_uid})" if facts.st_uid != os.getuid()
                 else f"may be written by others (mode {stat.filemode(facts.st_mode)})")
        raise UnsafeCache(f"the FMU cache {folder} {whose}, who could change the FMUs run "
                          "from it; use a folder only you may write (chmod go-w, or set "
                          "COSIM_FMU_CACHE)")
    return folder


def materialise(shipped: Bundle, blobs: dict[str, bytes]) -> SystemDescription:
    """The bundle's system, its FMUs in this machine's cache (a corrupt one written again)."""
    cache = fmu_cache()
    components = {}
    for name, component in shipped.system.components.items():
        sha = Path(component.source).stem
        target = cache / f"{sha}.fmu"
        corrupt = target.exists() and file_hash(target) != sha
        if corrupt:
            print(f"warning: the FMU cache's {target} does not match its hash (a corrupt or "
                  "changed file); written again from the FMU sent", file=sys.stderr)
        if corrupt or not target.exists():
            data = blobs[sha]
            if hashlib.sha256(data).hexdigest() != sha:
                raise ValueError(f"the FMU sent for component '{name}' does not match its "
                                 f"hash {sha[:12]}")
            write_atomically(target, lambda path: path.write_bytes(data))  # noqa: B023
        components[name] = dataclasses.replace(component, source=str(target))
    return dataclasses.replace(shipped.system, components=components)
