"""Shared fixtures: FMUs built from the current sources."""
from __future__ import annotations

import gc
from pathlib import Path

import pytest

from fmukit.packaging import FMU_DIR, FMUS, ROOT, build


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


@pytest.fixture
def open_fmu(fmu_paths):
    """Factory of FmuInstance objects, freed (and garbage-collected) after the test."""
    from cosim.core.fmi import FmuInstance

    opened = []

    def open_(name: str, instance_name: str | None = None) -> FmuInstance:
        instance = FmuInstance(fmu_paths[name], instance_name or name)
        opened.append(instance)
        return instance

    yield open_
    for instance in opened:
        instance.free()
    gc.collect()            # a host corrupted by an FMU would crash here, inside the test

