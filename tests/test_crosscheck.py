"""Every FMU's cross-check files, FMI 2.0 and 3.0: replayed with fmpy's command line, checked by
fmpy's validator of cross-check folders, and written again as committed."""
from __future__ import annotations

import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from fmpy.cross_check.validate_vendor_repo import validate_test_fmu

from fmubuild import crosscheck
from fmubuild.crosscheck import CASES, CROSSCHECK_DIRS, files
from fmubuild.project import FMU_DIR

VERSIONS = sorted(CROSSCHECK_DIRS)


def read_opt(path: Path) -> dict[str, float]:
    """A cross-check .opt file: key: value."""
    pairs = (line.split(",", 1) for line in path.read_text().splitlines() if "," in line)
    return {key.strip(): float(value) for key, value in pairs}


def fmpy_simulate(fmu: Path, opt: dict[str, float], inputs: Path, cwd: Path) -> Path:
    """``fmpy simulate`` of ``fmu`` as a host runs it, in a child process isolated from this
    checkout (whose modules would be taken in place of the ones the FMU carries); the CSV."""
    subprocess.run([sys.executable, "-I", "-m", "fmpy.cli", "simulate", str(fmu),
                    "--start-time", str(opt["StartTime"]), "--stop-time", str(opt["StopTime"]),
                    "--output-interval", str(opt["StepSize"]), "--input-file", str(inputs),
                    "--output-file", "out.csv"], cwd=cwd, check=True, capture_output=True,
                   text=True, timeout=120)
    return cwd / "out.csv"


@pytest.fixture(scope="module")
def fmus(fmu_paths, fmi3_paths) -> dict[int, dict[str, Path]]:
    """FMI version: its FMUs, current."""
    return {2: fmu_paths, 3: fmi3_paths}


@pytest.mark.parametrize("name", list(CASES))
@pytest.mark.parametrize("fmi", VERSIONS)
def test_fmpy_simulate_reproduces_the_reference(fmus, tmp_path, fmi, name):
    paths = files(name, fmi)
    opt = read_opt(paths["opt"])
    replayed = fmpy_simulate(fmus[fmi][name], opt, paths["in"], tmp_path)
    ref = np.genfromtxt(paths["ref"], delimiter=",", names=True)
    out = np.genfromtxt(replayed, delimiter=",", names=True)
    assert out.dtype.names == ref.dtype.names and len(out) == len(ref) > 100
    for column in ref.dtype.names:
        scale = max(1.0, np.abs(ref[column]).max())
        assert np.abs(out[column] - ref[column]).max() <= opt["RelTol"] * scale, column


@pytest.mark.parametrize("name", list(CASES))
def test_an_fmus_two_versions_have_the_same_references_to_the_last_digit(name):
    fmi2, fmi3 = files(name, 2), files(name, 3)
    for key in ("in", "ref", "opt"):
        assert fmi3[key].read_bytes() == fmi2[key].read_bytes(), fmi3[key]
    assert len(fmi2["ref"].read_text().splitlines()) > 100
    assert fmi3["dir"].relative_to(FMU_DIR).parts[:3] == ("crosscheck", "3.0", "cs")
    assert (fmi3["dir"] / "ReadMe.txt").read_text().startswith(
        f"{name}.fmu, FMI 3.0 co-simulation, built with pythonfmu3 ")


@pytest.mark.parametrize("fmi", VERSIONS)
def test_the_folders_pass_fmpys_cross_check_validator(fmus, tmp_path, fmi):
    for name in CASES:
        # As the cross-check repository holds it: the FMU beside its files.
        folder = tmp_path / CROSSCHECK_DIRS[fmi].relative_to(FMU_DIR) / name
        shutil.copytree(files(name, fmi)["dir"], folder, ignore=shutil.ignore_patterns("*.fmu"))
        shutil.copy(fmus[fmi][name], folder / f"{name}.fmu")
        assert validate_test_fmu(str(folder)) == [], folder


@pytest.mark.parametrize("fmi", VERSIONS)
def test_the_command_writes_the_committed_files_again(fmus, tmp_path, monkeypatch, capsys,
                                                      fmi):
    other = {3: 2, 2: 3}[fmi]
    for version in VERSIONS:
        monkeypatch.setitem(CROSSCHECK_DIRS, version, tmp_path / f"{version}.0")
    assert crosscheck.main(["--fmi", str(fmi), "pd_autopilot"]) == 0
    written = tmp_path / f"{fmi}.0" / "pd_autopilot"
    assert capsys.readouterr().out == f"wrote {written}\n"
    assert not (tmp_path / f"{other}.0").exists()
    committed = files("pd_autopilot", fmi)["dir"]
    assert sorted(p.name for p in written.iterdir()) == sorted(
        ["pd_autopilot.fmu", *(p.name for p in committed.iterdir() if p.suffix != ".fmu")])
    for path in written.iterdir():
        if path.suffix != ".fmu":
            assert path.read_bytes() == (committed / path.name).read_bytes(), path.name
