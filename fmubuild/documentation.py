"""What an FMU says of itself (``describe``): its model description's generation tool and the
identity the model does not declare, documentation/index.html (its sources' docstrings,
every variable, the default experiment, what a host needs, a worked example with fmpy) and
model.png (``icon``). Derived from the entries alone, so the same sources give the same bytes.
"""
from __future__ import annotations

import html
import re
import textwrap
from collections.abc import Mapping
from xml.dom.minidom import parseString
from xml.etree.ElementTree import Element, fromstring, tostring

from . import icon

PAGE = "documentation/index.html"
IDENTITY = ("author", "version", "copyright", "license")
"""modelDescription.xml attributes set where the model does not declare them."""

PAPER = ("Tomera, M. (2010). <i>Nonlinear controller design of a ship autopilot</i>. "
         "Int. J. Appl. Math. Comput. Sci. 20(2), 271-280.")
"""The paper whose equation numbers the project's docstrings cite as Tomera 2010."""

_PRELOAD = ("a C or C++ program) must load libpython before the FMU: <code>LD_PRELOAD="
            "/path/to/libpython3.X.so</code>, with <code>PYTHONPATH</code> naming a "
            "site-packages that has numpy if that Python's own has none.")
_HOME = ("Set <code>PYTHONHOME</code> to that folder if Python cannot find its standard "
         "library, <code>PYTHONPATH</code> to a site-packages with numpy if its own has none.")
PYTHON_HOSTS = {
    "linux64": "CPython {python} (64-bit) with numpy. A Python host (fmpy, libcosimpy, "
               "ecospy) needs nothing else. A host that is not Python (ecos, cosim-cli, "
               "OMSimulator, " + _PRELOAD,
    "x86_64-linux": "CPython {python} (64-bit) with numpy. A Python host that runs FMI 3.0 "
                    "(fmpy, ecospy) needs nothing else. A host that is not Python (ecos, "
                    "OMSimulator, " + _PRELOAD,
    "x86_64-windows": "A 64-bit CPython {python} with numpy, whose installation folder (the "
                      "one with <code>python3.dll</code>) is on <code>PATH</code> of every "
                      "host: the binary imports python3.dll and KERNEL32 only. " + _HOME
                      + " (Not tested on a Windows host.)",
    "win64": "A 64-bit CPython {python} with numpy, whose installation folder (the one "
             "with <code>python3.dll</code>, not a venv's <code>Scripts</code>) is on "
             "<code>PATH</code> of every host, Python or not (Simulink, Dymola, "
             "OMSimulator, cosim-cli), and the Microsoft Visual C++ 2015-2022 "
             "Redistributable (x64) for <code>MSVCP140.dll</code>: the binary imports "
             "python3.dll, MSVCP140, VCRUNTIME140(_1), the Universal C runtime and KERNEL32. "
             + _HOME + " (Tested on Linux with the platform faked and the DLL's imports read, "
             "not on a Windows host.)",
}
"""What a host needs to run a Python FMU, by platform; {python}: the Python versions."""

_STYLE = ("body{font-family:sans-serif;max-width:60em;margin:1em auto;padding:0 1em}"
          "table{border-collapse:collapse}th,td{border:1px solid #bbb;padding:2px 6px;"
          "text-align:left;vertical-align:top}pre{background:#f4f4f4;padding:4px}")


def describe(entries: Mapping[str, bytes], generation_tool: str, identity: Mapping[str, str],
             overview: str, sources: Mapping[str, str],
             hosts: Mapping[str, str]) -> dict[str, bytes]:
    """``entries`` with the model description's ``generation_tool`` and ``identity``, the
    page (``overview``: the model's docstring; ``sources``: module: docstring; ``hosts``:
    platform: HTML) and the icon."""
    xml = identified(entries["modelDescription.xml"], generation_tool, identity)
    platforms = sorted({name.split("/")[1] for name in entries
                        if name.startswith("binaries/") and name.count("/") == 2})
    return {**entries, "modelDescription.xml": xml,
            PAGE: index_html(xml, overview, sources,
                             {p: hosts[p] for p in platforms if p in hosts}),
            "model.png": icon.model_png(xml)}


def identified(xml: bytes, generation_tool: str, identity: Mapping[str, str]) -> bytes:
    """The model description ``xml`` naming ``generation_tool``, with each attribute of
    ``identity`` it lacks; written as pythonfmu writes it (minidom, tab-indented)."""
    root = fromstring(xml)
    for element in root.iter():             # the layout is written again below
        if element.text is not None and not element.text.strip():
            element.text = None
        if element.tail is not None and not element.tail.strip():
            element.tail = None
    root.set("generationTool", generation_tool)
    for name in IDENTITY:
        if name in identity and not root.get(name):
            root.set(name, identity[name])
    return parseString(tostring(root, "UTF-8")).toprettyxml(indent="\t", encoding="UTF-8")


def index_html(xml: bytes, overview: str, sources: Mapping[str, str],
               hosts: Mapping[str, str]) -> bytes:
    """documentation/index.html of the FMU with model description ``xml``; see ``describe``."""
    root = fromstring(xml)
    name = root.get("modelName", "")
    variables = root.find("ModelVariables")
    if root.get("fmiVersion", "").startswith("3"):       # by value reference
        by_key = {v.get("valueReference"): v.get("name") for v in variables}
        unknowns, key = root.iterfind("ModelStructure/Output"), "valueReference"
    else:                                                # by 1-based index
        by_key = {str(i): v.get("name") for i, v in enumerate(variables, 1)}
        unknowns, key = root.iterfind("ModelStructure/Outputs/Unknown"), "index"
    feedthrough = {by_key[u.get(key)]: [by_key[d] for d in (u.get("dependencies") or "").split()]
                   for u in unknowns}
    inputs, outputs, parameters = ([v for v in variables if v.get("causality") == c]
                                   for c in ("input", "output", "parameter"))
    about = [("FMI", f"{root.get('fmiVersion')}, co-simulation"),
             *((a, root.get(a)) for a in (*IDENTITY, "generationTool") if root.get(a))]
    body = [f"<h1>{html.escape(name)}</h1>",
            f"<p>{html.escape(root.get('description', ''))}</p>",
            "<table>\n" + "\n".join(f"<tr><th>{a}</th><td>{html.escape(value)}</td></tr>"
                                    for a, value in about) + "\n</table>",
            "<h2>Model</h2>", _prose(overview)]
    if "Tomera" in overview + root.get("description", "") + "".join(sources.values()):
        body.append(f"<p>Equation numbers are those of {PAPER}</p>")
    if sources:
        body.append("<h2>Equations and sources</h2>")
        for module, doc in sources.items():
            summary, _, rest = doc.strip().partition("\n\n")
            body.append(f"<details><summary><code>{html.escape(module)}</code>: "
                        f"{_inline(summary)}</summary>{_prose(rest)}</details>")
    body += ["<h2>Inputs</h2>", _table(inputs, ("start", "min", "max")),
             "<h2>Outputs</h2>", _table(outputs, (), feedthrough),
             "<h2>Parameters</h2>", _table(parameters, ("start", "min", "max"))]
    experiment = root.find("DefaultExperiment")
    if experiment is not None:
        body.append("<h2>Default experiment</h2><p>" + ", ".join(
            f"{a} {experiment.get(a)} s" for a in ("startTime", "stopTime", "stepSize")
            if experiment.get(a)) + "</p>")
    body += ["<h2>Host requirements</h2>", "<ul>" + "".join(
        f"<li><b>{p}</b>: {needs}</li>" for p, needs in hosts.items()) + "</ul>"]
    body += ["<h2>Example</h2>", _example(name, inputs, experiment)]
    page = ('<!DOCTYPE html>\n<html lang="en">\n<head>\n<meta charset="utf-8"/>\n'
            f"<title>{html.escape(name)}</title>\n<style>{_STYLE}</style>\n</head>\n<body>\n"
            + "\n".join(part for part in body if part) + "\n</body>\n</html>\n")
    return page.encode()


def _table(variables: list[Element], columns: tuple[str, ...],
           feedthrough: Mapping[str, list[str]] | None = None) -> str:
    """A table of ``variables``: name, type, unit, the typed element's ``columns`` and
    meaning; for outputs (``feedthrough``), the inputs each depends on at once."""
    if not variables:
        return "<p>None.</p>"
    heads = ["name", "type", "unit", *("default" if c == "start" else c for c in columns),
             *(("direct feedthrough from",) if feedthrough is not None else ()), "meaning"]
    rows = ["<tr>" + "".join(f"<th>{h}</th>" for h in heads) + "</tr>"]
    for v in variables:
        typed = _typed(v)
        unit = typed.get("unit", "")
        if typed.get("displayUnit"):
            unit += f" (shown in {typed.get('displayUnit')})"
        cells = [f"<code>{html.escape(v.get('name'))}</code>", typed.tag, unit,
                 *(_attribute(typed, c) for c in columns)]
        if feedthrough is not None:
            cells.append(", ".join(feedthrough.get(v.get("name"), [])) or "none")
        cells.append(v.get("description", ""))
        rows.append("<tr>" + "".join(f"<td>{c if i == 0 else html.escape(c)}</td>"
                                     for i, c in enumerate(cells)) + "</tr>")
    return "<table>\n" + "\n".join(rows) + "\n</table>"


def _example(name: str, inputs: list[Element], experiment: Element | None) -> str:
    """fmpy's command line and Python running the FMU alone, its first input that starts
    at 0 held at 0.1 instead (clipped to its range)."""
    held = next((v for v in inputs if _typed(v).tag in ("Real", "Float64")
                 and float(_typed(v).get("start", 1)) == 0), None)
    stop = experiment.get("stopTime") if experiment is not None else None
    stop_option = f" --stop-time {stop}" if stop else ""
    if held is None:
        return (f"<pre>fmpy simulate {name}.fmu{stop_option} --output-file {name}.csv</pre>")
    typed = _typed(held)
    value = repr(min(max(0.1, float(typed.get("min", "-inf"))), float(typed.get("max", "inf"))))
    variable = held.get("name")
    arguments = f"start_values={{{variable!r}: {value}}}" + (f", stop_time={stop}" if stop
                                                              else "")
    unit = "" if typed.get("unit", "1") == "1" else " " + html.escape(typed.get("unit"))
    return (f"<p>The FMU alone{f' for {stop} s' if stop else ''}, with input "
            f"<code>{variable}</code> held at {value}{unit} "
            "and every other variable at its start value; its outputs at every step go to "
            f"{name}.csv:</p>\n"
            f"<pre>fmpy simulate {name}.fmu{stop_option} --start-values {variable} {value} "
            f"--output-file {name}.csv</pre>\n<p>or in Python:</p>\n"
            f"<pre>from fmpy import simulate_fmu\n"
            f"result = simulate_fmu({name + '.fmu'!r}, {arguments})</pre>")


def _typed(variable: Element) -> Element:
    """The element of a variable's type (FMI 2.0: its child; FMI 3.0: itself)."""
    return variable[0] if variable.tag == "ScalarVariable" else variable


def _attribute(typed: Element, name: str) -> str:
    """An attribute of a variable's type ('' if it has none); FMI 3.0 gives a String's
    start as the value of a <Start> child."""
    start = typed.find("Start") if name == "start" else None
    return typed.get(name, "") if start is None else start.get("value", "")


def _prose(doc: str) -> str:
    """A docstring as HTML: paragraphs, indented blocks as preformatted text, '- ' lists."""
    parts = []
    for block in re.split(r"\n\s*\n", textwrap.dedent(doc).strip("\n")):
        lines = block.splitlines()
        if all(line.startswith(" ") for line in lines):
            parts.append(f"<pre>{html.escape(textwrap.dedent(block))}</pre>")
        elif block.startswith("- "):
            items = re.split(r"\n- ", block[2:])
            parts.append("<ul>" + "".join(f"<li>{_inline(i)}</li>" for i in items) + "</ul>")
        elif block:
            parts.append(f"<p>{_inline(block)}</p>")
    return "\n".join(parts)


def _inline(text: str) -> str:
    """Escaped text, its ``literals`` as code, joined onto one line."""
    text = html.escape(" ".join(text.split()))
    return re.sub(r"``(.+?)``", r"<code>\1</code>", text)
