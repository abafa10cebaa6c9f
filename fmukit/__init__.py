"""The runtime an FMU built with fmukit carries: it imports nothing of this project.

- ``slave``: ``ModelSlave``, the base of every FMU's class, the same for FMI 2.0 and
  FMI 3.0, composed of: ``variables`` (declared variables and their ranges),
  ``registry`` (registered by value reference), ``sequence`` (the call sequence),
  ``fastpath`` (get and set planned once per list of references), ``state`` (saved
  states), ``units`` (the units' definitions), ``refusals`` (how a call is refused),
  ``entry`` (every FMI entry point, safe against pythonfmu's error path) and
  ``hostsignals`` (the host's Ctrl-C, handled in the host's code);
- the adapters, one per FMI version and the pythonfmu that builds it, each the only
  place that imports its pythonfmu, with what is owed to that version's defects:
  ``pythonfmu07`` (FMI 2.0, pythonfmu 0.7.0) and ``pythonfmu3_03`` (FMI 3.0,
  pythonfmu3 0.3.4); ``compose``: a model's FMU class of either version, for a host
  that runs it in its own process;
- ``autopilot``: the autopilot port contract; ``timebase`` and ``numerics``: the time
  base and numerical rules the models share;
- ``build``: only the name of the build command, ``python -m fmukit.build``
  (``fmubuild``); no FMU carries it.
"""
