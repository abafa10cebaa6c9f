"""Which report and figure a scenario gets, by the kind its .ssd names (``report``)."""
from __future__ import annotations

from typing import Callable, NamedTuple

from matplotlib.figure import Figure

from ..core.recording import Recording
from .figures import course_keeping_figure
from .plates import turning_circle_plate, zigzag_plate
from .reports import course_keeping_report, turning_circle_report, zigzag_report


class Analysis(NamedTuple):
    """What ``cosim.run`` prints (``report``) and draws (``figure``) for a kind of scenario."""
    report: Callable[..., list[str]]
    figure: Callable[[Recording], Figure] | None = None


ANALYSES = {
    "course_keeping": Analysis(course_keeping_report, course_keeping_figure),
    "turning_circle": Analysis(turning_circle_report, turning_circle_plate),
    "zigzag": Analysis(zigzag_report, zigzag_plate),
    "none": Analysis(lambda recording, **_: []),
}


def analysis(kind: str) -> Analysis:
    """The analysis of a kind; ValueError naming the known kinds."""
    if kind not in ANALYSES:
        raise ValueError(f"unknown report kind {kind!r}; known: {', '.join(ANALYSES)}")
    return ANALYSES[kind]
