"""The child's side of an isolated FMU (``core.isolated``): it hosts one FMU and does what
the master's messages ask, each a kind byte and a length, then a payload; one reply each."""
from __future__ import annotations

import faulthandler
import functools
import os
import pickle
import struct
import sys
import threading
import time
from typing import Any, Callable

from .instance import Instance, LogRecord

HEADER = struct.Struct("<cI")             # a message: its kind and length, then its payload


def message(kind: bytes, payload: bytes) -> bytes:
    return HEADER.pack(kind, len(payload)) + payload


def send(write: Callable[[bytes], int], message: bytes) -> None:
    """``message`` whole through ``write`` (``os.write`` on a descriptor, say)."""
    sent = write(message)
    if sent < len(message):                 # above the pipe's buffer
        data = memoryview(message)[sent:]
        while data:
            data = data[write(data):]


class Garbled(OSError):
    """What came is not a message: something else wrote to the descriptor."""


def receive(fd: int) -> tuple[bytes, bytes]:
    data = os.read(fd, 65536)
    if data[:1] not in (b"", b"C", b"X", b"R", b"E"):
        raise Garbled(data[:20])
    while len(data) < HEADER.size or len(data) < HEADER.size + HEADER.unpack_from(data)[1]:
        more = os.read(fd, 65536)
        if not more:
            raise EOFError
        data += more
    return data[:1], data[HEADER.size:]


def serve() -> None:
    """Host one FMU for the parent on the other ends of this process's stdin and stdout."""
    requests, replies = os.dup(0), functools.partial(os.write, os.dup(1))   # not inherited
    os.dup2(os.open(os.devnull, os.O_RDONLY), 0)   # by what the FMU starts, which reads
    os.dup2(2, 1)                                  # nothing; what it prints goes to stderr
    limit = int(sys.argv[1])
    faulthandler.enable()                          # the FMU's traceback, if it crashes
    if os.name == "posix":
        threading.Thread(target=_orphaned, args=(os.getppid(),), daemon=True).start()
    if limit and os.name == "posix":                # within a hard limit already set
        import resource
        hard = resource.getrlimit(resource.RLIMIT_AS)[1]
        resource.setrlimit(resource.RLIMIT_AS, (limit if hard == resource.RLIM_INFINITY
                                                else min(limit, hard), hard))
    try:
        _serve(requests, replies)
    except (EOFError, OSError) as error:            # the parent has gone, or the FMU closed
        if not isinstance(error, EOFError):         # a pipe: the parent reads the end
            print(f"FMU host: the master's pipe failed ({error}); ending", file=sys.stderr)


def _serve(requests: int, replies: Callable[[bytes], int]) -> None:
    host: dict[str, Any] = {}
    while True:
        kind, payload = receive(requests)
        try:
            if kind == b"X":
                send(replies, host["exchange"](payload))
                continue
            method, args = pickle.loads(payload)
            send(replies, message(b"R", pickle.dumps(_handle(host, method, args))))
            if method == "free":
                return
        except BaseException as error:             # the parent decides what to do
            records = getattr(error, "records", None)
            if records is None:
                records = [LogRecord("fatal", None, f"{type(error).__name__}: {error}")]
            memory = isinstance(error, MemoryError) or any("MemoryError" in r.text
                                                            for r in records)
            send(replies, message(b"E", pickle.dumps((getattr(error, "call", None),
                                                        getattr(error, "status", "fatal"),
                                                        records, memory))))


def _orphaned(parent: int) -> None:
    """End this child once its parent has gone (it is given to another parent)."""
    while os.getppid() == parent:
        time.sleep(0.5)
    os._exit(1)


def _handle(host: dict[str, Any], method: str, args: tuple) -> Any:
    if method == "open":                            # the class, by its module's name
        hosted, path, name = args
        host["instance"] = hosted(path, name)
        return None
    instance = host["instance"]
    if method == "read":
        return instance.reader(*args)()
    if method == "write":
        return instance.writer(args[0])(args[1])
    if method == "step":
        return instance.stepper()(*args)
    if method == "prepare":
        host["exchange"] = _exchanger(instance, *args)
        return None
    return getattr(instance, method)(*args)       # set, get, the modes, reset, free


def _exchanger(instance: Instance, inputs: list[int], then: list, first: list
               ) -> Callable[[bytes], bytes]:
    """One step's work on a message: set the inputs, read ``then``, step, read ``first``."""
    ask = struct.Struct(f"<dd?{len(inputs)}d")
    size = sum(len(vrs) for vrs, _ in then + first)
    answer = struct.Struct(f"<cI{size}d")
    write = instance.writer(inputs) if inputs else None
    before = [instance.reader(vrs, kind) for vrs, kind in then if vrs]
    after = [instance.reader(vrs, kind) for vrs, kind in first if vrs]
    step = instance.stepper()

    def exchange(payload: bytes) -> bytes:
        t, h, advance, *values = ask.unpack(payload)
        if write:
            write(values)
        out = [v for read in before for v in read()]
        if advance:
            step(t, h)
        out += [v for read in after for v in read()]
        return answer.pack(b"R", answer.size - HEADER.size, *out)
    return exchange
