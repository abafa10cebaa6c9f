"""Fault injection for the fault matrix: a rudder program whose outputs or model go wrong.

Until ``fault_time`` it commands a constant rudder and full ahead; from then on, by
``fault`` (an Integer, which every engine can set): 1 'nan' (the rudder command is
NaN), 2 'range' (the propeller command n1 is 100 rev/s, outside the ship's +-50),
3 'raise' (its own step raises: an exception inside a model), 4 'sigint' and
5 'sigterm' (its step sends that signal to its own process, once: Ctrl-C or a
kill arriving while FMU code runs), 6 'loop' (its step never returns, looping in
Python), 7 'block' (its step never returns, waiting in C: a sleep that no Python
exception interrupts), 8 'segv' (a segmentation fault), 9 'exit' (``os._exit(3)``),
10 'abort' (C's ``abort()``), 11 'memory' (64 MiB more held at each step), 12 'spawn' (a
``sleep`` process started, then a segmentation fault), 13 'garble' (bytes written to every
descriptor from 3 to 29, as a careless FMU might), 0 'none'. Where
the environment names a file in ``FAULT_HANG_MARKER``, a step that is about to hang writes
its process id there first, so that a test can wait for the hang itself instead of for a
time.
"""
import ctypes
import os
import signal
import subprocess
import time

from fmukit.slave import ModelSlave, Var

KINDS = ("none", "nan", "range", "raise", "sigint", "sigterm", "loop", "block", "segv", "exit",
         "abort", "memory", "spawn", "garble")


class Fault:
    def __init__(self, fault_time: float, fault: int):
        self.fault_time, self.fault_kind, self.t = fault_time, KINDS[fault], 0.0
        self.signalled, self.held = False, []

    def faulty(self, kind: str) -> bool:
        return self.fault_kind == kind and self.t >= self.fault_time

    def delta_c(self) -> float:
        return float("nan") if self.faulty("nan") else 0.1

    def n1(self) -> float:
        return 100.0 if self.faulty("range") else 8.13

    def step(self, t: float, h: float) -> None:
        if self.fault_kind == "raise" and t >= self.fault_time:
            raise RuntimeError(f"injected fault at t = {t}")
        if self.fault_kind.startswith("sig") and t >= self.fault_time and not self.signalled:
            self.signalled = True
            os.kill(os.getpid(), getattr(signal, self.fault_kind.upper()))
        if t >= self.fault_time and self.fault_kind not in ("none", "nan", "range", "raise"):
            marker = os.environ.get("FAULT_HANG_MARKER")
            if marker:
                with open(marker, "w") as f:
                    f.write(str(os.getpid()))
        if self.fault_kind == "garble" and t >= self.fault_time:
            for fd in range(3, 30):
                try:
                    os.write(fd, b"garbage")
                except OSError:
                    pass
        if self.fault_kind == "spawn" and t >= self.fault_time:
            subprocess.Popen(["sleep", "1000"])
        if self.fault_kind in ("segv", "spawn") and t >= self.fault_time:
            ctypes.string_at(0)
        if self.fault_kind == "exit" and t >= self.fault_time:
            os._exit(3)
        if self.fault_kind == "abort" and t >= self.fault_time:
            os.abort()
        if self.fault_kind == "memory" and t >= self.fault_time:
            self.held.append(bytearray(64 * 2**20))
        if self.fault_kind == "loop" and t >= self.fault_time:
            while True:
                pass
        if self.fault_kind == "block" and t >= self.fault_time:
            time.sleep(10**6)
        self.t = t + h

    def snapshot(self) -> dict:
        return {"t": self.t}

    def restore(self, snapshot: dict) -> None:
        self.t = float(snapshot["t"])


class FaultSlave(ModelSlave):
    model_name = "fault"
    description = "Test FMU: a rudder program that goes wrong at fault_time, as fault_kind says"
    variables = (
        Var.input("psi", 0.0, "rad", "heading (unused)"),
        Var.output("delta_c", "rad", "commanded rudder angle", get=lambda s: s.model.delta_c()),
        Var.output("n1", "rev/s", "propeller command", get=lambda s: s.model.n1()),
        Var.parameter("fault_time", 50.0, "s", "time of the fault"),
        Var.parameter("fault", 3, description="0 none, 1 nan, 2 range, 3 raise, 4 sigint, "
                      "5 sigterm, 6 loop, 7 block, 8 segv, 9 exit, 10 abort, 11 memory, "
                      "12 spawn, 13 garble", min=0, max=13),
    )

    def build_model(self) -> Fault:
        return Fault(self.fault_time, self.fault)

    def step_model(self, t: float, h: float) -> None:
        self.model.step(t, h)
