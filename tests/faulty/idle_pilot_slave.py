"""An autopilot that keeps the rudder amidships: it has the ports, and does not steer.

With ``fail_time`` set it fails every step from then on (an exception: fmi2Fatal, or
fmi3Error as an FMI 3.0 twin); with ``hang_time`` its step at that time never returns (a
loop in Python); with ``crash_time``, its step at that time dereferences a null pointer (a
segmentation fault); with ``linger_time``, its step at that time starts a thread that is
not a daemon and sleeps on; with ``hang_terminate`` = 1, Terminate never returns. Built as either FMI
version from this one script.
"""
import ctypes
import threading
import time

from fmukit.autopilot import INPUTS, rudder_command
from fmukit.slave import ModelSlave, Var


class Idle:
    def snapshot(self) -> dict:
        return {}

    def restore(self, snapshot: dict) -> None:
        pass


class IdlePilotSlave(ModelSlave):
    model_name = "idle_pilot"
    description = "holds the rudder amidships"
    variables = (*INPUTS, rudder_command(depends=(), get=lambda slave: 0.0),
                 Var.parameter("fail_time", 1e9, "s", "fail every step from then on"),
                 Var.parameter("hang_time", 1e9, "s", "loop for ever in the step at this time"),
                 Var.parameter("crash_time", 1e9, "s", "a segmentation fault at this time"),
                 Var.parameter("linger_time", 1e9, "s", "a lasting thread started at this time"),
                 Var.parameter("hang_terminate", 0, description="1: loop for ever in "
                               "Terminate", min=0, max=1))

    lingering = None

    def build_model(self) -> Idle:
        return Idle()

    def step_model(self, t: float, h: float) -> None:
        if t >= self.fail_time:
            raise RuntimeError(f"injected failure at t = {t}")
        while t >= self.hang_time:
            pass
        if t >= self.crash_time:
            ctypes.string_at(0)
        if t >= self.linger_time and not self.lingering:
            self.lingering = threading.Thread(target=time.sleep, args=(10**6,), name="lingerer")
            self.lingering.start()

    def terminate(self) -> None:
        while self.hang_terminate:
            pass
        super().terminate()
