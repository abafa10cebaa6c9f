"""Ctrl-C and SIGTERM: the first asks a run to stop between steps (``StopSignals``: a
KeyboardInterrupt would fail an FMU's call) or, where no FMU runs, raises ``Interrupted``
(``StopSignals(raising=True)``); a second ends the process at once."""
from __future__ import annotations

import signal
import sys
import threading
import time
from typing import Callable

from .isolated import end_now, kill_awaited

STOP_SIGNALS = (signal.SIGINT, signal.SIGTERM)
_received: list[signal.Signals] = []      # this command's signals so far


class Interrupted(BaseException):
    """A SIGINT or SIGTERM arrived (a BaseException, as KeyboardInterrupt is)."""

    def __init__(self, number: int):
        self.signal = signal.Signals(number)
        self.exit_status = 128 + self.signal
        super().__init__(f"interrupted by {self.signal.name}")


class StopSignals:
    """Within (main thread only): ``received``, the first SIGINT or SIGTERM (``raising``: it
    raises ``Interrupted``); a second kills the isolated FMU's process the loop awaits or ends
    the process at once, status 130 or 143, after each ``keep`` callback has said what it kept.
    Not raising, it may run inside an FMU's code (``fmukit.hostsignals``)."""

    def __init__(self, raising: bool = False) -> None:
        self.raising, self.received, self.received_at = raising, None, None
        self._keepers: list[Callable[[], str]] = []
        self._ending = threading.Lock()

    def __enter__(self) -> StopSignals:
        if self.raising:                        # a command begins
            _received.clear()

        def handler(number: int, frame: object) -> None:
            self.receive(signal.Signals(number))
        handler.safe_in_fmu_code = not self.raising
        main = threading.current_thread() is threading.main_thread()
        self._previous = {n: signal.signal(n, handler) for n in STOP_SIGNALS if main}
        return self

    def __exit__(self, *exc) -> None:
        for number, handler in self._previous.items():
            signal.signal(number, handler)
        if self.received is not None and not _received:    # a later one ends at once
            _received.append(self.received)

    def receive(self, number: signal.Signals) -> None:
        first = self.received or (_received[0] if _received else None)
        if first is None:
            self.received, self.received_at = number, time.monotonic()
            if self.raising:
                _received.append(number)
                raise Interrupted(number)
            return
        if kill_awaited(threading.get_ident(), f"killed on a second {number.name}") or \
                not self._ending.acquire(blocking=False):
            return                              # the loop ends the run; or already ending
        kept = []
        for keeper in self._keepers:
            try:
                kept.append(keeper())
            except Exception as error:          # the process ends all the same
                kept.append(f"(could not tidy up: {error})")
        if not (kept or self.raising):
            kept = ["nothing of the run under way was written"]
        print(f"{number.name} again: stopped at once" + "".join(f"; {k}" for k in kept),
              file=sys.stderr, flush=True)
        end_now(128 + first)

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
