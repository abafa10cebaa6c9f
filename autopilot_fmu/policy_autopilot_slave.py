"""The learned autopilot (autopilot_fmu.policy) as a co-simulation FMU, policy_autopilot: its
weights, the String parameter ``policy``, default to policy_autopilot.json beside this file,
in the FMU's resources. cosim.train builds each policy it trains from this file, its model
named anew, so that FMUs of other weights share no module in one host; delta_c is direct
feedthrough from psi, r and psi_d."""
from pathlib import Path

from autopilot_fmu.policy import Policy
from fmukit.autopilot import INPUTS, rudder_command
from fmukit.slave import ModelSlave, Var

WEIGHTS = Path(__file__).with_name("policy_autopilot.json").read_text().strip()


class PolicyAutopilotSlave(ModelSlave):
    model_name = "policy_autopilot"
    description = "learned heading autopilot: delta_c = f(psi - psi_d, r), a network (cosim.train)"
    variables = (
        *INPUTS,
        rudder_command(depends=("psi", "r", "psi_d", "policy"),
                       get=lambda s: s.model.command(s.psi, s.r, s.psi_d)),
        Var.parameter("policy", WEIGHTS, description="the network: JSON of cosim.train"),
    )

    def build_model(self) -> Policy:
        return Policy.from_json(self.policy)

    def step_model(self, t: float, h: float) -> None:
        pass                               # memoryless (do_step has checked the inputs)
