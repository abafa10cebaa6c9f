"""The CyberShip II vessel: plain modules, and the FMU classes that wrap them thinly.

- ``data``: hull, propeller and rudder data; ``hull``: rigid-body and hydrodynamic
  terms, eqs (1)-(6); ``thrusters``: propellers, bow thruster and rudders, eqs (8)-(13);
  ``steering_gear``: the rate-limited rudder; ``waves``: the sea and its loads,
  eqs (14)-(17); ``vessel``: all of it integrated by RK4 (``Vessel``);
- ``manoeuvres``: the rudder program of a turning circle or zig-zag; ``trial``: the
  ship run alone under it;
- FMUs: ``ship_slave`` (the vessel), ``manoeuvre_slave`` (the rudder program).
"""
