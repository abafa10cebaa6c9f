"""The CyberShip II vessel (Tomera 2010, eqs 1-17), its rudder program of standard
manoeuvres, and the FMU classes wrapping them thinly (``*_slave``)."""
