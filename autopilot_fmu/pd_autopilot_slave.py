"""The PD autopilot as an FMI 2.0 co-simulation FMU (fmus/pd_autopilot.fmu); delta_c is
direct feedthrough from psi, r and psi_d."""
from autopilot_fmu.pd import PDAutopilot
from fmukit.autopilot import INPUTS, rudder_command
from fmukit.slave import ModelSlave, Var

_P = PDAutopilot()


class PDAutopilotSlave(ModelSlave):
    model_name = "pd_autopilot"
    description = "PD heading autopilot, delta_c = Kp (psi - psi_d) + Kd r (Tomera 2010, eq 20)"
    variables = (
        *INPUTS,
        rudder_command(depends=("psi", "r", "psi_d", "Kp", "Kd"),
                       get=lambda s: s.model.command(s.psi, s.r, s.psi_d)),
        Var.parameter("Kp", _P.Kp, "1", "heading error gain, rad of rudder per rad", -1e4, 1e4),
        Var.parameter("Kd", _P.Kd, "s", "yaw rate gain, rad of rudder per rad/s", -1e4, 1e4),
    )

    def build_model(self) -> PDAutopilot:
        return PDAutopilot(self.Kp, self.Kd)

    def step_model(self, t: float, h: float) -> None:
        pass                               # memoryless (do_step has checked the inputs)
