"""What an FMU says of itself, derived from its entries alone (the same sources, the same
bytes): generation tool and identity in its model description, its page and its icon."""
from __future__ import annotations

import html
import io
import re
import textwrap
import zipfile
from collections.abc import Mapping
from importlib import metadata
from xml.etree.ElementTree import fromstring, indent, tostring

import matplotlib.style
from fmpy import read_model_description
from fmpy.model_description import ModelDescription, ModelVariable
from matplotlib.figure import Figure
from matplotlib.patches import FancyBboxPatch, Polygon

from fmukit.manifest import DISTRIBUTION
from ship_fmu.data import Hull

IDENTITY = ("author", "version", "copyright", "license")      # set where the model has none
PAPER = ("Tomera, M. (2010). <i>Nonlinear controller design of a ship autopilot</i>. "
         "Int. J. Appl. Math. Comput. Sci. 20(2), 271-280.")
_LINUX = ("CPython {{python}} (64-bit) with numpy. A Python host {} needs nothing else. A host "
          "that is not Python ({}, a C or C++ program) must load libpython before the FMU: "
          "<code>LD_PRELOAD=/path/to/libpython3.X.so</code>, with <code>PYTHONPATH</code> "
          "naming a site-packages that has numpy if that Python's own has none.")
_HOME = ("Set <code>PYTHONHOME</code> to that folder if Python cannot find its standard "
         "library, <code>PYTHONPATH</code> to a site-packages with numpy if its own has none.")
PYTHON_HOSTS = {                        # what a host needs to run a Python FMU, by platform
    "linux64": _LINUX.format("(fmpy, libcosimpy, ecospy)", "ecos, cosim-cli, OMSimulator"),
    "x86_64-linux": _LINUX.format("that runs FMI 3.0 (fmpy, ecospy)", "ecos, OMSimulator"),
    "x86_64-windows": "A 64-bit CPython {python} with numpy, its installation folder (with "
                      "<code>python3.dll</code>) on <code>PATH</code> of every host: the binary "
                      "imports python3.dll and KERNEL32 only. " + _HOME + " (Not tested on a "
                      "Windows host.)",
    "win64": "A 64-bit CPython {python} with numpy, its installation folder (with "
             "<code>python3.dll</code>, not a venv's <code>Scripts</code>) on <code>PATH</code> "
             "of every host, Python or not (Simulink, Dymola, OMSimulator, cosim-cli), and the "
             "Microsoft Visual C++ 2015-2022 Redistributable (x64): the binary imports "
             "python3.dll, MSVCP140, VCRUNTIME140(_1), the Universal C runtime and KERNEL32. "
             + _HOME + " (Tested with the platform faked and the DLL's imports read, not on "
             "a Windows host.)",
}
_STYLE = ("body{font-family:sans-serif;max-width:60em;margin:1em auto;padding:0 1em}"
          "table{border-collapse:collapse}th,td{border:1px solid #bbb;padding:2px 6px;"
          "text-align:left;vertical-align:top}pre{background:#f4f4f4;padding:4px}")
_ICON_INCHES, _DPI, _FONT = 2.56, 100, "DejaVu Sans"      # 256 x 256, matplotlib's own font


def describe(entries: Mapping[str, bytes], generation_tool: str, identity: Mapping[str, str],
             overview: str, sources: Mapping[str, str],
             hosts: Mapping[str, str]) -> dict[str, bytes]:
    """``entries`` with the model description's ``generation_tool`` and ``identity``, the
    page (``sources``: module: docstring; ``hosts``: platform: HTML) and the icon."""
    root = fromstring(entries["modelDescription.xml"])
    root.set("generationTool", generation_tool)
    root.attrib.pop("generationDateAndTime", None)       # the same sources, the same bytes
    for name in IDENTITY:
        if name in identity and not root.get(name):
            root.set(name, identity[name])
    indent(root, "\t")
    xml = tostring(root, "UTF-8", xml_declaration=True)
    with zipfile.ZipFile(buffer := io.BytesIO(), "w") as package:
        package.writestr("modelDescription.xml", xml)           # as fmpy reads it
    model = read_model_description(buffer, validate=False)
    platforms = {name.split("/")[1] for name in entries
                 if name.startswith("binaries/") and name.count("/") == 2}
    needed = metadata.metadata(DISTRIBUTION)["Requires-Python"]
    python = f"{needed[2:]} or later" if needed.startswith(">=") else needed
    return {**entries, "modelDescription.xml": xml, "model.png": model_png(model),
            "documentation/index.html": index_html(
                model, overview, sources,
                {p: hosts[p].format(python=python) for p in sorted(platforms) if p in hosts})}


def index_html(model: ModelDescription, overview: str, sources: Mapping[str, str],
               hosts: Mapping[str, str]) -> bytes:
    """documentation/index.html of ``model``; see ``describe``."""
    inputs, outputs, parameters = ([v for v in model.modelVariables if v.causality == c]
                                   for c in ("input", "output", "parameter"))
    feedthrough = {u.variable.name: [d.name for d in u.dependencies or []]
                   for u in model.outputs}
    about = [("FMI", f"{model.fmiVersion}, co-simulation"),
             *((a, getattr(model, a)) for a in (*IDENTITY, "generationTool") if getattr(model, a))]
    body = [f"<h1>{html.escape(model.modelName)}</h1>",
            f"<p>{html.escape(model.description or '')}</p>",
            "<table>\n" + "\n".join(f"<tr><th>{a}</th><td>{html.escape(value)}</td></tr>"
                                    for a, value in about) + "\n</table>",
            "<h2>Model</h2>", _prose(overview)]
    if "Tomera" in overview + (model.description or "") + "".join(sources.values()):
        body.append(f"<p>Equation numbers are those of {PAPER}</p>")
    body += ["<h2>Equations and sources</h2>"] if sources else []
    for module, doc in sources.items():
        summary, _, rest = doc.strip().partition("\n\n")
        body.append(f"<details><summary><code>{html.escape(module)}</code>: "
                    f"{_inline(summary)}</summary>{_prose(rest)}</details>")
    body += ["<h2>Inputs</h2>", _variables(inputs, ("start", "min", "max")),
             "<h2>Outputs</h2>", _variables(outputs, (), feedthrough),
             "<h2>Parameters</h2>", _variables(parameters, ("start", "min", "max"))]
    experiment = model.defaultExperiment
    if experiment is not None:
        body.append("<h2>Default experiment</h2><p>" + ", ".join(
            f"{a} {getattr(experiment, a)} s" for a in ("startTime", "stopTime", "stepSize")
            if getattr(experiment, a)) + "</p>")
    body += ["<h2>Host requirements</h2>", "<ul>" + "".join(
        f"<li><b>{p}</b>: {needs}</li>" for p, needs in hosts.items()) + "</ul>",
             "<h2>Example</h2>", _example(model, inputs)]
    return ('<!DOCTYPE html>\n<html lang="en">\n<head>\n<meta charset="utf-8"/>\n'
            f"<title>{html.escape(model.modelName)}</title>\n<style>{_STYLE}</style>\n</head>\n"
            "<body>\n" + "\n".join(part for part in body if part) + "\n</body>\n</html>\n").encode()


def _variables(variables: list[ModelVariable], columns: tuple[str, ...],
               feedthrough: Mapping[str, list[str]] | None = None) -> str:
    if not variables:
        return "<p>None.</p>"
    heads = ["name", "type", "unit", *("default" if c == "start" else c for c in columns),
             *(("direct feedthrough from",) if feedthrough is not None else ()), "meaning"]
    rows = ["<tr>" + "".join(f"<th>{h}</th>" for h in heads) + "</tr>"]
    for v in variables:
        shown = f" (shown in {v.displayUnit})" if v.displayUnit else ""
        cells = [v.type, (v.unit or "") + shown, *(getattr(v, c) or "" for c in columns)]
        if feedthrough is not None:
            cells.append(", ".join(feedthrough.get(v.name, [])) or "none")
        rows.append(f"<tr><td><code>{html.escape(v.name)}</code></td>" + "".join(
            f"<td>{html.escape(c)}</td>" for c in (*cells, v.description or "")) + "</tr>")
    return "<table>\n" + "\n".join(rows) + "\n</table>"


def _example(model: ModelDescription, inputs: list[ModelVariable]) -> str:
    """fmpy running the FMU alone, its first input that starts at 0 held at 0.1 instead (an
    FMU without inputs: its first such parameter)."""
    name = model.modelName
    held = next((v for v in inputs or [v for v in model.modelVariables
                                       if v.causality == "parameter"]
                 if v.type in ("Real", "Float64") and float(v.start or 1) == 0), None)
    stop = model.defaultExperiment.stopTime if model.defaultExperiment else None
    command = f"fmpy simulate {name}.fmu" + (f" --stop-time {stop}" if stop else "")
    if held is None:
        return f"<pre>{command} --output-file {name}.csv</pre>"
    value = repr(min(max(0.1, float(held.min or "-inf")), float(held.max or "inf")))
    unit = "" if (held.unit or "1") == "1" else " " + html.escape(held.unit)
    return (f"<p>The FMU alone{f' for {stop} s' if stop else ''}, with {held.causality} "
            f"<code>{held.name}</code> held at {value}{unit} and every other variable at its "
            f"start value; its outputs at every step go to {name}.csv:</p>\n"
            f"<pre>{command} --start-values {held.name} {value} --output-file {name}.csv</pre>\n"
            f"<p>or in Python:</p>\n<pre>from fmpy import simulate_fmu\nresult = simulate_fmu("
            f"{name + '.fmu'!r}, start_values={{{held.name!r}: {value}}}"
            + (f", stop_time={stop}" if stop else "") + ")</pre>")


def _prose(doc: str) -> str:
    """A docstring as HTML paragraphs, its indented blocks as preformatted text."""
    blocks = re.split(r"\n\s*\n", textwrap.dedent(doc).strip("\n"))
    return "\n".join(f"<pre>{html.escape(textwrap.dedent(block))}</pre>"
                     if all(line.startswith(" ") for line in block.splitlines())
                     else f"<p>{_inline(block)}</p>" for block in blocks if block)


def _inline(text: str) -> str:
    """Escaped text, its ``literals`` as code, joined onto one line."""
    return re.sub(r"``(.+?)``", r"<code>\1</code>", html.escape(" ".join(text.split())))


def model_png(model: ModelDescription) -> bytes:
    """model.png: a vessel (outputs x, y, psi) as CyberShip II's waterline, else a block."""
    inputs, outputs = ([v.name for v in model.modelVariables if v.causality == c]
                       for c in ("input", "output"))
    name = model.modelName
    with matplotlib.style.context("default"):
        figure = Figure(figsize=(_ICON_INCHES, _ICON_INCHES), dpi=_DPI)
        ax = figure.add_axes((0, 0, 1, 1), xlim=(0, 1), ylim=(0, 1))
        ax.set_axis_off()
        if {"x", "y", "psi"} <= set(outputs):       # the waterline, bow up, and two rudders
            length, half_beam, stern = 0.78, 0.39 * Hull.B / Hull.L, 0.16
            ax.add_patch(Polygon([(0.5, stern + length), (0.5 + half_beam, stern + 0.75 * length),
                                  (0.5 + half_beam, stern), (0.5 - half_beam, stern),
                                  (0.5 - half_beam, stern + 0.75 * length)], closed=True,
                                 facecolor="0.75", edgecolor="black", linewidth=2))
            for side in (-1, 1):
                ax.plot([0.5 + side * half_beam / 2] * 2, [stern, stern - 0.05],
                        color="black", linewidth=3, solid_capstyle="butt")
            title, size, arrows = 0.05, 14, ()
        else:                                       # a block with an arrow for each port
            ax.add_patch(FancyBboxPatch((0.1, 0.06), 0.8, 0.88, facecolor="#dde8f4",
                                        boxstyle="round,pad=0,rounding_size=0.06",
                                        edgecolor="black", linewidth=2))
            title, size = 0.85, 13
            arrows = ((inputs, 0.01, 0.1, 0.13, "left"), (outputs, 0.9, 0.99, 0.87, "right"))
        ax.text(0.5, title, name, ha="center", va="center", family=_FONT, weight="bold",
                fontsize=min(size, size * 11 / max(len(name), 1)))     # fits across
        for ports, start, end, label, side in arrows:
            step = 0.62 / max(len(ports), 1)
            for k, port in enumerate(ports):
                y = 0.7 - step * (k + 0.5)
                ax.annotate("", xy=(end, y), xytext=(start, y),
                            arrowprops=dict(arrowstyle="-|>", color="black", linewidth=1.5))
                ax.text(label, y, port, ha=side, va="center", family=_FONT,
                        fontsize=min(9.0, 0.9 * 72 * step * _ICON_INCHES))
        png = io.BytesIO()
        figure.savefig(png, format="png", transparent=True, metadata={"Software": None})
    return png.getvalue()
