"""Time limits for a run, and signals that reach it even while an FMU never returns.

A ``Watchdog`` is a thread beside the master's loop enforcing a step time limit
(``Limits.step``: one communication step, or one instantiation, in wall-clock seconds), a run
time limit (``Limits.run``) and a signal's grace (``Limits.grace``: after Ctrl-C or SIGTERM
the step under way must end within it). In the main thread it takes SIGINT and SIGTERM from
Python's wakeup file descriptor, which the C-level handler writes while FMU code runs; a
second signal ends the process (``StopSignals.receive``).

Past the run limit the loop stops at its next step (``beat`` says why). A step that does not
end is hung: ``TimeLimit`` is raised in the loop's thread (``PyThreadState_SetAsyncExc``,
only while an FMU call is under way), where Python FMU code fails its call and the master
stops as after any FMU failure. Code that runs no Python cannot take it: after the grace the
watchdog writes the rows kept (``salvage``), says so, and ends the process (status 1, or
130/143 after a signal); ``faulthandler`` ends it if even that cannot run.
"""
from __future__ import annotations

import ctypes
import faulthandler
import os
import select
import signal
import socket
import sys
import threading
import time
from types import TracebackType
from typing import Callable, NamedTuple

from .instance import Instance
from .interrupt import STOP_SIGNALS, StopSignals

STEP_LIMIT_S = 60.0
"""The default step time limit, far above a step's or an instantiation's time."""


class Limits(NamedTuple):
    """Wall-clock limits in seconds (None: no limit)."""

    step: float | None = STEP_LIMIT_S
    run: float | None = None
    grace: float = 3.0

    def check(self) -> Limits:
        """These limits, or ValueError naming the one that is not a positive number."""
        for name, value in (("step", self.step), ("run", self.run), ("grace", self.grace)):
            if value is not None and not (value > 0 and value < float("inf")):
                raise ValueError(f"the {name} time limit must be a positive number of "
                                 f"seconds, got {value!r}")
        return self


def no_limit(what: str | float) -> None:
    """``Watchdog.beat`` where there is no watchdog."""


class TimeLimit(BaseException):
    """Raised in the loop's thread when a limit is passed (a BaseException: no ``except
    Exception`` swallows it; ``Watchdog.expired`` says which)."""

    def __init__(self, *args: object):
        super().__init__(*(args or ("a time limit of the run was passed",)))


class Watchdog:
    """``with Watchdog(limits, stop) as dog``: ``dog.beat(what)`` as each step (or
    instantiation) begins; ``dog.expired`` says which limit was passed. ``salvage(reason)``,
    called from the watchdog's thread if the loop never returns, writes what it can and
    says what was kept."""

    def __init__(self, limits: Limits = Limits(), stop: StopSignals | None = None,
                 salvage: Callable[[str], str] | None = None):
        self.limits, self.stop, self.salvage = limits.check(), stop, salvage
        self.expired: str | None = None
        self._what: str | float = "the start of the run"
        self._beat = self._start = time.monotonic()
        self._signal_at: float | None = None      # when a signal came
        self._halt_at: float | None = None        # when the run time limit was passed
        self._raise = True                        # TimeLimit may be raised into the loop
        self._target = threading.get_ident()
        self._done = threading.Event()
        self._thread: threading.Thread | None = None
        self._signals = stop is not None and threading.current_thread() is threading.main_thread()
        self._wakeup: tuple[socket.socket, socket.socket] | None = None
        self._saved: tuple[int, dict] = (-1, {})

    def finishing(self, what: str) -> None:
        """The run is over and ``what`` (terminating the FMUs) begins: its limit starts now,
        and nothing is raised into it (an exception in fmi2Terminate has no safe way out of
        pythonfmu's C++); past the limit the rows are kept and the process ends."""
        self._raise = False
        self.beat(what)

    def beat(self, what: str | float) -> str | None:
        """A step (its time, in s) or call (a phrase) begins: its limit starts now. Returns
        ``expired``: the loop stops here if it is not None."""
        self._beat, self._what = time.monotonic(), what
        return self.expired

    @property
    def what(self) -> str:
        what = self._what
        return f"the step at t = {what:.6g} s" if isinstance(what, float) else what

    def __enter__(self) -> Watchdog:
        self._beat = self._start = time.monotonic()
        if self.limits.step is None and self.limits.run is None and not self._signals:
            return self
        if self._signals:
            self._take_signals()
        self._thread = threading.Thread(target=self._watch, name="cosim-watchdog", daemon=True)
        self._thread.start()
        return self

    def __exit__(self, kind: type | None, error: BaseException | None,
                 trace: TracebackType | None) -> None:
        if self._thread is None:
            return
        self._done.set()
        self._thread.join()
        self._thread = None
        if self.expired:              # one raised too late to land is cleared, not left armed
            _raise_in(self._target, None)
        if self._signals:
            self._give_back_signals()

    def _take_signals(self) -> None:
        """Signals to this thread's socket; Python's handlers idle meanwhile."""
        self._wakeup = socket.socketpair()
        for end in self._wakeup:
            end.setblocking(False)
        handlers = {number: signal.signal(number, _idle) for number in STOP_SIGNALS}
        self._saved = (signal.set_wakeup_fd(self._wakeup[1].fileno(),
                                            warn_on_full_buffer=False), handlers)

    def _give_back_signals(self) -> None:
        fd, handlers = self._saved
        signal.set_wakeup_fd(fd)
        for number, handler in handlers.items():
            signal.signal(number, handler)
        for received in self._received():       # one that came as the run ended
            self.stop.receive(received)
        for end in self._wakeup:
            end.close()
        self._wakeup = None

    def _received(self) -> list[signal.Signals]:
        try:
            data = self._wakeup[0].recv(64)
        except BlockingIOError:
            return []
        return [signal.Signals(number) for number in data if number in STOP_SIGNALS]
    def _deadline(self) -> tuple[float, str]:
        candidates = [(float("inf"), "")]
        if self.limits.step is not None:
            candidates.append((self._beat + self.limits.step,
                               f"{self.what} did not end within the step time limit of "
                               f"{self.limits.step:g} s"))
        if self.limits.run is not None and self.expired is None:
            candidates.append((self._start + self.limits.run, ""))
        if self._halt_at is not None:
            candidates.append((self._halt_at + self.limits.grace,
                               f"{self.what} did not end within {self.limits.grace:g} s of "
                               "the run time limit"))
        if self._signal_at is not None:
            candidates.append((self._signal_at + self.limits.grace,
                               f"{self.what} did not end within {self.limits.grace:g} s of "
                               f"{self.stop.received.name}"))
        return min(candidates)

    def _watch(self) -> None:
        while not self._done.is_set():
            deadline, reason = self._deadline()
            wait = min(max(deadline - time.monotonic(), 0.0), 0.5)
            if self._signals:
                select.select([self._wakeup[0]], [], [], wait)
                received = self._received()
                for number in received:
                    self._signal_at = self._signal_at or time.monotonic()
                    self.stop.receive(number)        # a second one ends the process
                if received:
                    continue
            elif self._done.wait(wait):
                return
            deadline, reason = self._deadline()    # a beat while it waited moves the limit
            if time.monotonic() >= deadline and not self._done.is_set():
                if not reason:          # the run limit: the loop stops at its next beat
                    self.expired = (f"the run did not end within its time limit of "
                                    f"{self.limits.run:g} s")
                    self._halt_at = time.monotonic()
                    continue
                self._expire(reason)
                return

    def _expire(self, reason: str) -> None:
        """The step under way is hung: raise TimeLimit in the loop's thread; if it has not
        returned after the grace, keep what can be kept and end the process."""
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
        status = self.stop.exit_status if self.stop is not None and self.stop.received else 1
        os._exit(status)


def _calling(thread_id: int) -> str | None:
    """The FMU and call the thread is in ("FMU 'ship' in doStep"), from its stack, or None.
    An ``Instance`` has its name from ``__new__`` on; prepared calls are closures over one."""
    frame = sys._current_frames().get(thread_id)
    while frame is not None:
        owner, what = frame.f_locals.get("self"), frame.f_locals.get("what")
        if isinstance(owner, Instance):
            call = what if isinstance(what, str) else _PREPARED.get(frame.f_code.co_name,
                                                                     frame.f_code.co_name)
            return f"FMU '{owner.name}' in {call}"
        frame = frame.f_back
    return None


_PREPARED = {"step": "doStep", "read": "a get call", "write": "a set call"}


def _idle(number: int, frame: object) -> None:
    """Python's handler of SIGINT and SIGTERM while a watchdog takes them."""


_idle.safe_in_fmu_code = True      # fmukit need not defer it (fmukit.hostsignals)


def _raise_in(thread_id: int, exception: type[BaseException] | None) -> None:
    """Raise ``exception`` in a thread at its next Python instruction (None: clear one)."""
    ctypes.pythonapi.PyThreadState_SetAsyncExc(ctypes.c_ulong(thread_id),
                                               ctypes.py_object(exception) if exception
                                               else None)
