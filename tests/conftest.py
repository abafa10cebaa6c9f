"""Shared fixtures: FMUs built from the current sources; the quick suite and the whole one.

``pytest`` runs the quick suite, which CI runs: every test but those marked ``long``, and
the tests that ask for ``long_run`` (the fuzzing campaigns) shortened. ``pytest --long``
runs the whole suite, every test at full length. A marker expression of one's own chooses
alone: ``pytest -m long`` runs only the tests the quick suite leaves out. Each test file
with long tests says which it keeps quick, and why they still cover what it tests."""
from __future__ import annotations

import contextlib
import fcntl
import gc
import os
import shutil
import tempfile
from pathlib import Path
from typing import Callable, Iterator

import pytest

from fmubuild.cbuild import build_c, c_compiler, sources
from fmubuild.packaging import build, build_script
from fmubuild.project import C_FMUS, FMU_DIRS, FMUS, ROOT, entry_source
from fmukit.manifest import read, staleness

pytest_plugins = ["pytester"]       # to run the example test file for each autopilot

HARD_LIMIT = 1200
"""Seconds any test may take, its fixtures' setup included, unless it has a limit of its own:
more than the whole suite takes, so only a hang reaches it."""
_FIRST = {name: k for k, name in enumerate((
    "test_fault_matrix.py", "test_run_lifecycle.py", "test_sweep_hostile.py",
    "test_scorecard.py", "test_fuzz.py", "test_sweep.py", "test_api.py", "test_fmi3_tools.py"))}
"""The files that take longest, collected first: pytest-xdist hands out whole files in
collection order (``--dist loadfile``), so the workers end together instead of one
finishing a long file alone."""
LONG = "pytest --long"
"""The command that runs the whole suite."""
_LEFT_OUT = pytest.StashKey[int]()
_SHORTENED = pytest.StashKey[int]()


def pytest_addoption(parser: pytest.Parser) -> None:
    parser.addoption("--long", action="store_true", dest="long_run",
                     help="run the whole suite: the tests marked long too, and the fuzzing "
                          "campaigns at full length (without it: the quick suite, as CI "
                          "runs it)")


def pytest_xdist_auto_num_workers(config: pytest.Config) -> int:
    """``-n auto``: a worker per core this process may use, and one more: many tests wait on a
    child process, a cluster or a grace period with their core idle (docs/performance.md)."""
    return len(os.sched_getaffinity(0)) + 1 if hasattr(os, "sched_getaffinity") else (
        (os.cpu_count() or 1) + 1)


def pytest_collection_modifyitems(config: pytest.Config, items: list[pytest.Item]) -> None:
    """Without --long or -m, the tests marked ``long`` are deselected. Every test without
    ``@pytest.mark.timeout`` gets HARD_LIMIT (pytest-timeout's thread method: it prints every
    thread's stack and ends the session, wherever the test is stuck, instead of waiting for
    ever). The longest files come first (``_FIRST``)."""
    if not config.getoption("long_run") and not config.option.markexpr:
        left_out = [item for item in items if item.get_closest_marker("long") is not None]
        if left_out:
            config.hook.pytest_deselected(items=left_out)
            items[:] = [item for item in items if item.get_closest_marker("long") is None]
        config.stash[_LEFT_OUT] = len(left_out)
    items.sort(key=lambda item: _FIRST.get(item.path.name, len(_FIRST)))     # stable
    for item in items:
        if item.get_closest_marker("timeout") is None:
            item.add_marker(pytest.mark.timeout(HARD_LIMIT, method="thread"))


def pytest_report_collectionfinish(config: pytest.Config, items: list[pytest.Item]) -> list[str]:
    """In the quick suite, the header says what it leaves out and how to run it all."""
    if config.getoption("long_run"):
        return []
    config.stash[_SHORTENED] = sum("long_run" in item.fixturenames for item in items)
    note = _quick_suite_note(config)
    return [note] if note else []


def pytest_terminal_summary(terminalreporter, config: pytest.Config) -> None:
    """And so does the summary."""
    note = _quick_suite_note(config)
    if note:
        terminalreporter.write_line(note)


def _quick_suite_note(config: pytest.Config) -> str | None:
    counts = {"tests marked long deselected": config.stash.get(_LEFT_OUT, 0),
              "run shortened": config.stash.get(_SHORTENED, 0)}
    said = ", ".join(f"{n} {what}" for what, n in counts.items() if n)
    return f"quick suite: {said}; the whole suite: {LONG}" if said else None


@pytest.fixture(scope="session")
def long_run(request) -> bool:
    """Whether this session runs the whole suite (--long), not the quick one."""
    return request.config.getoption("long_run")


@pytest.fixture(scope="session", autouse=True)
def session_tmpdir(tmp_path_factory) -> Iterator[Path]:
    """TMPDIR for the session and every process it starts: a folder of its own, removed
    at its end, so that what others leave in their temporary folder stays out of the
    user's (Dask's scratch space, the FMUs ecos unpacks and does not remove, those of a
    host killed on purpose by the fault matrix: about 470 MB a run of the quick suite)."""
    folder = tmp_path_factory.mktemp("tmpdir")
    with pytest.MonkeyPatch.context() as patch:
        patch.setenv("TMPDIR", str(folder))
        patch.setattr(tempfile, "tempdir", str(folder))
        yield folder
    shutil.rmtree(folder, ignore_errors=True)


@pytest.fixture(scope="session", autouse=True)
def fmu_cache(tmp_path_factory) -> Iterator[Path]:
    """The sweeps' workers keep the FMUs they are sent in the test session's own folder,
    not the user's cache (``cosim.studies.sweep_task.fmu_cache``); set before any cluster
    starts, so that its workers inherit it."""
    folder = tmp_path_factory.mktemp("fmu_cache")
    folder.chmod(0o700)
    with pytest.MonkeyPatch.context() as patch:
        patch.setenv("COSIM_FMU_CACHE", str(folder))
        yield folder


@pytest.fixture(scope="session")
def scheduler(fmu_cache) -> Iterator[str]:
    """The address of one local Dask cluster of two workers, for the tests that only need
    somewhere to run a sweep (those about clusters and workers make their own)."""
    from cosim.studies.cluster import local_cluster

    cluster = local_cluster(2)
    try:
        yield cluster.scheduler_address
    finally:
        cluster.close()


def _stale(path: Path) -> bool:
    """Missing, built without a manifest, or not current: a module it carries differs
    from this checkout's."""
    manifest = read(path) if path.exists() else None
    return manifest is None or staleness(manifest, entry_source) is not None


def _older(fmu: Path, sources: list[Path]) -> bool:
    return not fmu.exists() or max(p.stat().st_mtime for p in sources) > fmu.stat().st_mtime


def _current(fmi: int) -> dict[str, Path]:
    """Every FMU of FMI version ``fmi`` in its folder, rebuilt first if missing or not
    current (its manifest against the sources; the C FMU, which has none, by file times,
    its build script's included, and only where there is a C compiler)."""
    folder = FMU_DIRS[fmi]
    folder.mkdir(parents=True, exist_ok=True)
    with _build_lock(folder):
        return _current_locked(folder, fmi)


@contextlib.contextmanager
def _build_lock(folder: Path) -> Iterator[None]:
    """One test process at a time checks and builds a folder's FMUs: pytest-xdist's workers
    start together, and a worker must not load an FMU another one is writing."""
    with open(folder / ".build.lock", "w") as lock:
        fcntl.flock(lock, fcntl.LOCK_EX)
        try:
            yield
        finally:
            fcntl.flock(lock, fcntl.LOCK_UN)


def _current_locked(folder: Path, fmi: int) -> dict[str, Path]:
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


@pytest.fixture(scope="session")
def faulty_fmu(tmp_path_factory) -> Callable[..., Path]:
    """``faulty_fmu(name, fmi=2)``: the test FMU of tests/faulty/<name>_slave.py, built once
    a session."""
    built: dict[tuple[str, int], Path] = {}

    def get(name: str, fmi: int = 2) -> Path:
        if (name, fmi) not in built:
            folder = tmp_path_factory.mktemp(f"{name}{fmi}")
            built[name, fmi] = build_script(ROOT / "tests" / "faulty" / f"{name}_slave.py",
                                            ("fmukit",), folder / f"{name}.fmu", fmi=fmi)
        return built[name, fmi]
    return get


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
