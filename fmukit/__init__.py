"""The runtime an FMU built with fmukit carries, importing nothing of this project: every
FMU's base ``slave.ModelSlave`` and the only modules that import pythonfmu, the adapters
``pythonfmu07`` (FMI 2.0) and ``pythonfmu3_03`` (FMI 3.0), with what fmukit owes to their
defects. ``build`` only names the host's build command (``fmubuild``), which no FMU carries.
"""
