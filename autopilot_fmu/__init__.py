"""The paper's autopilots and guidance: ``pd`` (eq 20), ``design`` (eqs 22-34, 45-46),
``smc`` (eqs 35-44), ``guidance`` (eq 18), and the FMU classes wrapping them (``*_slave``);
the PID in one file, as your own would be (``pid_autopilot_slave``)."""
