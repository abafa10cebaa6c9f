"""The paper's autopilots and guidance (eqs 18-46), their FMUs, and the PID in one file."""
