"""The CyberShip II vessel (Tomera 2010, eqs 1-17): plain modules (``vessel`` integrates
``hull``, ``thrusters``, ``steering_gear`` and ``waves`` on the data of ``data``), the rudder
program of standard manoeuvres (``manoeuvres``; the ship alone under it: ``trial``), and
the FMU classes that wrap them thinly (``ship_slave``, ``manoeuvre_slave``)."""
