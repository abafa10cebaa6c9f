"""The runtime an FMU built with fmukit carries: it imports nothing of this project.

- ``slave``: ``ModelSlave``, the base of every FMU's class, composed of:
  ``variables`` (declared variables and their ranges), ``registry`` (registered by
  value reference), ``sequence`` (the FMI 2.0 call sequence), ``fastpath`` (get and
  set planned once per list of references), ``state`` (saved states),
  ``model_description`` and ``units`` (a complete modelDescription.xml) and
  ``refusals`` (how a call is refused);
- ``autopilot``: the autopilot port contract; ``timebase`` and ``numerics``: the time
  base and numerical rules the models share;
- ``pythonfmu07``: pythonfmu, and what is owed to version 0.7.0's defects;
- ``build``: only the name of the build command, ``python -m fmukit.build``
  (``fmubuild``); no FMU carries it.
"""
