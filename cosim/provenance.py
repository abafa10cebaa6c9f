"""What it takes to reproduce a run, as strict JSON next to its CSV: the master's record, the
FMUs' and scenario's SHA-256, the command, the versions and git commit."""
import functools
import hashlib
import json
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
ROOT = Path(__file__).resolve().parents[1]          # the checkout, or site-packages
CODE_PACKAGES = ("cosim", "fmukit", "ship_fmu", "autopilot_fmu")
NON_FINITE = {"NaN": "nan", "Infinity": "inf", "-Infinity": "-inf"}   # JSON's token: repr


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


def _fmu(fmu: dict[str, Any]) -> dict[str, Any]:
    """An FMU's entry with its SHA-256; for one built with fmukit, whether it is current."""
    entry = {**fmu, "sha256": _sha256(fmu["file"])}
    try:
        manifest = read(fmu["file"])
    except (OSError, ValueError, zipfile.BadZipFile):
        return entry
    if manifest is not None:
        stale = staleness(manifest)
        entry.update(sources_digest=manifest.digest, current=stale is None)
        if stale:
            entry["stale"] = stale
    return entry


def _commit() -> str | None:
    """The git commit of this checkout, with '+changes' if it has uncommitted ones."""
    try:
        git = subprocess.run(["git", "-C", str(ROOT), "describe", "--always", "--abbrev=40",
                              "--dirty=+changes", "--exclude=*"],
                             capture_output=True, text=True, timeout=10)
    except (OSError, subprocess.SubprocessError):
        return None
    return git.stdout.strip() if git.returncode == 0 else None


@functools.lru_cache(maxsize=1)
def code_version() -> str:
    """This package's version and a SHA-256 of its Python sources: the same string, same code."""
    digest = hashlib.sha256()
    for package in CODE_PACKAGES:
        for path in sorted((ROOT / package).rglob("*.py")):
            digest.update(f"{path.relative_to(ROOT).as_posix()}\n".encode())
            digest.update(path.read_bytes())
    return f"{_version(PACKAGE)} (code {digest.hexdigest()[:12]})"


def write_metadata(recording: Recording, path: str | Path) -> Path:
    """Write the run's metadata to ``path`` as strict JSON; returns the path."""
    meta = dict(recording.meta)
    meta["fmus"] = {name: _fmu(fmu) for name, fmu in meta.get("fmus", {}).items()}
    if meta.get("scenario_file"):
        meta["scenario_sha256"] = _sha256(meta["scenario_file"])
    meta.update(
        rows=recording.rows, error=recording.error,
        columns={"time": "s", **{c: recording.units.get(c, "") for c in recording.columns}},
        command=getattr(sys, "orig_argv", sys.argv),
        created=datetime.now(timezone.utc).isoformat(timespec="seconds"),
        versions={PACKAGE: _version(PACKAGE), "commit": _commit(),
                  "python": platform.python_version(), "numpy": _version("numpy"),
                  "fmpy": _version("fmpy"), "pythonfmu": _version("pythonfmu")})
    # a non-finite number becomes a string
    strict = json.loads(json.dumps(meta), parse_constant=NON_FINITE.get)
    path = Path(path)
    path.write_text(json.dumps(strict, indent=1, allow_nan=False) + "\n")
    return path
