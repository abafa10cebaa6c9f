"""The build's side of an FMU's manifest (``fmukit.manifest`` reads it): who made this project's
FMUs, and the entry module this build writes (``fmubuild.routes``)."""
from __future__ import annotations

from importlib import metadata
from pathlib import Path

from fmukit.manifest import DISTRIBUTION, Manifest

from .routes import ROUTES


def project_identity() -> dict[str, str]:
    """Who made this project's FMUs, as their model descriptions say: the author, version,
    copyright and license of its distribution (pyproject.toml; with no author there, the
    project's authors by its name)."""
    meta = metadata.metadata(DISTRIBUTION)
    author = meta.get("Author") or meta.get("Author-email") or f"the {DISTRIBUTION} authors"
    return {"author": author, "version": meta["Version"], "copyright": f"Copyright (c) {author}",
            "license": meta.get("License-Expression") or meta["License"]}


def entry_source(manifest: Manifest) -> str:
    """The entry module this build writes for the FMU of ``manifest``; pass it to
    ``fmukit.manifest.staleness`` to check an FMU's against it."""
    slave_file = Path(manifest.modules[manifest.slave_module]["file"])
    return ROUTES[manifest.fmi].entry_source(manifest.model_name, slave_file.stem,
                                             manifest.slave_class)
