"""WMO sea state codes at the 1:70 model's scale (Froude: heights / 70, periods / sqrt(70));
the choice of Hs and T0 per code is in docs/sweeps.md."""
from __future__ import annotations

import math

from ship_fmu.data import SCALE

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
    _, hs, t0 = WMO[code]               # code 0, calm water: its period only has to be valid
    return hs / SCALE, (t0 if t0 > 0.0 else 8.0) / math.sqrt(SCALE)
