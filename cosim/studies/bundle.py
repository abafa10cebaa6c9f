"""A sweep controller's system as a worker rebuilds it, each FMU named by its SHA-256: the
FMUs travel once per worker, which keeps them in its private cache (``fmu_cache``), checked
against their hashes when used; the hashes make a run's identity (``Bundle.digest``)."""
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
    """The FMU cache folder is not private to this user: anyone else who can write it could
    put code in the FMUs this worker runs."""


@dataclass(frozen=True)
class Bundle:
    """A controller's system as a worker rebuilds it."""
    system: SystemDescription          # component sources: "<sha256>.fmu"
    digest: str                        # SHA-256 of the system and its FMUs' contents

    def fmu_hashes(self) -> set[str]:
        """The SHA-256 of each of its FMUs."""
        return {Path(c.source).stem for c in self.system.components.values()}


def file_hash(path: Path) -> str:
    """SHA-256 of a file's content."""
    digest = hashlib.sha256()
    with open(path, "rb") as f:
        for block in iter(lambda: f.read(1 << 20), b""):
            digest.update(block)
    return digest.hexdigest()


def bundle(controller: dict[str, Any]) -> tuple[Bundle, dict[str, Path], SystemDescription]:
    """The bundle of a sweep controller (scenario, autopilot, map), each of its FMUs' files by
    hash, for the client to ship, and its system as loaded here."""
    system = scenarios.load(controller["scenario"], controller["autopilot"], controller["map"])
    files: dict[str, Path] = {}
    components = {}
    for name, component in system.components.items():
        path = system.fmu_path(name)
        sha = file_hash(path)
        files[sha] = path
        components[name] = dataclasses.replace(component, source=f"{sha}.fmu")
    shipped = dataclasses.replace(system, components=components, path=None, fmus=None)
    content = json.dumps(dataclasses.asdict(shipped), sort_keys=True, default=str)
    return Bundle(shipped, hashlib.sha256(content.encode()).hexdigest()), files, system


def fmu_cache() -> Path:
    """Where a worker keeps the FMUs it was sent: $COSIM_FMU_CACHE, else cosim-fmus in
    $XDG_CACHE_HOME (default ~/.cache), made 0o700; UnsafeCache unless it is a folder of
    this user's that no one else may write."""
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
    """The bundle's system with its FMUs in this machine's cache (a cached file that does not
    match its hash is written again, with a warning)."""
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
