"""An autopilot that keeps the rudder amidships: it has the ports, and does not steer."""
from fmukit.autopilot import INPUTS, rudder_command
from fmukit.slave import ModelSlave


class Idle:
    def snapshot(self) -> dict:
        return {}

    def restore(self, snapshot: dict) -> None:
        pass


class IdlePilotSlave(ModelSlave):
    model_name = "idle_pilot"
    description = "holds the rudder amidships"
    variables = (*INPUTS, rudder_command(depends=(), get=lambda slave: 0.0))

    def build_model(self) -> Idle:
        return Idle()

    def step_model(self, t: float, h: float) -> None:
        pass
