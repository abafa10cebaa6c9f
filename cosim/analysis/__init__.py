"""Analysis of recorded runs: figures of merit, the cost of eq (19), reports, figures, sea states.

- ``metrics``: heading error, eq (19) terms, settling, overshoot, rudder reversals (arrays in);
- ``cost``: eq (19) over a recording, with the calibrated weight lambda;
- ``manoeuvres``: the IMO figures of a turning circle and a zig-zag, from their trajectory,
  and the MSC.137(76) criteria they are judged by;
- ``reports``: the printed report of each kind of scenario, and Tables 1-2 beside the paper's;
- ``figures``: the course-keeping and comparison figures; ``plates``: the manoeuvres'
  IMO-style plates; ``animation``: a run as a moving picture;
- ``describe``: titles and headers in words, from the parameter values a run used;
- ``kinds``: which report and figure a scenario gets, by the kind its .ssd names;
- ``seastate``: WMO sea state codes at the model's scale.

Built on ``cosim.core`` (a ``Recording``) and the model packages (``ship_fmu``,
``autopilot_fmu``); used by the commands and the studies.
"""
