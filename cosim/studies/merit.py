"""A course-keeping run's figures of merit (``METRICS``, ``run_metrics``), its track, and the
criteria a scorecard compares controllers by (``CRITERIA``)."""
from __future__ import annotations

import math
from dataclasses import dataclass

from autopilot_fmu.guidance import R_ACCEPT, route as followed_route

from ..analysis.metrics import (cost, course_settling, cross_track_error, fraction_at_stops,
                                heading_error, mean_abs_rate, peak, rms, route_completion,
                                rudder_reversals_per_minute)

# A run's figures of merit and their units, as cosim.run prints them (NaN in a failed run's row)
METRICS = {"psi_E": "rad^2", "sum_delta2": "rad^2", "J": "rad^2", "rms_heading_error_deg": "deg",
           "course_settling_s": "s",
           "reversals_per_min": "1/min", "max_delta_deg": "deg", "mean_rudder_rate_deg_s": "deg/s",
           "at_stops_pct": "%", "cross_track_rms_m": "m", "cross_track_max_m": "m",
           "waypoints_reached": "", "waypoints": "", "last_waypoint_reached": "",
           "waypoint_margin_m": "m"}


@dataclass(frozen=True)
class Merit:
    """A column of ``METRICS`` as a criterion to compare controllers by."""
    column: str
    label: str
    lower_is_better: bool = True
    paired: str = "ratio"           # how a run is set beside another's: ratio or difference
    digits: int = 1                 # decimals shown
    out_of: str | None = None       # the column it is a count out of, if any

    @property
    def unit(self) -> str:
        return METRICS[self.column]

    @property
    def better(self) -> str:
        return "lower is better" if self.lower_is_better else "higher is better"

    def format(self, value: float, sign: str = "") -> str:
        """``value`` to this criterion's decimals ('-' if not finite); ``sign="+"`` signs it."""
        if not math.isfinite(value):
            return "-"
        return f"{value:{sign}g}" if self.digits == 0 else f"{value:{sign}.{self.digits}f}"


CRITERIA = (                        # what a scorecard compares controllers by
    Merit("J", "J of eq (19)"),
    Merit("rms_heading_error_deg", "RMS heading error psi_d - psi", paired="difference",
          digits=2),
    Merit("course_settling_s", "heading settling after a course change (to 5 %)"),
    Merit("reversals_per_min", "rudder reversals"),
    Merit("mean_rudder_rate_deg_s", "mean abs rudder rate", digits=2),
    Merit("at_stops_pct", "time on the rudder stops", paired="difference"),
    Merit("cross_track_rms_m", "RMS cross-track error", paired="difference", digits=2),
    Merit("cross_track_max_m", "max cross-track error", paired="difference", digits=2),
    Merit("waypoints_reached", "waypoints reached", lower_is_better=False,
          paired="difference", digits=0, out_of="waypoints"),
    Merit("waypoint_margin_m", "worst waypoint's margin (R_accept - closest approach; < 0: "
          "missed by)", lower_is_better=False, paired="difference", digits=2),
)


def route_of(recording) -> tuple[list[tuple[float, float]], float]:
    """The route the run's guidance followed and its radius of acceptance (m)."""
    guidance = recording.meta.get("parameters", {}).get("guidance", {})
    return followed_route(guidance), float(guidance.get("R_accept", R_ACCEPT))


def track(recording) -> dict:
    """The run's track every 1 s, its route and radius of acceptance (the tracks figure)."""
    stride = max(1, round(1.0 / recording.meta["step_size"]))
    points, R_accept = route_of(recording)
    return {"x": recording["ship.x"][::stride].tolist(),
            "y": recording["ship.y"][::stride].tolist(),
            "route": [list(point) for point in points], "R_accept": R_accept}


def run_metrics(recording) -> dict[str, float]:
    """Every figure of ``METRICS`` (eq (19), psi_d - psi, the rudder ship.delta, the route)."""
    c = cost(recording)
    t, delta, x, y = recording.t, recording["ship.delta"], recording["ship.x"], recording["ship.y"]
    points, R_accept = route_of(recording)
    stops = recording.meta.get("parameters", {}).get("ship", {}).get("delta_max", math.inf)
    off_track = cross_track_error(x, y, recording["guidance.wp_index"], points)
    completion = route_completion(x, y, points, R_accept)
    return {"psi_E": c.psi_E, "sum_delta2": c.sum_delta2, "J": c.J,
            "rms_heading_error_deg": math.degrees(rms(heading_error(
                recording["guidance.psi_d"], recording["ship.psi"]))),
            "course_settling_s": course_settling(t, recording["guidance.psi_d"],
                                                 recording["ship.psi"],
                                                 recording["guidance.wp_index"]),
            "reversals_per_min": rudder_reversals_per_minute(t, delta),
            "max_delta_deg": math.degrees(peak(delta)),
            "mean_rudder_rate_deg_s": math.degrees(mean_abs_rate(t, delta)),
            "at_stops_pct": 100.0 * fraction_at_stops(delta, stops),
            "cross_track_rms_m": rms(off_track), "cross_track_max_m": peak(off_track),
            "waypoints_reached": float(completion.count), "waypoints": float(len(points)),
            "last_waypoint_reached": float(completion.last_reached),
            "waypoint_margin_m": R_accept - max(completion.closest)}
