"""The sliding-mode autopilot as an FMI 2.0 co-simulation FMU (fmus/smc_autopilot.fmu): the
reference model (44), its state, starts at the heading and yaw rate seen at initialisation."""
from autopilot_fmu.design import design_model
from autopilot_fmu.smc import SlidingModeAutopilot, SlidingModeDesign
from fmukit.autopilot import INPUTS, rudder_command
from fmukit.numerics import require_finite
from fmukit.slave import ModelSlave, Var

_DESIGN = ("lambda1", "lambda2", "u0", "design_model")
_LAW = _DESIGN + ("eta_h", "phi_h", "omega_n", "zeta", "equivalent_control")


class SMCAutopilotSlave(ModelSlave):
    model_name = "smc_autopilot"
    description = ("Sliding-mode heading autopilot with reference model "
                   "(Tomera 2010, eqs 33-44), design computed from the linear model")
    variables = (
        *INPUTS,
        rudder_command(depends=("psi", "r", "psi_d") + _LAW,
                       get=lambda s: s.model.command(s.psi, s.r, s.psi_d),
                       description="commanded rudder angle, eq (43)"),
        Var.output("psi_z", "rad", "reference heading, eq (44)", initial_depends=("psi",)),
        Var.output("r_z", "rad/s", "reference yaw rate, eq (44)", initial_depends=("r",)),
        Var.output("sigma", "1", "sliding surface, eq (37)", depends=("psi", "r") + _DESIGN,
                   get=lambda s: s.model.sigma(s.psi, s.r)),
        Var.parameter("lambda1", -0.0005, "1/s", "closed-loop eigenvalue of smaller magnitude, "
                      "< 0", -1e3, 0.0),
        Var.parameter("lambda2", -7.8128, "1/s", "closed-loop eigenvalue of larger magnitude, "
                      "< 0", -1e3, 0.0),
        Var.parameter("eta_h", 10.0, "rad", "switching gain", 0.0, 1e3),
        Var.parameter("phi_h", 0.3, "rad", "boundary layer thickness, > 0", 0.0, 1e3),
        Var.parameter("omega_n", 0.1, "rad/s", "reference model natural frequency, > 0",
                      0.0, 10.0),
        Var.parameter("zeta", 0.85, "1", "reference model relative damping, > 0", 0.0, 10.0),
        Var.parameter("u0", 0.3, "m/s", "design surge speed (design_model 'ship'), > 0",
                      0.0, 5.0),
        Var.parameter("design_model", "paper", description=(
            "linear design model: 'paper' = eq (45) as printed, 'ship' = this ship "
            "model linearised at u0")),
        Var.parameter("equivalent_control", "paper", description=(
            "'paper' = eq (39), u_eq = N psi_z - K^T x; 'tracking' = -K^T (x - x_z), "
            "not the paper's law (see docs/reproduction.md)")),
    )

    def build_model(self) -> SlidingModeAutopilot:
        design = SlidingModeDesign.from_model(design_model(self.design_model, self.u0),
                                              self.lambda1, self.lambda2)
        return SlidingModeAutopilot(design, self.eta_h, self.phi_h, self.omega_n, self.zeta,
                                    equivalent_control=self.equivalent_control)

    def start_model(self, model: SlidingModeAutopilot) -> None:
        require_finite(psi=self.psi, r=self.r)
        model.psi_z, model.r_z = self.psi, self.r

    def step_model(self, t: float, h: float) -> None:
        self.model.step(t, h, self.psi_d)
