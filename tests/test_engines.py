"""Our FMUs in other FMI engines: one SSP package, identical traces, visible errors.

The quick suite (without ``pytest --long``) compares each paper scenario in one engine, the
engines in turn (``TRACES``): every scenario and every engine at least once."""
from __future__ import annotations

import subprocess
import sys
import textwrap
from pathlib import Path

import numpy as np
import pytest

from cosim.interop.hosts import TRACED, EngineError, run
from cosim.interop.ssp import export
from fmukit.timebase import nanoseconds
from helpers import ecos_missing, recorded

PAPER = ["calm_pd", "calm_smc", "waves_pd", "waves_smc"]
NEEDS_ECOS = pytest.mark.skipif(ecos_missing() is not None, reason=str(ecos_missing()))
ENGINES = ["libcosim", pytest.param("ecos", marks=NEEDS_ECOS), "fmpy"]
TRACES = [pytest.param(name, engine, marks=[NEEDS_ECOS] * (engine == "ecos")
                       + [pytest.mark.long] * (j != i % 3))
          for i, name in enumerate(PAPER) for j, engine in enumerate(("libcosim", "ecos", "fmpy"))]
"""Each paper scenario in each engine; in the quick suite, scenario i in engine i mod 3."""


@pytest.fixture(scope="module")
def packages(fmu_paths, tmp_path_factory) -> dict[str, Path]:
    out = tmp_path_factory.mktemp("ssp")
    return {name: export(name, out) for name in PAPER + ["turning_circle"]}




def ours(name: str):
    return recorded(name, coupling="jacobi")


def _compare(engine_trace: dict, name: str) -> tuple[float, int]:
    """Max difference over the times both have, and how many engine rows lie beyond ours."""
    rec = ours(name)
    row_of = {nanoseconds(t): k for k, t in enumerate(rec.t)}
    rows = [row_of.get(nanoseconds(t)) for t in engine_trace["time"]]
    beyond = sum(r is None for r in rows)
    both = [(i, r) for i, r in enumerate(rows) if r is not None]
    ei, oi = map(list, zip(*both))
    worst = max(np.abs(engine_trace[s][ei] - rec[s][oi]).max() for s in TRACED)
    return worst, beyond


@pytest.mark.parametrize("name, engine", TRACES)
def test_same_package_same_traces_as_our_master_in_jacobi(packages, engine, name):
    trace = run(engine, packages[name])
    worst, beyond = _compare(trace, name)
    assert worst <= 1e-9
    assert trace["time"][-1] == pytest.approx(400.0)           # the full 400 s
    assert beyond == 0            # fmpy: 0.1 added 4000 times reaches 400.00000000002
    assert len(trace["time"]) == (4001 if engine == "ecos" else 4000)   # see cosim.engines


def test_manoeuvre_in_libcosim_equals_our_master(packages):
    worst, beyond = _compare(run("libcosim", packages["turning_circle"]), "turning_circle")
    assert worst <= 1e-9 and beyond == 0


def test_fmpy_runner_steps_past_300_s_and_starts_its_connectors_at_zero(packages):
    """Two quirks of fmpy's SSP runner, handled by comparing on time.

    It adds 0.1 to a float until it reaches the stop time: 3000 additions give
    299.9999999999998, so a 300 s run takes 3001 steps. And its connectors start at
    0.0, not at the FMUs' initial outputs, so the ship receives the executed rudder
    one step later than from libcosim or our master.
    """
    trace = run("fmpy", packages["turning_circle"])
    _, beyond = _compare(trace, "turning_circle")
    assert beyond == 1 and len(trace["time"]) == 3001
    assert trace["time"][-1] == pytest.approx(300.1)
    moved = trace["time"][np.argmax(trace["ship.delta"] != 0.0)]
    ours_moved = ours("turning_circle").t[np.argmax(ours("turning_circle")["ship.delta"] != 0.0)]
    assert moved - ours_moved == pytest.approx(0.1)


@pytest.mark.parametrize("engine", ENGINES[:2])
def test_engines_report_an_invalid_parameter_with_the_fmu_message(fmu_paths, tmp_path, engine):
    bad = export("calm_pd", tmp_path, {"ship": {"Hs": -1.0}})
    with pytest.raises(EngineError) as failed:
        run(engine, bad)
    assert "parameter Hs = -1.0 is outside its range" in str(failed.value)


def test_fmpy_runner_raises_on_an_invalid_parameter(fmu_paths, tmp_path):
    bad = export("calm_pd", tmp_path, {"ship": {"T0": 0.0}})
    with pytest.raises(EngineError, match="parameter T0 = 0.0 is outside its range"):
        run("fmpy", bad)


@pytest.mark.parametrize("name", ["ship", "pd_autopilot", "smc_autopilot", "guidance",
                                  "manoeuvre"])
def test_each_fmu_runs_in_fmpy_cli_without_this_repository(fmu_paths, tmp_path, name):
    """fmpy's command line in a fresh interpreter that cannot import this repository."""
    repo = str(Path(__file__).resolve().parent.parent)
    script = textwrap.dedent(f"""
        import sys
        sys.path = [p for p in sys.path if p not in ("", {repo!r})]
        sys.meta_path = [f for f in sys.meta_path if "editable" not in repr(f).lower()]
        sys.argv = ["fmpy", "simulate", {str(fmu_paths[name])!r}, "--stop-time", "5",
                    "--output-file", "out.csv"]
        from fmpy.cli import main
        main()
        print("\\n".join(m.__file__ for k, m in sorted(sys.modules.items())
                         if k.split(".")[0] in ("fmukit", "ship_fmu", "autopilot_fmu", "cosim")
                         and getattr(m, "__file__", None)))
    """)
    child = subprocess.run([sys.executable, "-c", script], cwd=tmp_path, capture_output=True,
                           text=True, timeout=120)
    assert child.returncode == 0, child.stderr
    loaded = child.stdout.split()
    assert loaded and all("/resources/" in path for path in loaded), loaded
    assert not any("/cosim/" in path for path in loaded)
    assert len((tmp_path / "out.csv").read_text().splitlines()) > 10


def test_the_package_s_connectors_carry_the_fmus_units(fmu_paths, tmp_path):
    """SSP 1.0: each connector's ssc type names its unit, defined once in ssd:Units with the
    FMU's base-unit exponents; every tool above runs the package with them."""
    import xml.etree.ElementTree as ET
    import zipfile

    from cosim.core.fmi import read_description
    from cosim.core.ssd import NS
    package = export("waves_pd", tmp_path)
    root = ET.fromstring(zipfile.ZipFile(package).read("SystemStructure.ssd"))
    defined = {u.get("name"): u.find("ssc:BaseUnit", NS).attrib
               for u in root.findall("ssd:Units/ssc:Unit", NS)}
    assert defined["rad/s"] == {"s": "-1", "rad": "1"} and defined["N.m"]["m"] == "2"
    seen = 0
    for component in root.iter(f"{{{NS['ssd']}}}Component"):
        name = component.get("name")
        declared = {v.name: v.unit for v in read_description(
            fmu_paths[Path(component.get("source")).stem], name).modelVariables}
        for connector in component.iter(f"{{{NS['ssd']}}}Connector"):
            unit = connector[0].get("unit")             # its one ssc type
            assert unit == (declared[connector.get("name")] or None)
            if unit is not None:
                assert unit in defined
                seen += 1
    assert seen == 18          # every Real connector of the three FMUs (wp_index is an Integer)
