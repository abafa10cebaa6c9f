"""What it takes to reproduce a run, written as JSON next to its CSV.

The unit of every column, every parameter value the FMUs held (defaults and what
was set) with its unit, the settings given on top of the scenario, each FMU's
file, GUID and SHA-256, the coupling, step and times, the wall time, and the
versions of this package, Python, fmpy and pythonfmu.
"""
from __future__ import annotations

import hashlib
import json
import platform
import sys
from datetime import datetime, timezone
from importlib import metadata
from pathlib import Path
from typing import Any

from .recording import Recording

PACKAGE = "ship-autopilot-cosim"


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


def run_metadata(recording: Recording, command: list[str] | None = None) -> dict[str, Any]:
    """The metadata of a run, as plain JSON-able values."""
    meta = dict(recording.meta)
    meta["fmus"] = {name: {**fmu, "sha256": _sha256(fmu["file"])}
                    for name, fmu in meta.get("fmus", {}).items()}
    return {
        **meta,
        "rows": recording.rows,
        "error": recording.error,
        "columns": {column: recording.units.get(column, "") for column in recording.columns},
        "command": command if command is not None else sys.argv,
        "created": datetime.now(timezone.utc).isoformat(timespec="seconds"),
        "versions": {PACKAGE: _version(PACKAGE), "python": platform.python_version(),
                     "fmpy": _version("fmpy"), "pythonfmu": _version("pythonfmu")},
    }


def write_metadata(recording: Recording, path: str | Path,
                   command: list[str] | None = None) -> Path:
    """Write ``run_metadata`` to ``path`` (JSON); returns the path."""
    path = Path(path)
    path.write_text(json.dumps(run_metadata(recording, command), indent=1, allow_nan=True)
                    + "\n")
    return path
