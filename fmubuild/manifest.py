"""What an FMU built with fmukit carries, and whether it is current: its manifest.

Every such FMU holds ``resources/fmukit_manifest.json``: its model name, the slave
class (module and name, as this project imports them), each Python module it
carries (the module's name, where the FMU holds it, the SHA-256 of its source), a
digest of them all, its FMI version (2 or 3), the entry module the build wrote for it
(its module name, which ``slavemodule.txt`` gives pythonfmu, its file and SHA-256: it
defines the FMU's class, the slave class composed with the version's adapter), the
version of the pythonfmu that built it (pythonfmu3's for FMI 3.0) and the options it
was built with, and the version of fmukit that built it (this project's, which the FMU
declares as its own). No time, path or machine is in it, so the same sources give the
same manifest. A manifest of format 1 (before FMI 3.0) is an FMI 2.0 FMU's without an
entry module: read, so that ``staleness`` can say to rebuild it.

An FMU is current when it was built by this project's version, every module it
carries is importable in this process and has the same source, and its entry module is
the one this build writes (``fmubuild.routes``): ``staleness`` says why not, or None.
This is the one notion of a stale FMU: the in-process backend runs only current FMUs, a
run's metadata records it, and the tests rebuild what is not.
"""
from __future__ import annotations

import hashlib
import importlib.util
import json
import zipfile
from dataclasses import dataclass
from importlib import metadata
from pathlib import Path

from .routes import ROUTES

MANIFEST = "resources/fmukit_manifest.json"
FORMAT = 2
DISTRIBUTION = "ship-autopilot-cosim"
"""This project's distribution, fmukit's."""


@dataclass(frozen=True)
class Manifest:
    model_name: str
    slave_module: str                       # as this project imports it
    slave_class: str
    modules: dict[str, dict[str, str]]      # module: {"file": in the FMU, "sha256": ...}
    digest: str                             # of every module's name and SHA-256
    pythonfmu: str                          # the version of the pythonfmu that built it
    options: dict[str, bool]
    version: str | None                     # fmukit's that built it; None before it was kept
    fmi: int = 2                            # the FMI version
    entry: dict[str, str] | None = None     # {"module", "file", "sha256"}; None in format 1

    def to_json(self) -> str:
        return json.dumps({"format": FORMAT, "model_name": self.model_name,
                           "slave": {"module": self.slave_module, "class": self.slave_class},
                           "modules": self.modules, "digest": self.digest,
                           "pythonfmu": self.pythonfmu, "options": self.options,
                           "version": self.version, "fmi": self.fmi, "entry": self.entry},
                          indent=1, sort_keys=True) + "\n"


def version() -> str:
    """This project's version (fmukit's): its installed distribution's, as pyproject.toml
    gives it."""
    return metadata.version(DISTRIBUTION)


def project_identity() -> dict[str, str]:
    """Who made this project's FMUs, as their model descriptions say: the author, version,
    copyright and license of its distribution (pyproject.toml; with no author there, the
    project's authors by its name)."""
    meta = metadata.metadata(DISTRIBUTION)
    author = meta.get("Author") or meta.get("Author-email") or f"the {DISTRIBUTION} authors"
    return {"author": author, "version": meta["Version"], "copyright": f"Copyright (c) {author}",
            "license": meta.get("License-Expression") or meta["License"]}


def sha256(path: Path) -> str:
    return hashlib.sha256(path.read_bytes()).hexdigest()


def digest_of(modules: dict[str, str]) -> str:
    """The digest of a set of modules: SHA-256 over each one's name and source SHA-256."""
    return hashlib.sha256("".join(f"{name} {modules[name]}\n" for name in sorted(modules))
                          .encode()).hexdigest()


def read(fmu: str | Path) -> Manifest | None:
    """The manifest of an FMU, or None if it has none (not built with fmukit).
    ValueError naming the file if it has one that cannot be read."""
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


def staleness(manifest: Manifest) -> str | None:
    """Why the FMU is not current in this process (built by another version of fmukit, or
    a module it carries cannot be found here, or has another source, or its entry module
    is not the one this build writes), or None if it is."""
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
    written = manifest.entry and hashlib.sha256(entry_source(manifest).encode()).hexdigest()
    if written and written != manifest.entry["sha256"]:
        return (f"its entry module {manifest.entry['module']} is not the one this build writes "
                "(built before a change of fmubuild.routes: rebuild it)")
    return None


def entry_source(manifest: Manifest) -> str:
    """The entry module this build writes for the FMU of ``manifest`` (``fmubuild.routes``)."""
    slave_file = Path(manifest.modules[manifest.slave_module]["file"])
    return ROUTES[manifest.fmi].entry_source(manifest.model_name, slave_file.stem,
                                             manifest.slave_class)
