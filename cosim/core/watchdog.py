"""Time limits for a run, and signals that reach it even while an FMU never returns: a thread
beside the loop raises ``TimeLimit`` into a call past a limit, or else ends the process."""
from __future__ import annotations

import ctypes
import faulthandler
import math
import os
import select
import signal
import socket
import sys
import threading
import time
from typing import Callable, NamedTuple

from .instance import Instance
from .interrupt import STOP_SIGNALS, StopSignals, give_back, take_signals

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


def no_limit(what: str | float) -> None:
    """``Watchdog.beat`` where there is no watchdog."""


class TimeLimit(BaseException):
    """Raised in the loop's thread past a limit; a BaseException: no ``except`` swallows it."""

    def __init__(self, *args: object):
        super().__init__(*(args or ("a time limit of the run was passed",)))


class Watchdog:
    """``dog.beat(what)`` as each step or call begins; ``dog.expired``: the limit passed;
    ``salvage(reason)`` writes what it can if the loop never returns, saying what it kept."""

    def __init__(self, limits: Limits = Limits(), stop: StopSignals | None = None,
                 salvage: Callable[[str], str] | None = None):
        self.limits, self.stop, self.salvage = limits.check(), stop, salvage
        self.expired: str | None = None
        self._what: str | float = "the start of the run"
        self._grace: tuple[float, str] | None = None   # since when, after what
        self._raise = True                             # TimeLimit may be raised into the loop
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

    def finishing(self, what: str) -> None:
        """The run is over and ``what`` (terminating the FMUs) begins: nothing is raised into
        it (an exception has no safe way out of pythonfmu's fmi2Terminate)."""
        self._raise = False
        self.beat(what)

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
        if self.expired:              # one raised too late to land is cleared, not left armed
            _raise_in(self._target, None)
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

    def _deadline(self) -> tuple[float, str]:              # reason '': the run limit
        what = self._what if isinstance(self._what, str) else \
            f"the step at t = {self._what:.6g} s"
        limits, candidates = self.limits, [(math.inf, "")]
        if limits.step is not None:
            candidates.append((self._beat + limits.step, f"{what} did not end within the "
                                                         f"step time limit of {limits.step:g} s"))
        if limits.run is not None and self.expired is None:
            candidates.append((self._start + limits.run, ""))
        if self._grace is not None:
            since, after = self._grace
            candidates.append((since + limits.grace,
                               f"{what} did not end within {limits.grace:g} s of {after}"))
        return min(candidates)

    def _watch(self) -> None:
        while not self._done.is_set():
            wait = min(max(self._deadline()[0] - time.monotonic(), 0.0), 0.5)
            if self._signals:
                select.select([self._wakeup[0]], [], [], wait)
                received = self._received()
                for number in received:
                    self._grace = self._grace or (time.monotonic(), number.name)
                    self.stop.receive(number)        # a second one ends the process
                if received:
                    continue
            elif self._done.wait(wait):
                return
            deadline, reason = self._deadline()    # a beat while it waited moves the limit
            if time.monotonic() < deadline or self._done.is_set():
                continue
            if reason:
                return self._expire(reason)
            self.expired = (f"the run did not end within its time limit of "
                            f"{self.limits.run:g} s")     # the loop stops at its next beat
            self._grace = self._grace or (time.monotonic(), "the run time limit")

    def _expire(self, reason: str) -> None:
        """Raise TimeLimit in the loop's thread; if it has not returned after the grace, keep
        what can be kept and end the process (status 1, or 130/143 after a signal)."""
        where = _calling(self._target)
        self.expired = reason = f"{reason} ({where})" if where else reason
        deadline = time.monotonic() + self.limits.grace
        if self._raise:
            while not where and time.monotonic() < deadline:    # the master's own code:
                if self._done.wait(0.01):                        # its loop stops at the beat
                    return
                where = _calling(self._target)
            if where:
                _raise_in(self._target, TimeLimit)
                deadline = time.monotonic() + self.limits.grace
        if self._done.wait(max(deadline - time.monotonic(), 0.0)):
            return
        faulthandler.dump_traceback_later(self.limits.grace + 10, exit=True)
        kept = "nothing was written"
        if self.salvage is not None:
            try:
                kept = self.salvage(reason)
            except BaseException as error:         # whatever happens, the process ends
                kept = f"the rows could not be written ({error})"
        why = ("it cannot be stopped (code that is not Python)" if self._raise else
               "the run is over (nothing is raised into an FMU's clean-up)")
        print(f"error: {reason}, and {why}; {kept}; ending the process", file=sys.stderr,
              flush=True)
        os._exit(self.stop.exit_status if self.stop is not None and self.stop.received else 1)


def _calling(thread_id: int) -> str | None:
    """The FMU and call the thread is in ("FMU 'ship' in doStep"), from its stack, or None."""
    frame = sys._current_frames().get(thread_id)
    while frame is not None:
        owner, what = frame.f_locals.get("self"), frame.f_locals.get("what")
        if isinstance(owner, Instance):
            call = what if isinstance(what, str) else frame.f_code.co_name
            return f"FMU '{owner.name}' in {'doStep' if call == 'step' else call}"
        frame = frame.f_back
    return None


def _idle(number: int, frame: object) -> None:     # SIGINT and SIGTERM while a watchdog reads them
    pass


_idle.safe_in_fmu_code = True      # fmukit need not defer it (fmukit.hostsignals)


def _raise_in(thread_id: int, exception: type[BaseException] | None) -> None:
    """Raise ``exception`` in a thread at its next Python instruction (None: clear one)."""
    ctypes.pythonapi.PyThreadState_SetAsyncExc(ctypes.c_ulong(thread_id),
                                               ctypes.py_object(exception) if exception
                                               else None)
