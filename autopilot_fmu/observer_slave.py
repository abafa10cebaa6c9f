"""The heading observer as a co-simulation FMU (fmus/observer.fmu), between the compass and
the autopilot: psi_hat and r_hat, the wave-filtered estimates (autopilot_fmu.observer), are
states, so no algebraic loop closes through it."""
from autopilot_fmu.observer import HeadingObserver
from fmukit.slave import ModelSlave, Var

_O = HeadingObserver()
_START = ("psi_m",)         # the estimates start at the first reading


class ObserverSlave(ModelSlave):
    model_name = "observer"
    description = ("Heading observer with wave filtering: Fossen's passive observer on the "
                   "compass, a first-order yaw model and a bias (Fossen 2011, sec. 11.4)")
    variables = (
        Var.input("psi_m", 0.0, "rad", "measured heading (a compass, e.g. sensors.psi_m)"),
        Var.input("delta", 0.0, "rad", "rudder angle (ship.delta)", -3.2, 3.2),
        Var.output("psi_hat", "rad", "low-frequency heading estimate", initial_depends=_START,
                   get=lambda s: s.model.psi_hat),
        Var.output("r_hat", "rad/s", "low-frequency yaw rate estimate", initial_depends=_START,
                   get=lambda s: s.model.r_hat),
        Var.output("psi_wf_hat", "rad", "wave-frequency heading estimate",
                   get=lambda s: s.model.x[1]),
        Var.parameter("omega_0", _O.omega_0, "rad/s", "wave filter peak (2 pi / T0 of the "
                      "sea), > 0", 0.0, 1e3),
        Var.parameter("lambda_w", _O.lam, "1", "wave filter damping, < zeta_n", 0.0, 1.0),
        Var.parameter("zeta_n", _O.zeta_n, "1", "notch damping", 0.0, 10.0),
        Var.parameter("omega_c", _O.omega_c, "rad/s", "cut-off, > omega_0", 0.0, 1e3),
        Var.parameter("omega_lf", _O.omega_lf, "rad/s", "bandwidth of psi_hat and r_hat",
                      0.0, 1e3),
        Var.parameter("T_yaw", _O.T, "s", "yaw model's time constant, != 0", -1e4, 1e4),
        Var.parameter("K_yaw", _O.K, "1/s", "yaw model's gain (rad/s per rad of rudder)",
                      -1e4, 1e4),
    )

    def build_model(self) -> HeadingObserver:
        return HeadingObserver(self.omega_0, self.lambda_w, self.zeta_n, self.omega_c,
                               self.omega_lf, self.T_yaw, self.K_yaw)

    def start_model(self, model: HeadingObserver) -> None:
        model.start(self.psi_m)

    def step_model(self, t: float, h: float) -> None:
        self.model.step(h, self.psi_m, self.delta)
