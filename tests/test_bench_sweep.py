"""The sweep benchmark's code path, tiny (its figures are printed, never asserted): the rows
it measures, the ratios and goals it prints from them, and its refusals."""
from __future__ import annotations

import math
import re

import pytest

from cosim import bench as command
from cosim.studies import sweep_timing


def _figure(pattern: str, text: str) -> float:
    found = re.search(pattern, text)
    assert found, f"{pattern!r} not in:\n{text}"
    return float(found.group(1))


@pytest.mark.long          # the quick suite: the campaign below, on the same sweep code
@pytest.mark.timeout(120, method="thread")
def test_throughput_prints_per_core_rates_and_the_goal_from_what_it_measured(fmu_paths,
                                                                              capsys):
    rates = sweep_timing.sweep_throughput(2, 4, ("calm",), stop_time=5.0)
    assert set(rates) == {("calm", b, w) for b in ("fmi", "inprocess", "batch") for w in (1, 2)}
    assert all(math.isfinite(r) and r > 0 for r in rates.values())
    out = capsys.readouterr().out
    assert out.count("load average") == 2                # before and after
    assert "calm  batch     1 worker " in out and "batches of 2)" in out
    per_core = re.search(r"calm  batch +([\d.]+) +([\d.]+) +([\d.]+)\n", out)
    assert per_core, out
    one, two, efficiency = map(float, per_core.groups())
    assert one == pytest.approx(rates["calm", "batch", 1], abs=0.006)
    assert two == pytest.approx(rates["calm", "batch", 2] / 2, abs=0.006)
    assert efficiency == pytest.approx(rates["calm", "batch", 2] / rates["calm", "batch", 1] / 2,
                                       abs=0.006)
    goal = re.search(r"goal, calm: batch runs/s per core at least 10x in-process: "
                     r"([\d.]+)x with 1 worker, ([\d.]+)x with 2 workers: (met|NOT met)\n", out)
    assert goal, out
    ratios = [float(goal.group(i)) for i in (1, 2)]
    for ratio, workers in zip(ratios, (1, 2)):
        assert ratio == pytest.approx(rates["calm", "batch", workers]
                                      / rates["calm", "inprocess", workers], abs=0.006)
    assert goal.group(3) == ("met" if min(ratios) >= 10 else "NOT met")


@pytest.mark.timeout(60, method="thread")
def test_campaign_times_the_sweep_and_judges_only_the_issues_campaign(fmu_paths, capsys):
    measure = sweep_timing.campaign(4, 1, 2.0)
    assert measure.runs == 4 and measure.batches == (4,) and len(measure.peak_rss) == 1
    assert 0 < measure.simulated and 0 < measure.startup and 0 < measure.wall
    out = capsys.readouterr().out
    assert _figure(r"4 runs in ([\d.]+) s from submission", out) == pytest.approx(
        measure.wall, abs=0.06)
    assert "not judged here" in out and "goal:" not in out


@pytest.mark.long
@pytest.mark.timeout(90, method="thread")
def test_memory_counts_the_results_and_judges_full_batches(fmu_paths, capsys):
    found = sweep_timing.batch_memory((2, 4), 2.0, batch_size=2)
    samples = 21                                        # 2 s at 0.1 s, both ends
    for members, (wall, before, peak, results) in found["calls"].items():
        assert results * 2**20 == (members * 6 + 1) * samples * 8   # six signals and the time
        assert 0 < before <= peak and wall > 0
    assert [s.batches for s in found["sweeps"].values()] == [(2,), (2, 2)]
    out = capsys.readouterr().out
    low, high = (found["sweeps"][m].peak_rss[0] for m in (2, 4))
    verdict = "met" if high / low - 1 <= sweep_timing.FLAT else "NOT met"
    assert f"at 2 runs, {high:.1f} MB at 4 runs" in out and out.rstrip().splitlines()[-2] \
        .endswith(f": {verdict}")


def test_the_command_refuses_bad_counts_before_any_cluster(capsys):
    assert command.main(["sweep", "--parts", "throughput", "--runs", "3"]) == 2
    assert "runs must be an even number of runs >= 2 (half for each autopilot), got 3" in \
        capsys.readouterr().err
    assert command.main(["sweep", "--parts", "campaign", "--campaign-runs", "0"]) == 2
    assert "the campaign's runs must be at least 1, got 0" in capsys.readouterr().err
    with pytest.raises(SystemExit):
        command.main(["sweep", "--memory-members", "64,0"])
    assert "expected whole numbers >= 1 separated by commas, got '64,0'" in \
        capsys.readouterr().err


def test_all_runs_the_five_benchmarks_in_turn_each_with_its_defaults(monkeypatch):
    ran = []
    monkeypatch.setattr(command, "_benchmark", lambda name, args, repeats: ran.append(
        (name, repeats, getattr(args, "hours", None), getattr(args, "runs", None))))
    assert command.main(["all", "--repeats", "3"]) == 0
    assert ran == [("engines", 3, None, None), ("overhead", 3, None, None),
                   ("memory", 3, 24.0, None), ("sweep", 3, None, 32), ("rl", 3, None, None)]
    ran.clear()
    assert command.main(["memory", "--hours", "2"]) == 0 and ran == [("memory", 5, 2.0, None)]
