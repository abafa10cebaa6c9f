"""What it takes to reproduce a run, written as JSON next to its CSV.

Besides what the master records (``Master.run_meta``: units, parameters as held and as set,
backends, step, times), each FMU's SHA-256 (and, for one built with fmukit, its sources'
digest and whether they are this process's: ``current``), the scenario's SHA-256, the
command, and the versions of this package (with its git commit), Python, numpy, fmpy and
pythonfmu. Strict JSON: a non-finite number is written as a string.
"""
from __future__ import annotations

import functools
import hashlib
import importlib.util
import json
import math
import platform
import subprocess
import sys
import zipfile
from datetime import datetime, timezone
from importlib import metadata
from pathlib import Path
from typing import Any

from fmukit.manifest import read, staleness

from .core.recording import Recording

PACKAGE = "ship-autopilot-cosim"
CODE_PACKAGES = ("cosim", "fmukit", "ship_fmu", "autopilot_fmu")


def _version(distribution: str) -> str | None:
    try:
        return metadata.version(distribution)
    except metadata.PackageNotFoundError:
        return None


def _sha256(path: str) -> str | None:
    try:
        return hashlib.sha256(Path(path).read_bytes()).hexdigest()
    except OSError:
        return None


def _manifest(path: str) -> dict[str, Any]:
    """An FMU built with fmukit: its sources' digest, and whether they are this process's
    (``fmukit.manifest.staleness``); nothing for any other FMU."""
    try:
        manifest = read(path)
    except (OSError, ValueError, zipfile.BadZipFile):
        return {}
    if manifest is None:
        return {}
    stale = staleness(manifest)
    return {"sources_digest": manifest.digest, "current": stale is None,
            **({"stale": stale} if stale else {})}


def _commit() -> str | None:
    """The git commit of this checkout, with '+changes' if it has uncommitted ones."""
    root = Path(__file__).resolve().parents[1]
    try:
        head = subprocess.run(["git", "-C", str(root), "rev-parse", "HEAD"], capture_output=True,
                              text=True, timeout=10)
        dirty = subprocess.run(["git", "-C", str(root), "status", "--porcelain",
                                "--untracked-files=no"], capture_output=True, text=True,
                               timeout=10)
    except (OSError, subprocess.SubprocessError):
        return None
    if head.returncode != 0:
        return None
    return head.stdout.strip() + ("+changes" if dirty.stdout.strip() else "")


@functools.lru_cache(maxsize=1)
def code_version() -> str:
    """This package's version and a SHA-256 of its Python sources (12 digits): two
    environments with the same string run the same code, from a checkout or a wheel."""
    digest = hashlib.sha256()
    for package in CODE_PACKAGES:
        root = Path(importlib.util.find_spec(package).submodule_search_locations[0])
        for path in sorted(root.rglob("*.py")):
            digest.update(f"{package}/{path.relative_to(root).as_posix()}\n".encode())
            digest.update(path.read_bytes())
    return f"{_version(PACKAGE)} (code {digest.hexdigest()[:12]})"


def _strict(value: Any) -> Any:
    """JSON without NaN or Infinity tokens: a non-finite number becomes its name, a string."""
    if isinstance(value, float) and not math.isfinite(value):
        return repr(value)
    if isinstance(value, dict):
        return {k: _strict(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [_strict(v) for v in value]
    return value


def run_metadata(recording: Recording, command: list[str] | None = None) -> dict[str, Any]:
    """The metadata of a run, as plain JSON values (non-finite numbers as strings)."""
    meta = dict(recording.meta)
    meta["fmus"] = {name: {**fmu, "sha256": _sha256(fmu["file"]), **_manifest(fmu["file"])}
                    for name, fmu in meta.get("fmus", {}).items()}
    if meta.get("scenario_file"):
        meta["scenario_sha256"] = _sha256(meta["scenario_file"])
    return _strict({
        **meta,
        "rows": recording.rows,
        "error": recording.error,
        "columns": {"time": "s", **{column: recording.units.get(column, "")
                                    for column in recording.columns}},
        "command": command if command is not None else getattr(sys, "orig_argv", sys.argv),
        "created": datetime.now(timezone.utc).isoformat(timespec="seconds"),
        "versions": {PACKAGE: _version(PACKAGE), "commit": _commit(),
                     "python": platform.python_version(), "numpy": _version("numpy"),
                     "fmpy": _version("fmpy"), "pythonfmu": _version("pythonfmu")},
    })


def write_metadata(recording: Recording, path: str | Path,
                   command: list[str] | None = None) -> Path:
    """Write ``run_metadata`` to ``path`` as strict JSON; returns the path."""
    path = Path(path)
    path.write_text(json.dumps(run_metadata(recording, command), indent=1, allow_nan=False)
                    + "\n")
    return path
