"""Analysis of recorded runs: figures of merit, the cost of eq (19), reports, figures, sea states.

- ``metrics``: heading error, eq (19) terms, settling, overshoot, rudder reversals (arrays in);
- ``cost``: eq (19) over a recording, with the calibrated weight lambda;
- ``reports``: the printed report of each kind of scenario, and Tables 1-2 beside the paper's;
- ``figures``: the figure of each kind of scenario;
- ``kinds``: which report and figure a scenario gets, by the kind its .ssd names;
- ``seastate``: WMO sea state codes at the model's scale.

Built on ``cosim.core`` (a ``Recording``); used by the commands and the studies.
"""
