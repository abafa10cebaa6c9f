"""FMUs in processes of their own (``--isolate``, ``core.isolation``): a crash, an exit, a hang or runaway memory
ends the FMU's child, not the run. The master sends one message per FMU per step (inputs,
doStep, outputs) down the child's standard input and reads the reply from its standard output;
the child hosts the FMU as the master would have (``fmi`` or ``inprocess``)."""
from __future__ import annotations

import functools
import os
import pickle
import signal
import socket
import struct
import subprocess
import sys
import threading
from contextlib import contextmanager
from pathlib import Path
from typing import Any, Callable, Iterable, Iterator

from .fmi import described, read_description
from .fmu_host import HEADER, Garbled, message, receive, send
from .instance import FmuCallError, Instance
from .wiring import gatherer

ROOT = Path(__file__).resolve().parents[2]
CHILD = "from cosim.core.fmu_host import serve; serve()"
GARBLED = "it garbled its reply (something in it wrote to the master's socket)"
_live: dict[int, IsolatedInstance] = {}   # every child running, by process id
_awaited: dict[int, IsolatedInstance] = {}    # thread id: the child whose reply it awaits


class IsolatedInstance(Instance):
    """An FMU in a child process; its variables read here from its model description."""

    def __init__(self, path: str | Path, name: str, hosted: type[Instance],
                 memory_limit: int | None = None):
        """``hosted``: the class the child runs the FMU with (``FmuInstance``, ...)."""
        self.description = read_description(self.path, name)
        self.guid, self.memory_limit = self.description.guid, memory_limit
        self.variables, self.feedthrough = described(self.description)
        self.killed: str | None = None          # why the watchdog killed the child
        self._busy = False
        if os.name == "posix":     # its own session (no Ctrl-C from the terminal); a socket,
            mine, theirs = socket.socketpair()      # so that a dead child raises no SIGPIPE
            own: dict[str, Any] = {"start_new_session": True, "stdin": theirs, "stdout": theirs}
        else:
            own = {"creationflags": subprocess.CREATE_NEW_PROCESS_GROUP,
                   "stdin": subprocess.PIPE, "stdout": subprocess.PIPE}
        path_list = os.pathsep.join(filter(None, [str(ROOT), os.environ.get("PYTHONPATH")]))
        self.process = subprocess.Popen([sys.executable, "-c", CHILD, str(memory_limit or 0)],
                                        env={**os.environ, "PYTHONPATH": path_list}, **own)
        if os.name == "posix":
            theirs.close()
            self._pipes, self._from = [mine], mine.fileno()
            self._write = lambda data: mine.send(data, socket.MSG_NOSIGNAL)
        else:
            self._pipes, self._from = [self.process.stdin, self.process.stdout], \
                self.process.stdout.fileno()
            self._write = functools.partial(os.write, self.process.stdin.fileno())
        _live[self.process.pid] = self
        send(self._write, message(b"C", pickle.dumps(("open", (hosted, str(self.path), name)))))
        self._opening = True     # its reply is read with the next call's: children start together

    def _ask(self, request: bytes, what: str, time: float | None = None,
             size: int | None = None) -> bytes:
        """The child's reply to ``request`` (a whole message; ``size``: the payload's);
        FmuCallError if the FMU refused or the child did not reply (or garbled its reply)."""
        thread, doing = threading.get_ident(), ("instantiate", None)
        _awaited[thread], self._busy = self, True   # busy: an exception would leave it so
        try:
            if self._opening:
                self._opening = False
                self._reply(receive(self._from), *doing)
            doing = (what, time)
            send(self._write, request)
            kind, payload = receive(self._from)
        except (EOFError, OSError) as error:
            if isinstance(error, Garbled):
                self.kill(GARBLED)
            raise self._failure(*doing) from None
        finally:
            del _awaited[thread]
        self._busy = False
        return self._reply((kind, payload), what, time, size)

    def _reply(self, answer: tuple[bytes, bytes], what: str, time: float | None,
               size: int | None = None) -> bytes:
        kind, payload = answer
        if kind == b"R" and size in (None, len(payload)):
            return payload
        try:                            # a refusal; anything else: garbled
            call, status, records, memory = pickle.loads(payload if kind == b"E" else b"")
        except Exception:
            self.kill(GARBLED)
            raise self._failure(what, time) from None
        limit = f"its memory limit of {(self.memory_limit or 0) / 2**20:.0f} MiB"
        error = FmuCallError(self.name, call or what, time,
                             f"{status}, out of {limit}" if memory else status, records)
        error.cause = limit if memory else error.cause
        raise error

    def _failure(self, what: str, time: float | None) -> FmuCallError:
        try:
            status = self.process.wait(5.0)
        except subprocess.TimeoutExpired:
            self.kill("it closed its pipe but did not end")
            status = self.process.wait()
        self.discard()
        self._kill_group()                  # what it started, if anything
        cause = self.killed or (f"its process was ended by signal {signal.Signals(-status).name}"
                                if status < 0 else f"its process exited with status {status}")
        error = FmuCallError(self.name, what, time, f"no reply: {cause}", [])
        error.cause = cause
        return error

    def _remote(self, method: str, *args: Any, what: str | None = None,
                time: float | None = None) -> Any:
        return pickle.loads(self._ask(message(b"C", pickle.dumps((method, args))), what or method,
                                      time))

    def kill(self, reason: str) -> None:
        """End the child at once (from any thread); its caller gets ``reason`` as the cause."""
        self.killed = self.killed or reason
        self._kill_group()

    def _kill_group(self) -> None:
        """The child and what it started in its session (POSIX), or the child alone."""
        try:
            os.killpg(self.process.pid, signal.SIGKILL)
        except (AttributeError, OSError):   # Windows; or the group has ended
            self.process.kill()

    def discard(self) -> None:
        _live.pop(self.process.pid, None)
        for pipe in self._pipes:
            try:
                pipe.close()
            except OSError:                 # a write the dead child never read
                pass

    def set(self, values: dict[str, Any], time: float | None = None) -> None:
        self._remote("set", values, time, what="set", time=time)

    def get(self, names: Iterable[str]) -> dict[str, Any]:
        return self._remote("get", list(names))

    def enter_initialization(self, start_time: float = 0.0) -> None:
        self._remote("enter_initialization", start_time, what="enterInitializationMode")

    def exit_initialization(self, start_time: float = 0.0) -> None:
        self._remote("exit_initialization", start_time, what="exitInitializationMode",
                     time=start_time)

    def reset(self) -> None:
        self._remote("reset")

    def free(self) -> None:
        if self.process.poll() is None and _live.get(self.process.pid) is self:
            try:                        # after a call the master gave up on: no more calls
                self._remote("free", what="terminate and freeInstance") if not self._busy \
                    else self.kill("the master stopped waiting for its reply")
            except FmuCallError:
                self.kill("it failed to end")
            self.discard()
            try:                        # it has replied: it ends now unless a thread holds it
                self.process.wait(1.0)
            except subprocess.TimeoutExpired:
                self.process.kill()
                self.process.wait()
            self._kill_group()              # what it started and left running, if anything

    def reader(self, vrs: list[int], kind: str = "Real") -> Callable[[], list]:
        return lambda: self._remote("read", vrs, kind, what=f"get{kind}")

    def writer(self, vrs: list[int]) -> Callable[[list[float]], None]:
        return lambda values: self._remote("write", vrs, list(values), what="setReal")

    def stepper(self) -> Callable[[float, float], None]:
        return lambda t, h: self._remote("step", t, h, what="doStep", time=t)

    def couple(self, node, gauss_seidel: bool):
        """(start, exchange) as ``wiring.couple``'s: one message a step, its reply holding the
        outputs read once the inputs are set and those read after the step for the next."""
        first, then = node.phases(gauss_seidel)
        base, integers = node.state.start, node.integers

        def kinds(block: slice) -> list[tuple[list[int], str]]:   # its Reals, its Integers
            cut = min(max(block.start, integers.start), block.stop) - base
            return [(node.vrs[block.start - base:cut], "Real"),
                    (node.vrs[cut:block.stop - base], "Integer")]
        inputs, read = node.vrs[integers.stop - base:], kinds(first)
        self._remote("prepare", inputs, kinds(then), read)
        ask = struct.Struct(f"<cIdd?{len(inputs)}d")
        answer = struct.Struct(f"<{then.stop - then.start + first.stop - first.start}d")
        size = ask.size - HEADER.size
        n_then, ints, cached = then.stop - then.start, integers.start < integers.stop, [None]
        gather = gatherer(node)

        def read_first() -> list:
            return [v for vrs, kind in read if vrs for v in self._remote("read", vrs, kind)]

        def start(values: list) -> None:
            values[first] = cached[0] if cached[0] is not None else read_first()
            if ints and not gauss_seidel:
                values[integers] = map(int, values[integers])

        def exchange(values: list, t: float, h: float, step: bool) -> None:
            sent = gather(values)
            got = answer.unpack(self._ask(ask.pack(b"X", size, t, h, step, *sent),
                                          "doStep" if step else "setReal and get", t,
                                          answer.size))
            values[node.inputs], values[then], cached[0] = sent, got[:n_then], got[n_then:]
            if ints and gauss_seidel:
                values[integers] = map(int, values[integers])
        return start, exchange


def kill_all(reason: str) -> None:
    """End every child of this process at once (before it ends itself)."""
    for instance in list(_live.values()):
        instance.kill(reason)


def end_now(status: int) -> None:
    """End this process at once, its children first."""
    kill_all("the master ended")
    os._exit(status)


def kill_awaited(thread: int, reason: str) -> bool:
    """Kill the child whose reply ``thread`` awaits, if any: that thread gets the failure."""
    instance = _awaited.get(thread)
    if instance is not None:
        instance.kill(reason)
    return instance is not None


@contextmanager
def one_cpu(instances: Iterable[Instance]) -> Iterator[None]:
    """This thread and its FMUs' children on the CPU it runs on, for a run: a step's messages
    pass without waking another CPU (on Linux; elsewhere as they are)."""
    children = [i.process.pid for i in instances if isinstance(i, IsolatedInstance)]
    if not children or not hasattr(os, "sched_setaffinity"):
        yield
        return
    allowed = os.sched_getaffinity(0)
    with open("/proc/thread-self/stat") as stat:
        cpu = {int(stat.read().rsplit(")", 1)[1].split()[36])}
    for pid in (0, *children):
        try:
            os.sched_setaffinity(pid, cpu)
        except OSError:                      # a child that has ended: its call will say so
            pass
    try:
        yield
    finally:
        os.sched_setaffinity(0, allowed)


