"""Shared fixtures: FMUs built from the current sources."""
from __future__ import annotations

from pathlib import Path

import pytest

from fmukit.build import FMU_DIR, FMUS, ROOT, build


def _stale(name: str) -> bool:
    fmu = FMU_DIR / f"{name}.fmu"
    if not fmu.exists():
        return True
    sources = [ROOT / FMUS[name][0]] + [p for pkg in FMUS[name][1]
                                        for p in (ROOT / pkg).rglob("*.py")]
    return max(p.stat().st_mtime for p in sources) > fmu.stat().st_mtime


@pytest.fixture(scope="session")
def fmu_paths() -> dict[str, Path]:
    """Every FMU in fmus/, rebuilt first if missing or older than its sources."""
    for name in FMUS:
        if _stale(name):
            build(name)
    return {name: FMU_DIR / f"{name}.fmu" for name in FMUS}
