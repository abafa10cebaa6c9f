"""Ctrl-C and SIGTERM: a request to stop between steps (``StopSignals``: a KeyboardInterrupt
would fail an FMU's call), or an exception where no FMU runs (``raise_on_signals``)."""
from __future__ import annotations

import os
import signal
import sys
import threading
from contextlib import contextmanager
from typing import Callable, Iterator

from .isolated import kill_all

STOP_SIGNALS = (signal.SIGINT, signal.SIGTERM)


def take_signals(handler: Callable) -> dict:
    """``handler`` for SIGINT and SIGTERM (main thread only): the handlers it replaced."""
    if threading.current_thread() is not threading.main_thread():
        return {}
    return {number: signal.signal(number, handler) for number in STOP_SIGNALS}


def give_back(handlers: dict) -> None:
    for number, handler in handlers.items():
        signal.signal(number, handler)


class StopSignals:
    """``stop.received``: the first SIGINT or SIGTERM that arrived, or None (main thread)."""

    def __init__(self) -> None:
        self.received: signal.Signals | None = None
        self._keepers: list[Callable[[], str]] = []
        self._ending = threading.Lock()

    def __enter__(self) -> StopSignals:
        self._previous = take_signals(lambda number, frame: self.receive(signal.Signals(number)))
        return self

    def __exit__(self, *exc) -> None:
        give_back(self._previous)
        if self.received is not None and not _received:    # a later one ends at once
            _received.append(self.received)

    def receive(self, number: signal.Signals) -> None:
        """The first signal asks the run to stop between steps; a second ends the process at
        once (status 130 or 143), after each ``keep`` callback has said what is kept."""
        if self.received is None:
            self.received = number
            return
        if not self._ending.acquire(blocking=False):
            return                              # already ending
        kept = []
        for keeper in self._keepers:
            try:
                kept.append(keeper())
            except Exception as error:          # the process ends all the same
                kept.append(f"(could not tidy up: {error})")
        print(f"{number.name} again: stopped at once; " + ("; ".join(kept) or
              "nothing of the run under way was written"), file=sys.stderr, flush=True)
        end_now(128 + self.received)

    def keep(self, keeper: Callable[[], str]) -> Callable[[], None]:
        """Have ``keeper`` say what it kept if a second signal ends the process; returns an undo."""
        self._keepers.append(keeper)
        return lambda: self._keepers.remove(keeper) if keeper in self._keepers else None

    @property
    def exit_status(self) -> int:               # the shell's: 130, 143
        return 128 + self.received if self.received else 0

    def check(self) -> None:
        """Raise ``Interrupted`` if a signal has arrived."""
        if self.received is not None:
            raise Interrupted(self.received)


class Interrupted(BaseException):
    """A SIGINT or SIGTERM arrived (a BaseException, as KeyboardInterrupt is)."""

    def __init__(self, number: int):
        self.signal = signal.Signals(number)
        self.exit_status = 128 + self.signal
        super().__init__(f"interrupted by {self.signal.name}")


_received: list[signal.Signals] = []      # this command's signals so far


def _raise(number: int, frame) -> None:
    """The first signal raises ``Interrupted``; one more while it is handled ends at once."""
    number = signal.Signals(number)
    if _received:
        print(f"{number.name} again: stopped at once", file=sys.stderr, flush=True)
        end_now(128 + _received[0])
    _received.append(number)
    raise Interrupted(number)


@contextmanager
def raise_on_signals() -> Iterator[None]:
    """Within: SIGINT and SIGTERM raise ``Interrupted``, once (main thread only)."""
    _received.clear()
    previous = take_signals(_raise)
    try:
        yield
    finally:
        give_back(previous)


def end_now(status: int) -> None:
    """End the process at once, its FMUs' children first (``core.isolated``)."""
    kill_all("the master ended")
    os._exit(status)
