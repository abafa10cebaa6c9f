"""A rudder program that fails on purpose, to test how masters handle a failing FMU."""
from fmukit.slave import ModelSlave, Var


class Fault:
    """Commands a constant rudder until fault_time, then fails every step."""

    def __init__(self, fault_time: float, fault_kind: str):
        if fault_kind not in ("discard", "raise"):
            raise ValueError(f"parameter fault_kind must be 'discard' or 'raise', "
                             f"got {fault_kind!r}")
        self.fault_time, self.fault_kind = fault_time, fault_kind

    def step(self, t: float, h: float) -> None:
        if t >= self.fault_time:
            if self.fault_kind == "raise":          # an exception: fmi2Fatal
                raise RuntimeError(f"injected fault at t = {t}")
            raise ValueError(f"injected fault at t = {t}")     # refused step: fmi2Discard

    def snapshot(self) -> dict:
        return {}

    def restore(self, snapshot: dict) -> None:
        pass


class FaultSlave(ModelSlave):
    model_name = "fault"
    description = "Test FMU: a constant rudder command that fails from fault_time on"
    variables = (
        Var.input("psi", 0.0, "rad", "heading (unused)"),
        Var.output("delta_c", "rad", "commanded rudder angle", get=lambda s: 0.1),
        Var.parameter("fault_time", 50.0, "s", "time from which every step fails"),
        Var.parameter("fault_kind", "discard", description="'discard' or 'raise'"),
    )

    def build_model(self) -> Fault:
        return Fault(self.fault_time, self.fault_kind)

    def step_model(self, t: float, h: float) -> None:
        self.model.step(t, h)
