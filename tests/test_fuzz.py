"""Fuzzing every FMU through fmpy (tests/fmu_fuzz.py), each campaign in a child process.

A crash of the host ends the child with a signal, a hang hits the time limit: both fail
here instead of taking the test session down. 1,500 examples per FMU; the documented
long run takes 10,000 (docs/robustness.md).
"""
from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import pytest

from fmu_fuzz import FMUS

EXAMPLES = 1500


@pytest.mark.parametrize("name", FMUS)
def test_fuzzed_calls_are_refused_by_name_and_never_crash_or_hang(fmu_paths, name):
    child = subprocess.run(
        [sys.executable, str(Path(__file__).with_name("fmu_fuzz.py")), name,
         "--examples", str(EXAMPLES)],
        capture_output=True, text=True, timeout=600)
    assert child.returncode == 0, f"exit {child.returncode}:\n{child.stdout}\n{child.stderr}"
    counts = json.loads(child.stdout.strip().splitlines()[-1])
    print(f"\n{name}: {json.dumps(counts)}")
    assert counts["examples"] == EXAMPLES
    assert counts["valid steps"] > 100                  # the valid path was exercised
    refused = sum(v for k, v in counts.items() if k.endswith(("fatal", "logged an error")))
    assert refused > 1000                               # and so were the invalid ones
