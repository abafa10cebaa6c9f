"""The ship as a reinforcement-learning environment (docs/rl.md): ``ShipEnv`` (one ship, the
real FMUs) and ``ShipVectorEnv`` (M ships on the batch kernel), registered with Gymnasium as
``cosim/ShipAutopilot-v0``."""
import gymnasium

ENV_ID = "cosim/ShipAutopilot-v0"

if ENV_ID not in gymnasium.registry:
    gymnasium.register(ENV_ID, entry_point="cosim.rl.env:ShipEnv",
                       vector_entry_point="cosim.rl.vector:ShipVectorEnv")
