"""The time base: FMUs round time and step to whole nanoseconds and masters compute
t_k = t_0 + k h in integer nanoseconds, so masters that form time differently (libcosim
counts nanoseconds, fmpy adds floats) drive the FMUs bit for bit alike."""
NANOSECONDS = 1_000_000_000
MAX_TIME = 1e15                         # s: largest |t| an FMU accepts (30 million years)
EXACT_TIME = 2**53 / NANOSECONDS        # s: largest |t| whose every nanosecond a float holds


def nanoseconds(t: float) -> int:
    """Seconds -> whole nanoseconds (exact up to 2^53 ns, about 104 days)."""
    return round(t * NANOSECONDS)


def seconds(ns: int) -> float:
    """Whole nanoseconds -> seconds, correctly rounded."""
    return ns / NANOSECONDS


def on_time_base(t: float) -> float:
    """t rounded to whole nanoseconds: ``seconds(nanoseconds(t))``."""
    return round(t * NANOSECONDS) / NANOSECONDS


def communication_point(t0: float, k: int, h: float) -> float:
    """t_k = t_0 + k h, computed in integer nanoseconds."""
    return seconds(nanoseconds(t0) + k * nanoseconds(h))


def step_count(start: float, stop: float, step: float) -> int:
    """Communication steps of ``step`` from start to stop; ValueError unless a whole number >= 1."""
    for name, value in (("start time", start), ("stop time", stop), ("step size", step)):
        if not abs(value) <= MAX_TIME:
            raise ValueError(f"{name} {value} s is not a finite time within +-{MAX_TIME:g} s")
    h = nanoseconds(step)
    if h <= 0:
        raise ValueError(f"step size {step} s is not positive (at least 1 ns)")
    span = nanoseconds(stop) - nanoseconds(start)
    if span <= 0:
        raise ValueError(f"stop time {stop} s is not after the start time {start} s")
    n, remainder = divmod(span, h)
    if remainder and max(abs(start), abs(stop)) > EXACT_TIME:
        raise ValueError(f"stop time {stop} s is beyond {EXACT_TIME:.4g} s (2^53 ns, 104 "
                         "days), past which a float no longer holds every whole nanosecond: "
                         "its steps cannot be counted exactly")
    if remainder:
        raise ValueError(f"stop time {stop} s is not a whole number of {seconds(h)} s steps "
                         f"after {start} s")
    return n
