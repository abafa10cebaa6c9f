"""Sweeps under hostile input: every bad spec, option, cache or trial ends in one clear
message naming the input, before anything runs, with no partial output file."""
from __future__ import annotations

import functools
import re

import pytest

import cosim.scenarios.autopilot as autopilot
from fmubuild.trial import TrialFailed, trial


@pytest.mark.timeout(60, method="thread")
def test_a_trial_that_runs_out_of_time_names_the_fmu_and_the_limit(fmu_paths, monkeypatch):
    fmu = fmu_paths["pd_autopilot"]
    said = f"{fmu}: instantiating the FMU did not end within 0.01 s (the child was killed)"
    with pytest.raises(TrialFailed, match=re.escape(said)):
        trial(fmu, timeout=0.01)            # no Python starts in 10 ms
    # checking a user's autopilot: the same words, as the contract's refusal
    monkeypatch.setattr(autopilot, "instantiate_in_child", functools.partial(trial, timeout=0.01))
    with pytest.raises(autopilot.AutopilotError, match=re.escape(said)):
        autopilot.check_autopilot(fmu, trial=True)
