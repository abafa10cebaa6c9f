"""The FMI 3.0 twins in other tools: `cosim.export --fmi 3` writes an SSP package of them, which
ecos and OMSimulator run with the FMI 2.0 package's results; libcosim and fmpy's SSP runner
(FMI 2.0 only) refuse it by name.

The quick suite (without ``pytest --long``) runs ecos on waves_smc alone (the waves and the
chattering SMC: the most code), and each scenario through one of OMSimulator's interfaces,
command line and API in turn: every scenario once, every interface at least once."""
from __future__ import annotations

import os
import subprocess
import sys
import zipfile
from pathlib import Path

import numpy as np
import pytest

from cosim import engines as engines_cli
from cosim import export as export_cli
from cosim import scenarios
from cosim.core.master import Master
from cosim.interop.hosts import EngineError, run, run_omsimulator
from cosim.interop.ssp import described, export
from helpers import ecos_missing

ROOT = Path(__file__).resolve().parent.parent
OMS = Path(os.environ.get("OMSIMULATOR_HOME") or ROOT.parent / "shared" / "tools" / "omsimulator")
NAMES = ("calm_pd", "waves_smc", "zigzag_10_10")


needs_ecos = pytest.mark.skipif(ecos_missing() is not None, reason=str(ecos_missing()))
needs_oms = pytest.mark.skipif(not (OMS / "bin" / "OMSimulator").is_file(),
                               reason=f"OMSimulator is not at {OMS} (../shared/tools/"
                                      "omsimulator, or set OMSIMULATOR_HOME; CI has it)")


@pytest.fixture(scope="module")
def packages(fmu_paths, fmi3_paths, tmp_path_factory) -> dict[tuple[str, int], Path]:
    """(scenario, FMI version): its package."""
    out = {fmi: tmp_path_factory.mktemp(f"fmi{fmi}") for fmi in (2, 3)}
    return {(name, fmi): export(name, out[fmi], fmi=fmi) for name in NAMES for fmi in out}


def _master(name: str, coupling: str):
    with Master(scenarios.load(name, fmi=3), coupling=coupling) as master:
        return master.run()


def test_the_fmi3_package_holds_the_twins_and_the_same_system(packages):
    for name in NAMES:
        two, three = packages[name, 2], packages[name, 3]
        assert {d.fmiVersion for d in described(three)[1].values()} == {"3.0"}
        assert {d.fmiVersion for d in described(two)[1].values()} == {"2.0"}
        with zipfile.ZipFile(two) as a, zipfile.ZipFile(three) as b:
            assert a.read("SystemStructure.ssd") == b.read("SystemStructure.ssd")
            assert a.namelist() == b.namelist()
        assert set(described(three.with_suffix(""))[1]) == set(described(three)[1])


def test_the_export_command_writes_it_and_says_who_cannot_run_it(fmi3_paths, tmp_path,
                                                                monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    assert export_cli.main(["calm_pd", "--fmi", "3"]) == 0
    out, err = capsys.readouterr()
    package = tmp_path / "results" / "ssp" / "fmi3" / "calm_pd.ssp"
    assert f"wrote {Path('results/ssp/fmi3/calm_pd.ssp')}" in out and package.is_file()
    assert "note: calm_pd.ssp holds FMI 3.0 FMUs: ecos and OMSimulator run it; OSP libcosim " \
           "and fmpy's SSP runner run FMI 2.0 FMUs only and cannot" in err
    assert export_cli.main(["calm_pd"]) == 0
    assert "note:" not in capsys.readouterr().err                 # an FMI 2.0 package


@needs_ecos
@pytest.mark.parametrize("name", [
    pytest.param(name, marks=() if name == "waves_smc" else pytest.mark.long) for name in NAMES])
def test_ecos_runs_the_fmi3_package_as_the_fmi2_one_bit_for_bit(packages, name):
    three, two = run("ecos", packages[name, 3]), run("ecos", packages[name, 2])
    assert sorted(three) == sorted(two) and len(three["time"]) > 3000
    for signal in two:
        assert np.array_equal(three[signal], two[signal]), signal
    ours = _master(name, "jacobi")                   # ecos's coupling: see cosim.engines
    for signal in ("ship.psi", "ship.r", "ship.delta"):
        assert np.abs(three[signal] - ours[signal]).max() <= 1e-9, signal


@needs_oms
@pytest.mark.parametrize("name, interface", [    # quick: calm_pd by the command line
    pytest.param(name, interface, marks=() if i == j == 0 else pytest.mark.long)
    for i, name in enumerate(NAMES) for j, interface in enumerate(["cli", "api"])])
def test_omsimulator_runs_the_fmi3_package_as_the_fmi2_one(packages, name, interface):
    """Its CSV holds 12 significant digits: the FMI 3.0 package gives the FMI 2.0 one's
    columns, and our Gauss-Seidel run rounded to them; and each twin's independent
    variable, ``time``, the result's time."""
    three = run_omsimulator(packages[name, 3], OMS, interface, timeout=300)
    two = run_omsimulator(packages[name, 2], OMS, interface, timeout=300)
    clocks = {f"{component}.time" for component in scenarios.load(name).components}
    assert set(three) == set(two) | clocks
    for clock in clocks:
        assert np.array_equal(three[clock], three["time"]), clock
    for column in two:
        assert np.array_equal(three[column], two[column]), column
    ours = _master(name, "gauss-seidel")
    assert len(three["time"]) == ours.rows
    compared = [c for c in ours.columns if c in three]
    assert len(compared) == len(ours.columns)
    for column in compared:
        assert np.array_equal(three[column], [float(f"{v:.12g}") for v in ours[column]]), column


@pytest.mark.parametrize("engine, who", [("libcosim", "OSP libcosim"),
                                         ("fmpy", "fmpy's SSP runner")])
def test_fmi2_only_engines_refuse_the_fmi3_package_by_name(packages, engine, who):
    with pytest.raises(EngineError) as refused:
        run(engine, packages["calm_pd", 3])
    assert str(refused.value) == (
        f"{who} runs FMI 2.0 FMUs only; calm_pd.ssp holds guidance (FMI 3.0), autopilot "
        "(FMI 3.0), ship (FMI 3.0): run it with ecos or OMSimulator, or export the FMI 2.0 "
        "package (python -m cosim.export without --fmi 3)")


def test_the_engines_command_refuses_the_fmi3_package_and_its_osp_folder(packages, tmp_path,
                                                                        capsys):
    """Not libcosim's own 'Unable to create execution from path'."""
    for target in (packages["calm_pd", 3], packages["calm_pd", 3].with_suffix("")):
        assert engines_cli.main(["libcosim", str(target), "--out",
                                 str(tmp_path / "t.npz")]) == 1
        err = capsys.readouterr().err
        assert err.startswith("error: OSP libcosim runs FMI 2.0 FMUs only;"), err
        assert "Unable to create execution" not in err
    assert not (tmp_path / "t.npz").exists()


def test_libcosim_itself_cannot_load_the_fmi3_package(packages, tmp_path):
    """Why the refusal: libcosimpy 0.0.6, given the package, fails with its own words
    (its host may even die: a child process, under a time limit)."""
    pytest.importorskip("libcosimpy")
    load = ("import sys\nfrom libcosimpy.CosimExecution import CosimExecution\n"
            "CosimExecution.from_ssp_file(sys.argv[1])\n")
    child = subprocess.run([sys.executable, "-c", load, str(packages["calm_pd", 3])],
                           capture_output=True, text=True, timeout=120, check=False)
    assert child.returncode != 0
    assert "Unable to create execution from path" in child.stdout + child.stderr
