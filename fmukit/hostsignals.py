"""Ctrl-C while an FMU computes: the host's handler runs in the host's code, not ours (in FMU
code a KeyboardInterrupt would escape to pythonfmu's C++ layer, which loses it and releases
the instance once too often): the signal is raised again until the host's code runs."""
from __future__ import annotations

import _thread
import ctypes
import signal
import sys
import threading
import time
import traceback
from typing import Callable

SIGNALS = (signal.SIGINT, signal.SIGTERM)
ENTRY = f"{__package__}.entry"                      # fmi_entry's wrapper: FMU code below it
_pending: set[signal.Signals] = set()   # arrived while FMU code ran; not yet handled


def _deferring(host_handler: Callable) -> Callable:
    def deferring_handler(number: int, frame) -> object:
        if frame is not None and any(f.f_code.co_name == "entry" and f.f_globals.get("__name__")
                                     == ENTRY for f, _ in traceback.walk_stack(frame)):
            first = not _pending            # signalled again each ms until host code runs
            _pending.add(signal.Signals(number))
            if first:
                threading.Thread(target=_signal_again, name="fmukit-signals",
                                 daemon=True).start()
            return None
        _pending.discard(signal.Signals(number))
        return host_handler(number, frame)
    deferring_handler.safe_in_fmu_code = True       # deferred already: not wrapped again
    return deferring_handler


def _signal_again() -> None:
    while _pending:
        time.sleep(0.001)
        for number in tuple(_pending):
            _thread.interrupt_main(number)


def defer_host_handlers() -> None:
    """Wrap the host's Python handlers of SIGINT and SIGTERM (not one with a true
    ``safe_in_fmu_code``); in a host that is not Python, give SIGINT its default action back
    (undoing Python's start-up handler in the C library that installed it; on Windows, the
    Universal CRT)."""
    if not sys.orig_argv and signal.getsignal(signal.SIGINT) is signal.default_int_handler:
        libc = ctypes.CDLL("ucrtbase") if sys.platform == "win32" else ctypes.CDLL(None)
        libc.signal.argtypes = (ctypes.c_int, ctypes.c_void_p)
        libc.signal.restype = ctypes.c_void_p
        libc.signal(signal.SIGINT, None)      # SIG_DFL; Python's own record of it stays
    elif sys.orig_argv and threading.current_thread() is threading.main_thread():
        for number in SIGNALS:
            handler = signal.getsignal(number)
            if callable(handler) and not getattr(handler, "safe_in_fmu_code", False):
                signal.signal(number, _deferring(handler))
