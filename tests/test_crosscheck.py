"""Replay every FMU's cross-check reference with fmpy's command line."""
from __future__ import annotations

import numpy as np
import pytest

from fmubuild.crosscheck import CASES, files, read_opt
from helpers import fmpy_cli


@pytest.mark.parametrize("name", list(CASES))
def test_fmpy_simulate_reproduces_the_reference(fmu_paths, tmp_path, name):
    paths = files(name)
    opt = read_opt(paths["opt"])
    fmpy_cli("simulate", str(fmu_paths[name]), "--start-time", str(opt["StartTime"]),
             "--stop-time", str(opt["StopTime"]), "--output-interval", str(opt["StepSize"]),
             "--input-file", str(paths["in"]), "--output-file", "out.csv", cwd=tmp_path)
    ref = np.genfromtxt(paths["ref"], delimiter=",", names=True)
    out = np.genfromtxt(tmp_path / "out.csv", delimiter=",", names=True)
    assert out.dtype.names == ref.dtype.names and len(out) == len(ref) > 100
    for column in ref.dtype.names:
        scale = max(1.0, np.abs(ref[column]).max())
        assert np.abs(out[column] - ref[column]).max() <= opt["RelTol"] * scale, column
