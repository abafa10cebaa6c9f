"""Time limits for a run, and signals that reach it even while an FMU never returns: past a
limit, a thread beside the loop kills the isolated FMU's process the loop waits for (``core.
isolated``: the run ends with its rows), or else keeps what it can and ends this process."""
from __future__ import annotations

import faulthandler
import math
import select
import signal
import socket
import sys
import threading
import time
from typing import Callable, NamedTuple

from .interrupt import STOP_SIGNALS, StopSignals, end_now, give_back, take_signals
from .isolated import kill_awaited

STEP_LIMIT_S = 60.0          # the default step limit, far above a step's or instantiation's


class Limits(NamedTuple):
    """Wall-clock limits in seconds (None: none): of a step (or instantiation), of the run
    (the loop stops at its next step), of the step under way after a signal or the run's."""
    step: float | None = STEP_LIMIT_S
    run: float | None = None
    grace: float = 3.0

    def check(self) -> Limits:
        for name, value in self._asdict().items():
            if value is not None and not 0 < value < math.inf:
                raise ValueError(f"the {name} time limit must be a positive number of "
                                 f"seconds, got {value!r}")
        return self


class TimeLimit(RuntimeError):
    """A time limit was passed where the loop can stop (the batch route's)."""


def no_limit(what: str | float) -> None:
    """``Watchdog.beat`` where there is no watchdog."""


class Watchdog:
    """``dog.beat(what)`` as each step or call begins; ``dog.expired``: the limit passed;
    ``salvage(reason)`` writes what it can before the process ends, saying what it kept."""

    def __init__(self, limits: Limits = Limits(), stop: StopSignals | None = None,
                 salvage: Callable[[str], str] | None = None):
        self.limits, self.stop, self.salvage = limits.check(), stop, salvage
        self.expired: str | None = None
        self.calling: list[str | None] = [None]    # the component whose calls are under way
        self._what: str | float = "the start of the run"
        self._grace: tuple[float, str] | None = None   # since when, after what
        self._target = threading.get_ident()
        self._done = threading.Event()
        self._thread = threading.Thread(target=self._watch, name="cosim-watchdog", daemon=True)
        self._signals = stop is not None and threading.current_thread() is threading.main_thread()

    def beat(self, what: str | float) -> str | None:
        """A step (its time, in s) or call (a phrase) begins; ``expired``: not None stops it."""
        self._beat, self._what = time.monotonic(), what
        return self.expired

    def halt(self, reason: str) -> None:
        """Have the loop stop at its next beat, with ``reason`` as its error."""
        self.expired = reason

    def __enter__(self) -> Watchdog:
        self._beat = self._start = time.monotonic()
        if self._signals:                # signals to this socket; Python's handlers idle
            self._wakeup = socket.socketpair()
            for end in self._wakeup:
                end.setblocking(False)
            self._saved = (signal.set_wakeup_fd(self._wakeup[1].fileno(),
                                                warn_on_full_buffer=False), take_signals(_idle))
        self._thread.start()
        return self

    def __exit__(self, *exc) -> None:
        self._done.set()
        self._thread.join()
        if self._signals:
            signal.set_wakeup_fd(self._saved[0])
            give_back(self._saved[1])
            for number in self._received():         # one that came as the run ended
                self.stop.receive(number)
            for end in self._wakeup:
                end.close()

    def _received(self) -> list[signal.Signals]:
        try:
            data = self._wakeup[0].recv(64)
        except BlockingIOError:
            return []
        return [signal.Signals(number) for number in data if number in STOP_SIGNALS]

    def _deadline(self) -> tuple[float, str]:   # the limit passed then ('': the run's)
        limits, candidates = self.limits, [(math.inf, "")]
        if limits.step is not None:
            candidates.append((self._beat + limits.step,
                               f"the step time limit of {limits.step:g} s"))
        if limits.run is not None and self.expired is None:
            candidates.append((self._start + limits.run, ""))
        if self._grace is not None:
            since, after = self._grace
            candidates.append((since + limits.grace, f"{limits.grace:g} s of {after}"))
        return min(candidates)

    def _watch(self) -> None:
        while not self._done.is_set():
            wait = min(max(self._deadline()[0] - time.monotonic(), 0.0), 0.5)
            if self._signals:
                select.select([self._wakeup[0]], [], [], wait)
                for number in self._received():
                    again = self.stop.received is not None
                    if not (again and kill_awaited(self._target, f"killed on a second "
                                                                 f"{number.name}")):
                        self.stop.receive(number)   # a second one ends the process
                    self._grace = self._grace or (time.monotonic(), number.name)
            elif self._done.wait(wait):
                return
            deadline, limit = self._deadline()    # a beat while it waited moves the limit
            if time.monotonic() < deadline or self._done.is_set():
                continue
            if not limit:
                self.expired = (f"the run did not end within its time limit of "
                                f"{self.limits.run:g} s")     # the loop stops at its next beat
                self._grace = self._grace or (time.monotonic(), "the run time limit")
            elif kill_awaited(self._target, f"killed when it did not end within {limit}"):
                self._beat, self._grace = time.monotonic(), None    # the loop ends the run
            else:
                what = self._what if isinstance(self._what, str) else \
                    f"the step at t = {self._what:.6g} s"
                where = f" (in FMU '{self.calling[0]}')" if self.calling[0] else ""
                self._end(f"{what} did not end within {limit}{where}")

    def _end(self, reason: str) -> None:
        """Keep what can be kept and end the process (status 1, or 130/143 after a signal):
        an FMU in this process that does not return cannot be stopped."""
        faulthandler.dump_traceback_later(self.limits.grace + 10, exit=True)  # if salvage hangs
        kept = "nothing was written"
        if self.salvage is not None:
            try:
                kept = self.salvage(reason)
            except BaseException as error:         # whatever happens, the process ends
                kept = f"the rows could not be written ({error})"
        print(f"error: {reason}; {kept}; ending the process (an FMU that does not return "
              "cannot be stopped in it: --isolate runs each in a process of its own)",
              file=sys.stderr, flush=True)
        end_now(self.stop.exit_status if self.stop is not None and self.stop.received else 1)


def _idle(number: int, frame: object) -> None:     # SIGINT and SIGTERM while a watchdog reads them
    pass


_idle.safe_in_fmu_code = True      # fmukit need not defer it (fmukit.hostsignals)
