"""Timed events in OSP's scenario format (issue 40, item 6): read and refused by name, a
steering-gear failure through a tunable parameter, the same bits in-process, through FMI 2.0
and 3.0, and in libcosim's own scenario manager; sweeps carry them and replay them."""
from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

import cosim
from cosim.core.events import EventsError, read_events
from cosim.interop.hosts import run as run_engine
from cosim.interop.ssp import export
from cosim.studies.sweep_spec import Spec

MIXED = {"defaults": {"action": "override"}, "events": [
    {"time": 2, "model": "ship", "variable": "delta_rate_max", "value": 0.0},
    {"time": 1, "model": "autopilot", "variable": "psi", "action": "bias", "value": 0.1},
    {"time": 1.55, "model": "autopilot", "variable": "psi", "action": "reset"},
    {"time": 0.5, "model": "ship", "variable": "V_c", "value": 0.03}], "end": 400}


def events_file(tmp_path: Path, document: dict | str, name: str = "events.json") -> Path:
    path = tmp_path / name
    path.write_text(document if isinstance(document, str) else json.dumps(document))
    return path


@pytest.mark.parametrize("document, says", [
    ("{not json", "cannot be read"),
    ({"events": {}}, "a list 'events'"),
    ({"events": [{"time": 1, "model": "ship", "variable": "x0", "value": 1}]},
     "event 0 'action' = None is not one of override, bias, reset"),
    ({"events": [{"time": -1, "model": "ship", "variable": "x0", "action": "reset"}]},
     "event 0 'time' = -1 is not a time"),
    ({"events": [{"time": 5, "model": "s", "variable": "v", "action": "reset"}], "end": 4},
     "from 0 to the end, 4"),
    ({"events": [{"time": 1, "model": "ship", "variable": "x0", "action": "bias"}]},
     "event 0 needs a 'value' (reset takes none)"),
    ({"events": [{"time": 1, "model": "ship", "variable": "x", "action": "reset", "value": 1}]},
     "event 0 needs a 'value' (reset takes none)"),
    ({"events": [{"time": 1, "variable": "x", "action": "reset"}]}, "needs 'model'"),
    ({"events": [{"time": 1, "model": "ship", "variable": "x", "action": "reset",
                  "when": 2}]}, "unknown keys ['when']"),
])
def test_a_scenario_file_that_is_wrong_is_refused_naming_file_and_event(tmp_path, document,
                                                                         says):
    path = events_file(tmp_path, document)
    with pytest.raises(EventsError, match="scenario file .*events.json") as refused:
        read_events(path)
    assert says in str(refused.value)
    with pytest.raises(EventsError, match="JSON form only"):
        read_events(events_file(tmp_path, "events: []", "events.yml"))


@pytest.mark.parametrize("event, says", [
    ({"model": "rudder", "variable": "x"}, "no component 'rudder' (the system has guidance"),
    ({"model": "ship", "variable": "delta_rate"}, "did you mean"),
    ({"model": "ship", "variable": "Hs"}, "ship.Hs is a fixed parameter; events set inputs "
                                          "and tunable parameters"),
    ({"model": "ship", "variable": "delta_rate_max", "value": 20.0}, "outside its declared"),
    ({"model": "guidance", "variable": "wp_index"}, "is a discrete output"),
])
def test_events_that_do_not_fit_the_fmus_are_refused_before_the_run(tmp_path, event, says):
    document = {"events": [{"time": 1, "action": "override", "value": 0.0, **event}]}
    with pytest.raises(EventsError, match="event at 1 s") as refused:
        cosim.simulate("calm_pd", stop_time=2, backend="inprocess",
                       events=events_file(tmp_path, document))
    assert says in str(refused.value)
    with pytest.raises(EventsError, match="unknown events 'gear'; shipped: current_turns, "
                                          "gear_failure, gyro_dropout"):
        cosim.simulate("calm_pd", stop_time=2, events="gear")


def test_a_failed_steering_gear_holds_the_rudder_alike_on_every_route(tmp_path, fmi3_paths):
    path = events_file(tmp_path, MIXED)
    runs = [cosim.simulate("waves_pd", stop_time=3, backend=backend, fmi=fmi, events=path)
            for backend, fmi in (("inprocess", None), ("fmi", None), ("fmi", 3))]
    plain = cosim.simulate("waves_pd", stop_time=3, backend="inprocess")
    k = {t: int(round(t * 10)) for t in (0.5, 1.0, 1.6, 2.0)}
    delta = runs[0]["ship.delta"]
    assert np.all(delta[k[2.0]:] == delta[k[2.0]])              # stuck from its step on
    assert not np.all(plain["ship.delta"][k[2.0]:] == plain["ship.delta"][k[2.0]])
    sent, true = runs[0]["autopilot.psi"], runs[0]["ship.psi"]  # biased from 1 s to 1.6 s
    assert np.array_equal(sent[k[1.0]:k[1.6]], true[k[1.0]:k[1.6]] + 0.1)
    assert np.array_equal(sent[k[1.6]:], true[k[1.6]:])
    assert runs[0].meta["events"][0] == {"time": 0.5, "model": "ship", "variable": "V_c",
                                         "action": "override", "value": 0.03}
    for other in runs[1:]:
        assert all(np.array_equal(runs[0][c], other[c]) for c in runs[0].columns)


def test_libcosim_runs_the_same_scenario_file_to_the_same_bits(tmp_path, fmu_paths):
    pytest.importorskip("libcosimpy")
    path, signals = events_file(tmp_path, MIXED), ("ship.psi", "ship.delta", "ship.y")
    theirs = run_engine("libcosim", export("waves_pd", tmp_path), signals, events=path)
    ours = cosim.simulate("waves_pd", coupling="jacobi", backend="inprocess", events=path)
    for signal in signals:
        assert np.array_equal(theirs[signal], ours[signal][1:])
    with pytest.raises(ValueError, match="ecos runs no timed events"):
        run_engine("ecos", tmp_path / "waves_pd.ssp", signals, events=path)


def test_a_sweep_carries_its_events_and_replays_them(tmp_path, fmu_paths):
    events_file(tmp_path, MIXED, "mine.json")
    spec = tmp_path / "sweep.toml"
    spec.write_text('events = "gear_failure"\nstop_time = 3\n[controllers]\npd = "waves_pd"\n'
                    '[controllers.mine]\nscenario = "waves_smc"\nevents = "mine.json"\n'
                    '[axes]\nwave_seed = [1]\n')
    read = Spec.read(spec)
    systems = {c: b.system for c, b in read.bundles().items()}
    assert [e.time for e in systems["pd"].events] == [150.0]
    assert [e.time for e in systems["mine"].events] == [0.5, 1.0, 1.55, 2.0]
    assert read.batch_coverage["pd"] == "the batch route has no timed events"
    commands = {r["controller"]: read.replay(r) for r in read.runs()}
    assert "--events gear_failure" in commands["pd"]
    assert f"--events {tmp_path / 'mine.json'}" in commands["mine"]
    spec.write_text('events = "nowhere.json"\n')
    with pytest.raises(ValueError, match="sweep.toml: controller 'pd': scenario file "
                                         ".*nowhere.json cannot be read"):
        Spec.read(spec)
