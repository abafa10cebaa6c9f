"""What an FMU built with fmukit carries about itself (no time, path or machine: the same
sources, the same manifest), and whether it is current here. Format 1 (before FMI 3.0) is
read so that ``staleness`` can say to rebuild."""
from __future__ import annotations

import hashlib
import importlib.util
import json
import zipfile
from dataclasses import dataclass
from importlib import metadata
from pathlib import Path
from typing import Callable

MANIFEST = "resources/fmukit_manifest.json"
FORMAT = 2
DISTRIBUTION = "ship-autopilot-cosim"      # its version is fmukit's


@dataclass(frozen=True)
class Manifest:
    model_name: str
    slave_module: str                       # as the host imports it
    slave_class: str
    modules: dict[str, dict[str, str]]      # module: {"file": in the FMU, "sha256": ...}
    digest: str                             # of every module's name and SHA-256
    pythonfmu: str                          # the version of the pythonfmu that built it
    options: dict[str, bool]
    version: str | None                     # fmukit's that built it; None before it was kept
    fmi: int = 2
    entry: dict[str, str] | None = None     # {"module", "file", "sha256"}; None in format 1

    def to_json(self) -> str:
        return json.dumps({"format": FORMAT, "model_name": self.model_name,
                           "slave": {"module": self.slave_module, "class": self.slave_class},
                           "modules": self.modules, "digest": self.digest,
                           "pythonfmu": self.pythonfmu, "options": self.options,
                           "version": self.version, "fmi": self.fmi, "entry": self.entry},
                          indent=1, sort_keys=True) + "\n"


def version() -> str:
    return metadata.version(DISTRIBUTION)


def sha256(path: Path) -> str:
    return hashlib.sha256(Path(path).read_bytes()).hexdigest()


def digest_of(modules: dict[str, str]) -> str:
    """SHA-256 over each module's name and source SHA-256."""
    return hashlib.sha256("".join(f"{name} {modules[name]}\n" for name in sorted(modules))
                          .encode()).hexdigest()


def read(fmu: str | Path) -> Manifest | None:
    """The manifest of an FMU, None if it has none; ValueError naming the file if unreadable."""
    with zipfile.ZipFile(fmu) as package:
        if MANIFEST not in package.namelist():
            return None
        try:
            data = json.loads(package.read(MANIFEST))
            if data["format"] not in (1, FORMAT):
                raise ValueError(f"format {data['format']}, not {FORMAT}")
            extra = {"fmi": data["fmi"], "entry": data["entry"]} if data["format"] > 1 else {}
            return Manifest(data["model_name"], data["slave"]["module"],
                            data["slave"]["class"], data["modules"], data["digest"],
                            data["pythonfmu"], data["options"], data.get("version"), **extra)
        except (KeyError, TypeError, ValueError) as error:
            raise ValueError(f"{fmu}: its {MANIFEST} cannot be read ({error})") from error


def staleness(manifest: Manifest,
              entry_source: Callable[[Manifest], str] | None = None) -> str | None:
    """Why the FMU is not current in this process (another fmukit, a module it carries
    missing or changed, with ``entry_source`` its entry module changed), or None."""
    if manifest.version != version():
        return (f"it was built by fmukit {manifest.version or 'of an older version'}, this "
                f"is fmukit {version()} (rebuild it)")
    for module, carried in manifest.modules.items():
        try:
            spec = importlib.util.find_spec(module)
        except (ImportError, ValueError):
            spec = None
        if spec is None or not spec.origin or not Path(spec.origin).is_file():
            return f"its module {module} is not importable here"
        if sha256(Path(spec.origin)) != carried["sha256"]:
            return f"its {module} differs from {spec.origin} (built before a change: rebuild it)"
    if entry_source is not None and manifest.entry and hashlib.sha256(
            entry_source(manifest).encode()).hexdigest() != manifest.entry["sha256"]:
        return (f"its entry module {manifest.entry['module']} is not the one this build writes "
                "(built before a change of fmubuild.project: rebuild it)")
    return None
