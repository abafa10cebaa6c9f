"""Which report and figure a scenario gets, by the kind its .ssd names (``report``)."""
from __future__ import annotations

from importlib import import_module
from typing import TYPE_CHECKING, Callable, NamedTuple

from ..core.recording import Recording
from .reports import course_keeping_report, turning_circle_report, zigzag_report

if TYPE_CHECKING:
    from matplotlib.figure import Figure


class Analysis(NamedTuple):
    """What ``cosim.run`` prints (``report``) and draws (``figure``) for a kind of scenario."""
    report: Callable[..., list[str]]
    drawn_by: str | None = None      # "module.function" here, imported only to draw

    @property
    def figure(self) -> Callable[[Recording], Figure] | None:
        """The function that draws the figure (a run that draws none loads no matplotlib)."""
        if self.drawn_by is None:
            return None
        module, name = self.drawn_by.split(".")
        return getattr(import_module(f"{__package__}.{module}"), name)


ANALYSES = {
    "course_keeping": Analysis(course_keeping_report, "figures.course_keeping_figure"),
    "turning_circle": Analysis(turning_circle_report, "plates.turning_circle_plate"),
    "zigzag": Analysis(zigzag_report, "plates.zigzag_plate"),
    "none": Analysis(lambda recording, **_: []),
}


def analysis(kind: str) -> Analysis:
    """The analysis of a kind; ValueError naming the known kinds."""
    if kind not in ANALYSES:
        raise ValueError(f"unknown report kind {kind!r}; known: {', '.join(ANALYSES)}")
    return ANALYSES[kind]
