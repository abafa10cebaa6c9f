"""Property-based fuzzing of one FMU through fmpy: random call sequences and values.

    python tests/fmu_fuzz.py ship --examples 2000       # both versions; counts as JSON
    python tests/fmu_fuzz.py ship --fmi 3               # the FMI 3.0 twin only
    python tests/fmu_fuzz.py --all --examples 10000     # the long run (docs/robustness.md)

Each example is a random program of FMI calls on a fresh instance: setupExperiment
(FMI 2.0), enter/exitInitializationMode, terminate, reset, set (any variable, any
value: in range, out of range, extreme, NaN, infinite, of the wrong type), doStep (any
step size, including 0, negative, non-finite and huge, at any time), get, and a
get/serialize/deserialize/set state round trip. A reference model of the call
sequence (Instantiated, InitializationMode, StepMode, Terminated: the same in both
versions), of the declared variable ranges and of fmukit's failed state
(docs/robustness.md) predicts which calls must be refused; the FMU must then
refuse with a log message that names the cause, must accept every call that is
valid, must give finite outputs after every accepted step and NaN outputs once it
has failed. Invalid parameters are accepted at exitInitializationMode with an error
logged, and fail the FMU; a refused step fails it; every step of a failed FMU is
refused naming the first cause, until reset.

The statuses: FMI 2.0 refuses every call with fmi2Fatal (pythonfmu 0.7 has no other
failure). An FMI 3.0 twin refuses a step with fmi3Error (non-fatal: fmi3Reset revives
it) and every other call with fmi3Fatal, as pythonfmu3 makes every exception. FMI 3.0's
own calls: no setupExperiment; enterInitializationMode with a random tolerance, start
and stop time (each possibly undefined), the clock of the steps that follow starting
at that start time; setting the independent variable ``time`` (refused); doStep's
outputs (never terminateSimulation; lastSuccessfulTime t + h after an accepted step,
t after a refused one; pythonfmu3 writes neither eventHandlingNeeded nor earlyReturn).
After every call ``time`` must read 0 on a fresh or reset instance, t + h after an
accepted step, and be unchanged by anything else (pythonfmu3 drops the start time).
Crashes and hangs are caught by the caller (tests/test_fuzz.py runs this in a child
process with a time limit).
"""
from __future__ import annotations

import argparse
import copy
import json
import math
import sys
import time
from collections import Counter
from ctypes import byref
from pathlib import Path

from fmpy import extract
from fmpy.fmi3 import fmi3Boolean, fmi3Float64
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

from autopilot_fmu.smc import reference_step_bound  # noqa: E402
from cosim.core.fmi import FmuInstance, fmi_version, read_description  # noqa: E402
from cosim.core.instance import FmuCallError  # noqa: E402
from fmubuild.project import FMU_DIRS  # noqa: E402
from fmubuild.project import FMUS as PYTHON_FMUS  # noqa: E402
from fmukit.timebase import MAX_TIME  # noqa: E402

FMUS = ["ship", "pd_autopilot", "smc_autopilot", "guidance", "manoeuvre"]
FUZZED = {2: FMUS, 3: list(PYTHON_FMUS)}
"""The FMUs fuzzed in each FMI version: FMI 3.0, the twin of every Python FMU."""
STEP_SIZES = [0.1, 0.1, 0.1, 0.05, 0.25, 1.0, 7.3, 1e-9, 0.0, -0.1, math.nan, math.inf, 1e-12,
              2e4, 1e9]
EXTREMES = [0.0, -0.0, 1e-300, -1e-300, 1e300, -1e300, 1.7976931348623157e308, math.pi, 1e6]
TEXT = st.text(st.characters(codec="utf-8", exclude_characters="\x00"), max_size=40)
"""Strings: UTF-8 without NUL, which ends a C string (the master refuses it before any call,
as ValueError: cosim.core.values)."""
START_TIMES = [0.0, 0.0, 0.0, 10.0, -3.5, 1e-9, 1e6, 2e15]
"""FMI 3.0: enterInitializationMode's start time (also the clock of the steps after it)."""
STATE_CALLS = {2: ("getFMUstate", "serializeFMUstate", "deSerializeFMUstate", "setFMUstate",
                   "freeFMUstate"),
               3: ("getFMUState", "serializeFMUState", "deserializeFMUState", "setFMUState",
                   "freeFMUState")}
"""fmpy's names of get, serialize, deserialize, set and free state, by FMI version."""


class Expectation:
    """What a correct FMU does: the phase machine of its FMI version and the declared
    ranges."""

    def __init__(self, md):
        self.fmi = fmi_version(md)
        self.vars = {v.name: v for v in md.modelVariables if v.causality != "independent"}
        self.time_vr = _time_vr(md)
        self.reset()

    def reset(self) -> None:
        self.phase = "instantiated"
        self.failure: list[str] | None = None      # words naming why the FMU failed
        self.values = {n: _start(v) for n, v in self.vars.items() if v.causality != "output"}
        self.defaults = True
        self.time = 0.0                            # what FMI 3.0's time must read

    def valid(self, name: str) -> bool:
        v, value = self.vars[name], self.values[name]
        if v.type == "String":
            return True
        if not math.isfinite(value):
            return False
        low = float(v.min) if v.min is not None else -math.inf
        high = float(v.max) if v.max is not None else math.inf
        return low <= value <= high


def _time_vr(md) -> int | None:
    """The value reference of FMI 3.0's independent variable ``time``; None in FMI 2.0."""
    return next((v.valueReference for v in md.modelVariables if v.causality == "independent"),
                None)


def _start(v):
    if v.start is None:
        return None
    if v.type == "Real":
        return float(v.start)
    if v.type == "Integer":
        return int(v.start)
    return v.start


def values_for(v) -> st.SearchStrategy:
    """Any value a master might send to variable v, valid or not, of its type or not."""
    if v.type == "String":
        return st.one_of(TEXT, st.just(v.start),
                         st.just("0,0;10,0;10,10"), st.just("1,1"), st.just("0,0;0,0"))
    if v.type == "Integer":
        return st.one_of(st.integers(-2**31, 2**31 - 1), st.integers(-3, 60))
    low = float(v.min) if v.min is not None else -1e6
    high = float(v.max) if v.max is not None else 1e6
    return st.one_of(st.floats(low, high), st.floats(low, high), st.floats(),
                     st.sampled_from(EXTREMES + [math.nan, math.inf, -math.inf]),
                     st.just(float(v.start) if v.start is not None else 0.0))


def in_range(v) -> st.SearchStrategy:
    """A valid value of a Real input: within its declared range."""
    low = float(v.min) if v.min is not None else -1e6
    high = float(v.max) if v.max is not None else 1e6
    return st.floats(low, high)


def programs(md) -> st.SearchStrategy:
    """Random programs for the FMU that ``md`` describes, in its FMI version's calls."""
    fmi3 = fmi_version(md) == 3
    variables = [v for v in md.modelVariables if v.causality != "independent"]
    inputs = [v for v in variables if v.causality == "input"]
    sets = st.one_of(*[st.tuples(st.just("set"), st.just(v.name), values_for(v))
                       for v in variables])
    wrong_type = st.tuples(st.just("set_wrong_type"), st.sampled_from([v.name for v in variables]))
    steps = st.tuples(st.just("step"), st.sampled_from(STEP_SIZES),
                      st.sampled_from(["clock", "clock", "clock", "zero", "huge", "negative"]))
    if fmi3:
        undefined_or = st.one_of(st.none(), st.floats())  # tolerance, stop time
        enter = st.tuples(st.just("enter"), undefined_or,
                          st.one_of(st.sampled_from(START_TIMES), st.floats()), undefined_or)
        calls = st.one_of(enter, st.sampled_from([("exit",), ("terminate",), ("reset",),
                                                  ("get",), ("state",)]),
                          st.tuples(st.just("set_time"), st.floats()))
        opening = enter.map(lambda call: [call])
    else:
        calls = st.sampled_from([("setup",), ("enter",), ("exit",), ("terminate",), ("reset",),
                                 ("get",), ("state",)])
        opening = st.just([("setup",), ("enter",)])
    anything = st.lists(st.one_of(sets, wrong_type, steps, calls), max_size=25)
    input_sets = (st.one_of(*[st.tuples(st.just("set"), st.just(v.name), values_for(v))
                              for v in inputs]) if inputs else st.nothing())
    valid_input_sets = (st.one_of(*[st.tuples(st.just("set"), st.just(v.name), in_range(v))
                                    for v in inputs]) if inputs else st.nothing())
    # Mostly a well-formed run with random values, sometimes random calls after it.
    valid_steps = st.tuples(st.just("step"), st.sampled_from([0.1, 0.1, 0.05, 0.3, 2.0]),
                            st.just("clock"))
    running = st.lists(st.one_of(valid_input_sets, valid_input_sets, input_sets, valid_steps,
                                 valid_steps, steps, st.just(("get",)), st.just(("state",))),
                       max_size=40)
    parameters = st.lists(st.one_of(*[st.tuples(st.just("set"), st.just(v.name),
                                                values_for(v))
                                      for v in variables if v.causality == "parameter"]),
                          max_size=3)
    well_formed = st.builds(lambda o, p, s, r, a: [*o, *p, ("exit",), s, *r, *a],
                            opening, parameters, valid_steps, running, anything)
    return st.one_of(well_formed, well_formed, anything)


def run_program(fmu: FmuInstance, expected: Expectation, program: list, counts: Counter) -> None:
    clock = 0.0
    for op in program:
        kind = op[0]
        counts["calls"] += 1
        must, names = _predict(op, expected, clock)
        try:
            _execute(op, fmu, clock)
            status, messages = "ok", []
        except FmuCallError as error:
            status, messages = error.status, error.messages
        counts[f"{kind} {status}"] += 1
        where = f"{op!r} in phase {expected.phase}"
        if status == "ok":
            assert must != "refuse", f"accepted an invalid call: {where}"
        else:
            assert must != "accept", f"refused a valid call: {where}: {messages}"
            assert status == _refusal_status(kind, expected), f"{status}: {where}"
            text = " ".join(messages)
            assert messages and any(n in text for n in names), \
                f"refusal does not name {names}: {where}: {messages}"
        _advance(op, status, expected, names)
        outputs = [v.name for v in fmu.description.modelVariables
                   if v.causality == "output" and v.type == "Real"]
        if expected.failure and kind in ("step", "get"):
            values = fmu.get(outputs)
            assert all(math.isnan(x) for x in values.values()), \
                f"outputs of a failed FMU after {where}: {values}"
        elif kind == "step" and status == "ok":
            clock = expected.time = _clock(op, clock) + op[1]
            values = fmu.get(outputs)
            bad = {n: x for n, x in values.items() if not math.isfinite(x)}
            assert not bad, f"non-finite outputs after an accepted {where}: {bad}"
            counts["valid steps"] += 1
        elif kind == "enter" and status == "ok" and expected.fmi == 3:
            clock = op[2]                       # the steps start at the start time
        if expected.fmi == 3:
            time_now = fmu.call("get time", fmu.slave.getFloat64, [expected.time_vr])[0]
            assert _same(time_now, expected.time), \
                f"time reads {time_now}, not {expected.time}, after {where}"


def _clock(op, clock: float) -> float:
    return {"clock": clock, "zero": 0.0, "huge": 2 * MAX_TIME, "negative": -5.0}[op[2]]


FAILED_AT_EXIT = "OK but logged an error"
"""How the master reports invalid parameters: exitInitializationMode returns OK, logs."""


def _refusal_status(kind: str, e: Expectation) -> str:
    """The status of a refused call: see FAILED_AT_EXIT; FMI 3.0's refused step fmi3Error;
    every other refusal fatal."""
    if kind == "exit" and e.phase == "initialization":
        return FAILED_AT_EXIT
    return "error" if kind == "step" and e.fmi == 3 else "fatal"


def _same(a: float, b: float) -> bool:
    """Equal, or both NaN."""
    return a == b or (a != a and b != b)


def _predict(op, e: Expectation, clock: float) -> tuple[str, list[str]]:
    """('accept' | 'refuse' | 'either', words one of which a refusal must contain)."""
    kind = op[0]
    phase_words = ["not allowed in phase"]
    if kind in ("setup", "enter"):
        return ("accept" if e.phase == "instantiated" else "refuse"), phase_words
    if kind == "exit":
        if e.phase != "initialization":
            return "refuse", phase_words
        params = [n for n, v in e.vars.items() if v.causality == "parameter"]
        if any(not e.valid(n) for n in params):  # reported, and the FMU has failed
            return "refuse", ["parameter"]
        return ("accept" if e.defaults else "either"), ["parameter"]
    if kind == "terminate":
        return ("accept" if e.phase == "step" or e.failure else "refuse"), phase_words
    if kind in ("reset", "get"):
        return "accept", []
    if kind == "state":
        return "accept", []
    if kind == "set_wrong_type":
        return "refuse", [op[1], "type"]
    if kind == "set_time":                  # FMI 3.0's independent variable
        return "refuse", ["time", f"value reference {e.time_vr}"]
    if kind == "set":
        v = e.vars[op[1]]
        if v.causality == "output":
            return "refuse", [op[1]]
        if e.phase == "terminated":
            return "refuse", [op[1]]
        if v.causality == "parameter" and e.phase == "step":     # a tunable one, valid
            trial = copy.copy(e)
            trial.values = {**e.values, op[1]: _convert(v, op[2])}
            if v.variability != "tunable" or not trial.valid(op[1]):
                return "refuse", [op[1]]
        return "accept", []
    if kind == "step":
        h, t = op[1], _clock(op, clock)
        if e.failure:
            return "refuse", e.failure
        if e.phase != "step":
            return "refuse", ["phase"]
        if not (0.0 < h <= MAX_TIME and abs(t) <= MAX_TIME):
            return "refuse", ["communication step"]
        bad = [n for n, v in e.vars.items() if v.causality == "input" and not e.valid(n)]
        if bad:
            return "refuse", bad
        if math.ceil(h / _largest_internal_step(e) - 1e-9) > 100_000:
            return "refuse", ["RK4 steps"]
        return "accept", []
    raise AssertionError(op)


def _largest_internal_step(e: Expectation) -> float:
    """The FMU's largest integration step: h_max (ship), the reference model's (SMC)."""
    if "h_max" in e.values:
        return e.values["h_max"]
    if "omega_n" in e.values:
        return reference_step_bound(e.values["omega_n"], e.values["zeta"])
    return math.inf


def _execute(op, fmu: FmuInstance, clock: float) -> None:
    kind, slave = op[0], fmu.slave
    if kind == "setup":
        fmu.call("setupExperiment", slave.setupExperiment, startTime=0.0)
    elif kind == "enter":                   # FMI 3.0: tolerance, start and stop time
        fmu.call("enterInitializationMode", slave.enterInitializationMode, *op[1:])
    elif kind == "exit":
        fmu.exit_initialization()
    elif kind == "terminate":
        fmu.call("terminate", slave.terminate)
    elif kind == "reset":
        fmu.reset()
    elif kind == "get":                     # FMI 3.0's time: after every call
        fmu.get(fmu.variables)
    elif kind == "set":
        fmu.set({op[1]: op[2]})
    elif kind == "set_wrong_type":
        v = fmu.variable(op[1])
        setter, value = ((fmu.fmi("setInteger"), 1) if v.type == "Real"
                         else (fmu.fmi("setReal"), 1.0))
        fmu.call(f"set {op[1]} with the wrong type", setter, [v.valueReference], [value])
    elif kind == "set_time":
        fmu.call("set time", fmu.fmi("setReal"), [_time_vr(fmu.description)], [op[1]])
    elif kind == "step" and fmi_version(fmu.description) == 3:
        _step3(fmu, _clock(op, clock), op[1])
    elif kind == "step":
        fmu.do_step(_clock(op, clock), op[1])
    elif kind == "state":
        get, serialize, deserialize, set_, free = STATE_CALLS[fmi_version(fmu.description)]
        before = fmu.get(fmu.variables)
        state = fmu.call(get, getattr(slave, get))
        data = fmu.call(serialize, getattr(slave, serialize), state)
        again = fmu.call(deserialize, getattr(slave, deserialize), data)
        fmu.call(set_, getattr(slave, set_), again)
        assert fmu.call(serialize, getattr(slave, serialize), again) == data
        after = fmu.get(fmu.variables)
        same = all(_same(a, b) for a, b in zip(before.values(), after.values()))
        assert same, f"state round trip changed values: {before} -> {after}"
        fmu.call(free, getattr(slave, free), state)
        fmu.call(free, getattr(slave, free), again)


def _step3(fmu: FmuInstance, t: float, h: float) -> None:
    """fmi3DoStep, its outputs checked: terminateSimulation never set, lastSuccessfulTime
    t + h after an accepted step and t after a refused one (FmuCallError)."""
    slave = fmu.slave
    event, terminate, early, last = fmi3Boolean(), fmi3Boolean(), fmi3Boolean(), fmi3Float64()

    def outputs(reached: float) -> None:
        assert not terminate.value, f"doStep({t}, {h}) asked to end the simulation"
        assert _same(last.value, reached), \
            f"doStep({t}, {h}): lastSuccessfulTime {last.value}, not {reached}"
    try:
        fmu.call("doStep", slave.fmi3DoStep, slave.component, t, h, True, byref(event),
                 byref(terminate), byref(early), byref(last), time=t)
    except FmuCallError:
        outputs(t)
        raise
    outputs(t + h)


def _advance(op, status: str, e: Expectation, names: list[str]) -> None:
    kind = op[0]
    if status == FAILED_AT_EXIT:
        e.phase, e.failure = "step", names
    elif kind == "step" and status != "ok" and e.phase == "step" and not e.failure:
        e.failure = names
    if status != "ok":
        return
    if kind == "enter":
        e.phase = "initialization"
    elif kind == "exit":
        e.phase = "step"
    elif kind == "terminate":
        e.phase = "terminated"
    elif kind == "reset":
        e.reset()
    elif kind == "set":
        v = e.vars[op[1]]
        e.values[op[1]] = _convert(v, op[2])
        if v.causality == "parameter" and e.values[op[1]] != _start(v):
            e.defaults = False


def _convert(v, value):
    if v.type == "Integer":
        return int(value)
    if v.type == "String":
        return str(value)
    return float(value)


def _without_local_constants() -> None:
    """Hypothesis 6.131 and later also draws the literals of every local module imported (this
    project's code): a campaign's draws, and so its counts, would change with any edit of the
    package or its imports. Without them, they depend on the seed and the FMU alone."""
    try:
        from hypothesis.internal.conjecture import providers
    except ImportError:                                  # an older Hypothesis: none drawn
        return
    if hasattr(providers, "_get_local_constants"):
        providers._get_local_constants = providers.Constants


def fuzz(name: str, examples: int, seed: int | None = None, fmi: int = 2) -> dict:
    """Fuzz FMU ``name`` of FMI version ``fmi`` (its FMI 3.0 twin: fmus/fmi3/) with
    ``examples`` programs; the counts of calls by kind and status."""
    fmu_path = FMU_DIRS[fmi] / f"{name}.fmu"
    md = read_description(fmu_path, name)
    unzipped = extract(str(fmu_path))
    counts: Counter = Counter()

    @settings(max_examples=examples, deadline=None, database=None, derandomize=seed is None,
              suppress_health_check=list(HealthCheck))
    @given(programs(md))
    def check(program):
        counts["examples"] += 1
        fmu = FmuInstance(fmu_path, name, unzip_dir=unzipped)
        try:
            run_program(fmu, Expectation(md), program, counts)
        finally:
            fmu.free()

    _without_local_constants()
    started = time.perf_counter()
    check()
    return {"fmu": name, "fmi": fmi, "seconds": round(time.perf_counter() - started, 1),
            **dict(sorted(counts.items()))}


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("names", nargs="*", choices=[[], *FUZZED[3]], metavar="FMU",
                        help="the FMUs to fuzz (default: all); each in the versions it is "
                        "fuzzed in (pid_autopilot: FMI 3.0 only)")
    parser.add_argument("--all", action="store_true", help="every FMU")
    parser.add_argument("--fmi", type=int, choices=sorted(FUZZED), action="append",
                        help="only this FMI version (2 or 3; default: both)")
    parser.add_argument("--examples", type=int, default=2000)
    args = parser.parse_args(argv)
    for fmi in args.fmi or sorted(FUZZED):
        for name in (FUZZED[fmi] if args.all or not args.names else args.names):
            if name in FUZZED[fmi]:
                print(json.dumps(fuzz(name, args.examples, fmi=fmi)), flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
