"""The paper's autopilots and guidance (eqs 18-46) and the FMU classes wrapping them
(``*_slave``); the PID in one file, as your own would be (``pid_autopilot_slave``)."""
