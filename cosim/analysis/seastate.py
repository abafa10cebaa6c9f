"""WMO sea state codes at the model's scale (Froude scaling, CyberShip II is 1:70).

Full-scale significant wave height: the middle of the WMO code's range. Modal
period: the most probable modal period of the open North Atlantic for that code
(Lee and Bales, 1980, as tabulated in STANAG 4194 and by Price and Bishop). Codes
0 and 1 have none there; code 1 takes code 2's. A shorter period would not be
more realistic here: the loads of eqs (14)-(16) grow with the wave slope,
A k = A omega^2 / g, and the block model behind them holds only for waves longer
than the hull, so a rippled sea with a 2 s period came out rougher than code 2.

Froude scaling with the length ratio lambda = 70: heights scale with lambda,
periods with sqrt(lambda):

    Hs_model = Hs_full / 70,    T0_model = T0_full / sqrt(70).

| code | description | Hs full (m) | T0 full (s) | Hs model (mm) | T0 model (s) |
|---|---|---|---|---|---|
| 0 | calm (glassy) | 0 | - | 0 | - |
| 1 | calm (rippled) | 0.05 | 7.5 (code 2's) | 0.71 | 0.90 |
| 2 | smooth | 0.3 | 7.5 | 4.3 | 0.90 |
| 3 | slight | 0.875 | 7.5 | 12.5 | 0.90 |
| 4 | moderate | 1.875 | 8.8 | 26.8 | 1.05 |
| 5 | rough | 3.25 | 9.7 | 46.4 | 1.16 |
| 6 | very rough | 5.0 | 12.4 | 71.4 | 1.48 |

The paper's waves (Hs = 5 mm, T0 = 0.8 s at model scale, 0.35 m and 6.7 s full
scale) are code 2; its "3 m, sea state 5" would be code 5 here.
"""
from __future__ import annotations

import math

SCALE = 70.0
"""Length ratio of CyberShip II to the supply ship it models."""

# code: (description, Hs full scale m, modal period full scale s)
WMO = {
    0: ("calm (glassy)", 0.0, 0.0),
    1: ("calm (rippled)", 0.05, 7.5),
    2: ("smooth", 0.3, 7.5),
    3: ("slight", 0.875, 7.5),
    4: ("moderate", 1.875, 8.8),
    5: ("rough", 3.25, 9.7),
    6: ("very rough", 5.0, 12.4),
}


def model_scale(code: int) -> tuple[float, float]:
    """(Hs, T0) at model scale for a WMO sea state code 0-6, in m and s."""
    if code not in WMO:
        raise ValueError(f"sea_state must be a WMO code 0-6, got {code!r}")
    _, hs, t0 = WMO[code]
    # Code 0 is calm water (Hs = 0); its period only has to be valid.
    return hs / SCALE, (t0 if t0 > 0.0 else 8.0) / math.sqrt(SCALE)
