"""The CyberShip II vessel (Tomera 2010, eqs 1-17), its manoeuvres' rudder program, their FMUs."""
