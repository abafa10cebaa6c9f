"""model.png, an FMU's icon drawn from its model description: a vessel (outputs x, y, psi) as
CyberShip II's waterline to scale, any other model as a block with its ports; 256 x 256,
matplotlib's default style, no software or time in the file.
"""
from __future__ import annotations

import io
from xml.etree.ElementTree import fromstring

import matplotlib.style
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure
from matplotlib.patches import FancyBboxPatch, Polygon

from ship_fmu.data import Hull

SIZE, DPI = 256, 100
VESSEL = {"x", "y", "psi"}
"""Outputs that make a model a vessel."""
_FONT = "DejaVu Sans"               # matplotlib's own


def model_png(xml: bytes) -> bytes:
    """The icon of the model described by ``xml`` (FMI 2.0 or 3.0) as PNG bytes."""
    root = fromstring(xml)
    ports = {c: [v.get("name") for v in root.find("ModelVariables")
                 if v.get("causality") == c] for c in ("input", "output")}
    name = root.get("modelName", "")
    with matplotlib.style.context("default"):
        figure = Figure(figsize=(SIZE / DPI, SIZE / DPI), dpi=DPI)
        FigureCanvasAgg(figure)
        ax = figure.add_axes((0, 0, 1, 1), xlim=(0, 1), ylim=(0, 1))
        ax.set_axis_off()
        if VESSEL <= set(ports["output"]):
            _hull(ax, name)
        else:
            _block(ax, name, ports["input"], ports["output"])
        png = io.BytesIO()
        figure.savefig(png, format="png", dpi=DPI, transparent=True,
                       metadata={"Software": None})
    return png.getvalue()


def _hull(ax, name: str) -> None:
    """The waterline, bow up, 0.78 of the icon long, and the name below it."""
    scale = 0.78 / Hull.L
    length, beam = Hull.L * scale, Hull.B * scale
    bottom, middle = 0.16, 0.5
    ax.add_patch(Polygon([(middle, bottom + length), (middle + beam / 2, bottom + 0.75 * length),
                          (middle + beam / 2, bottom), (middle - beam / 2, bottom),
                          (middle - beam / 2, bottom + 0.75 * length)], closed=True,
                         facecolor="0.75", edgecolor="black", linewidth=2))
    for side in (-1, 1):                # the two rudders behind the stern
        ax.plot([middle + side * beam / 4] * 2, [bottom, bottom - 0.05], color="black",
                linewidth=3, solid_capstyle="butt")
    ax.text(middle, 0.05, name, ha="center", va="center", fontsize=_fit(name, 14),
            family=_FONT, weight="bold")


def _block(ax, name: str, inputs: list[str], outputs: list[str]) -> None:
    """A rounded block with the name on top and a labelled arrow for each port."""
    ax.add_patch(FancyBboxPatch((0.1, 0.06), 0.8, 0.88, boxstyle="round,pad=0,rounding_size=0.06",
                                facecolor="#dde8f4", edgecolor="black", linewidth=2))
    ax.text(0.5, 0.85, name, ha="center", va="center", fontsize=_fit(name, 13),
            family=_FONT, weight="bold")
    for ports, edge, side in ((inputs, 0.1, "left"), (outputs, 0.9, "right")):
        step = 0.62 / max(len(ports), 1)
        for k, port in enumerate(ports):
            y = 0.7 - step * (k + 0.5)
            start, end = (edge - 0.09, edge) if side == "left" else (edge, edge + 0.09)
            ax.annotate("", xy=(end, y), xytext=(start, y),
                        arrowprops=dict(arrowstyle="-|>", color="black", linewidth=1.5))
            ax.text(edge + (0.03 if side == "left" else -0.03), y, port, ha=side, va="center",
                    fontsize=min(9.0, 0.9 * 72 * step * SIZE / DPI), family=_FONT)


def _fit(text: str, size: float) -> float:
    """A font size at most ``size`` points at which ``text`` fits across the icon."""
    return min(size, size * 11 / max(len(text), 1))
