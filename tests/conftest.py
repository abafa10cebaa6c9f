"""Shared fixtures: FMUs built from the current sources."""
from __future__ import annotations

import gc
import os
from pathlib import Path
from typing import Iterator

import pytest

from fmubuild.cbuild import build_c, c_compiler, sources
from fmubuild.manifest import read, staleness
from fmubuild.packaging import build
from fmubuild.project import C_FMUS, FMU_DIRS, FMUS, ROOT

pytest_plugins = ["pytester"]       # to run the example test file for each autopilot

HARD_LIMIT = 1200
"""Seconds any test may take, its fixtures' setup included, unless it has a limit of its own:
more than the whole suite's budget (15 min), so only a hang reaches it."""


def pytest_collection_modifyitems(items: list[pytest.Item]) -> None:
    """Every test without ``@pytest.mark.timeout`` gets HARD_LIMIT (pytest-timeout's thread
    method: it prints every thread's stack and ends the session, wherever the test is stuck,
    instead of waiting for ever)."""
    for item in items:
        if item.get_closest_marker("timeout") is None:
            item.add_marker(pytest.mark.timeout(HARD_LIMIT, method="thread"))


@pytest.fixture(scope="session", autouse=True)
def fmu_cache(tmp_path_factory) -> Iterator[Path]:
    """The sweeps' workers keep the FMUs they are sent in the test session's own folder,
    not the user's cache (``cosim.studies.bundle.fmu_cache``); set before any cluster
    starts, so that its workers inherit it."""
    folder = tmp_path_factory.mktemp("fmu_cache")
    folder.chmod(0o700)
    previous = os.environ.get("COSIM_FMU_CACHE")
    os.environ["COSIM_FMU_CACHE"] = str(folder)
    yield folder
    if previous is None:
        os.environ.pop("COSIM_FMU_CACHE", None)
    else:
        os.environ["COSIM_FMU_CACHE"] = previous


def _stale(path: Path) -> bool:
    """Missing, built without a manifest, or not current: a module it carries differs
    from this checkout's."""
    manifest = read(path) if path.exists() else None
    return manifest is None or staleness(manifest) is not None


def _older(fmu: Path, sources: list[Path]) -> bool:
    return not fmu.exists() or max(p.stat().st_mtime for p in sources) > fmu.stat().st_mtime


def _current(fmi: int) -> dict[str, Path]:
    """Every FMU of FMI version ``fmi`` in its folder, rebuilt first if missing or not
    current (its manifest against the sources; the C FMU, which has none, by file times,
    its build script's included, and only where there is a C compiler)."""
    folder = FMU_DIRS[fmi]
    for name in FMUS:
        if _stale(folder / f"{name}.fmu"):
            build(name, fmi=fmi)
    built = list(FMUS)
    if c_compiler() is not None:
        for name in C_FMUS:
            if _older(folder / f"{name}.fmu", [*sources(name, fmi),
                                                ROOT / "fmubuild" / "cbuild.py"]):
                build_c(name, fmi=fmi)
        built += list(C_FMUS)
    return {name: folder / f"{name}.fmu" for name in built}


@pytest.fixture(scope="session")
def fmu_paths() -> dict[str, Path]:
    """Every FMI 2.0 FMU in fmus/, current (``_current``)."""
    return _current(2)


@pytest.fixture(scope="session")
def fmi3_paths() -> dict[str, Path]:
    """Every FMI 3.0 twin in fmus/fmi3/, current (``_current``)."""
    return _current(3)


@pytest.fixture
def c_autopilot(fmu_paths) -> Path:
    """The autopilot in C; the test is skipped, saying why, on a machine without a compiler."""
    if "pd_autopilot_c" not in fmu_paths:
        pytest.skip("no C compiler on this machine (set CC or install gcc)")
    return fmu_paths["pd_autopilot_c"]


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
