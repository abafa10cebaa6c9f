"""The paper's autopilots and guidance: plain modules, and the FMU classes that wrap them.

- ``pd``: the PD law, eq (20); ``design``: the sway-yaw and Nomoto design models,
  eqs (22)-(34), (45)-(46); ``smc``: the sliding-mode design and law, eqs (35)-(44);
  ``guidance``: waypoints and the desired course, eq (18);
- FMUs: ``pd_autopilot_slave``, ``smc_autopilot_slave``, ``guidance_slave``; the PID in
  one file, as your own would be (``pid_autopilot_slave``); the PD in C
  (``pd_autopilot_c``, not a Python module).
"""
