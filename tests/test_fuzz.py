"""Fuzzing every FMU through fmpy (tests/fmu_fuzz.py), each campaign in a child process.

A crash of the host ends the child with a signal, a hang hits the time limit: both fail
here instead of taking the test session down. FMI 2.0: 1,500 examples per FMU, one
campaign at a time. The FMI 3.0 twins: 500 examples per twin, two campaigns at a time
(``fmi3_campaigns``): an FMI 3.0 example costs more (fmpy loads every FMI 3.0 function at
each instantiation). The quick suite (without ``pytest --long``) fuzzes the ship, the PD
autopilot and the guidance with 300 examples and the ship's and the PD autopilot's twins with
250 (``EXAMPLES``), against thresholds that are the same fractions of the examples (fewer
examples miss the valid path of some FMUs). The documented long run takes 10,000 of either
(docs/robustness.md).
"""
from __future__ import annotations

import json
import subprocess
import sys
from concurrent.futures import Future, ThreadPoolExecutor
from pathlib import Path

import pytest

from fmu_fuzz import FMUS, FUZZED

EXAMPLES = {2: {True: 1500, False: 300}, 3: {True: 500, False: 250}}
"""Examples per campaign, by FMI version and whether the whole suite runs (``long_run``)."""
TIME_LIMIT = 600
"""Seconds a campaign may take."""
FUZZER = Path(__file__).with_name("fmu_fuzz.py")


def _fuzz(name: str, fmi: int, examples: int) -> subprocess.CompletedProcess:
    """One campaign in a child process, within TIME_LIMIT."""
    return subprocess.run([sys.executable, str(FUZZER), name, "--fmi", str(fmi),
                           "--examples", str(examples)],
                          capture_output=True, text=True, timeout=TIME_LIMIT)


def _counts(child: subprocess.CompletedProcess, name: str) -> dict:
    """The campaign's counts; the test fails with its output if it did not end well."""
    assert child.returncode == 0, f"exit {child.returncode}:\n{child.stdout}\n{child.stderr}"
    counts = json.loads(child.stdout.strip().splitlines()[-1])
    print(f"\n{name}: {json.dumps(counts)}")
    return counts


@pytest.mark.parametrize("name", [   # quick: the ship, an autopilot and the guidance
    n if n in ("ship", "pd_autopilot", "guidance") else pytest.param(n, marks=pytest.mark.long)
    for n in FMUS])
def test_fuzzed_calls_are_refused_by_name_and_never_crash_or_hang(fmu_paths, long_run, name):
    examples = EXAMPLES[2][long_run]
    counts = _counts(_fuzz(name, 2, examples), name)
    assert counts["examples"] == examples
    assert counts["valid steps"] > examples / 15        # the valid path was exercised
    refused = sum(v for k, v in counts.items() if k.endswith(("fatal", "logged an error")))
    assert refused > examples * 2 / 3                   # and so were the invalid ones


@pytest.fixture(scope="session")
def fmi3_campaigns(request, fmi3_paths, long_run) -> dict[str, Future]:
    """The selected FMI 3.0 twins' campaigns, two at a time, each as its finished future (a
    campaign past TIME_LIMIT fails its own test)."""
    names = [item.callspec.params["name"] for item in request.session.items
             if item.originalname == "test_fmi3_twins_refuse_fuzzed_calls_by_name_and_never_"
             "crash_or_hang" and hasattr(item, "callspec")]
    with ThreadPoolExecutor(max_workers=2) as pool:
        return {name: pool.submit(_fuzz, name, 3, EXAMPLES[3][long_run]) for name in names}


@pytest.mark.parametrize("name", [     # quick: the ship's twin and an autopilot's
    n if n in ("ship", "pd_autopilot") else pytest.param(n, marks=pytest.mark.long)
    for n in FUZZED[3]])
def test_fmi3_twins_refuse_fuzzed_calls_by_name_and_never_crash_or_hang(fmi3_campaigns,
                                                                      long_run, name):
    examples = EXAMPLES[3][long_run]
    counts = _counts(fmi3_campaigns[name].result(), name)
    assert (counts["fmi"], counts["examples"]) == (3, examples)
    assert counts["valid steps"] > examples / 50        # the valid path was exercised
    assert counts["step error"] > examples / 5          # refused steps: fmi3Error
    fatal = sum(v for k, v in counts.items() if k.endswith("fatal"))
    assert fatal > examples / 2                         # every other refusal: fmi3Fatal
    assert counts["set_time fatal"] > 0 and counts["exit OK but logged an error"] > 0
