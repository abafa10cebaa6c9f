"""The runtime an FMU built with fmukit carries (it imports nothing of this project).

``slave.ModelSlave`` is every FMU's base, the same for FMI 2.0 and 3.0; the adapters
``pythonfmu07`` (FMI 2.0) and ``pythonfmu3_03`` (FMI 3.0) are the only modules that
import their pythonfmu, with what fmukit owes to its defects. ``build`` only names the
host's build command (``fmubuild``), which no FMU carries.
"""
