"""Time limits for a run: past one, a thread beside the loop kills the isolated FMU's process
that the loop awaits (``core.isolated``: the run ends with its rows), or else keeps what it
can and ends this process (an FMU in it that does not return cannot be stopped)."""
from __future__ import annotations

import faulthandler
import math
import sys
import threading
import time
from typing import Callable, NamedTuple

from .interrupt import StopSignals
from .isolated import end_now, kill_awaited

STEP_LIMIT_S = 60.0          # the default step limit, far above a step's or instantiation's


class Limits(NamedTuple):
    """Wall-clock limits in seconds (None: none): of a step (or instantiation), of the run
    (it stops at its next step), of the step under way after a signal."""
    step: float | None = STEP_LIMIT_S
    run: float | None = None
    grace: float = 3.0

    def check(self) -> Limits:
        for name, value in self._asdict().items():
            if value is not None and not 0 < value < math.inf:
                raise ValueError(f"the {name} time limit must be a positive number of "
                                 f"seconds, got {value!r}")
        return self


def no_limit(what: str | float) -> None:
    """``Watchdog.beat`` where there is no watchdog."""


class Watchdog:
    """``dog.beat(what)`` as each step (its time) or call (a phrase) begins: ``expired``, not
    None once the run should stop (set it to stop it); ``salvage(reason)`` writes what it can
    and says what."""

    def __init__(self, limits: Limits = Limits(), stop: StopSignals | None = None,
                 salvage: Callable[[str], str] | None = None):
        self.limits, self.stop, self.salvage = limits.check(), stop, salvage
        self.expired: str | None = None
        self.calling: list[str | None] = [None]    # the component whose calls are under way
        self._target, self._done = threading.get_ident(), threading.Event()
        self._thread = threading.Thread(target=self._watch, name="cosim-watchdog", daemon=True)

    def beat(self, what: str | float) -> str | None:
        self._beat, self._what = time.monotonic(), what
        return self.expired

    def __enter__(self) -> Watchdog:
        self.beat("the start of the run")
        self._start = self._beat
        self._thread.start()
        return self

    def __exit__(self, *exc) -> None:
        self._done.set()
        self._thread.join()

    def _deadline(self) -> tuple[float, str]:   # when, and the limit passed then ('': the run's)
        limits, stop, candidates = self.limits, self.stop, [(math.inf, "")]
        if limits.step is not None:
            candidates.append((self._beat + limits.step,
                               f"the step time limit of {limits.step:g} s"))
        if limits.run is not None and self.expired is None:
            candidates.append((self._start + limits.run, ""))
        if stop and stop.received:                  # the step under way has its grace
            candidates.append((max(stop.received_at, self._beat) + limits.grace,
                               f"{limits.grace:g} s of {stop.received.name}"))
        return min(candidates)

    def _watch(self) -> None:
        """Past a limit, kill or end (status 1, or 130/143 after a signal) keeping what can be
        kept (``salvage``); past the run time limit, the loop stops at its next beat."""
        while not self._done.wait(min(max(self._deadline()[0] - time.monotonic(), 0.0), 0.1)):
            deadline, limit = self._deadline()    # a beat while it waited moves the limit
            if time.monotonic() < deadline:
                continue
            if not limit:
                self.expired = f"the run did not end within its time limit of " \
                               f"{self.limits.run:g} s"
            elif kill_awaited(self._target, f"killed when it did not end within {limit}"):
                self._beat = time.monotonic()       # the loop ends the run
            else:
                what = self._what if isinstance(self._what, str) else \
                    f"the step at t = {self._what:.6g} s"
                reason = f"{what} did not end within {limit}" + (
                    f" (in FMU '{self.calling[0]}')" if self.calling[0] else "")
                faulthandler.dump_traceback_later(self.limits.grace + 10, exit=True)  # if
                try:                                                    # salvage hangs
                    kept = self.salvage(reason) if self.salvage else "nothing was written"
                except BaseException as error:      # whatever happens, the process ends
                    kept = f"the rows could not be written ({error})"
                print(f"error: {reason}; {kept}; ending the process (an FMU that does not return "
                      "cannot be stopped in it: --isolate runs each in its own)",
                      file=sys.stderr, flush=True)
                end_now(self.stop.exit_status if self.stop and self.stop.received else 1)
