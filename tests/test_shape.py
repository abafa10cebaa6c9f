"""The package's own rules of shape (docs/architecture.md), read from its sources: no import
cycle, a core that knows nothing of the project, cosim's layers, library code that imports no
command, no module over 300 lines, the master and the slave base class within their budgets."""
from __future__ import annotations

import ast
from pathlib import Path

import pytest

from fmubuild.project import ROOT

PACKAGES = ("cosim", "fmukit", "fmubuild", "ship_fmu", "autopilot_fmu")
COMMANDS = {"cosim.run", "cosim.sweep", "cosim.export", "cosim.bench", "cosim.engines",
            "cosim.score", "cosim.accuracy", "cosim.train", "cosim._cli", "fmukit.build",
            "fmubuild.cli"}
LAYERS = (("cosim.core",), ("cosim.ensemble",), ("cosim.scenarios",), ("cosim.analysis",),
          ("cosim.interop",), ("cosim", "cosim.api", "cosim.outputs", "cosim.provenance",
                               "cosim.testing"), ("cosim.studies",), ("cosim.rl",))
"""cosim's layers, lowest first: a module imports only from its own layer and those below."""
MAX_LINES = 300
CLASS_BUDGETS = {("cosim/core/master.py", "Master"): 150, ("fmukit/slave.py", "ModelSlave"): 220}


def _modules() -> dict[str, Path]:
    files = [p for package in PACKAGES for p in (ROOT / package).rglob("*.py")]
    return {".".join(p.relative_to(ROOT).with_suffix("").parts).removesuffix(".__init__"): p
            for p in files}


MODULES = _modules()


def _imports(name: str, path: Path) -> set[str]:
    """The project's modules ``name`` imports, wherever in the file (a package for ``from
    package import name`` only where ``name`` is not a module of it)."""
    package = name if path.name == "__init__.py" else name.rpartition(".")[0]
    found = set()
    for node in ast.walk(ast.parse(path.read_text())):
        if isinstance(node, ast.Import):
            found |= {a.name for a in node.names}
        elif isinstance(node, ast.ImportFrom):
            base = node.module or ""
            if node.level:
                parts = package.split(".")[:len(package.split(".")) - node.level + 1]
                base = ".".join([*parts, base] if base else parts)
            subs = {f"{base}.{a.name}" for a in node.names} & MODULES.keys()
            found |= subs or {base}
    return (found & MODULES.keys()) - {name}


GRAPH = {name: _imports(name, path) for name, path in MODULES.items()}


def test_no_module_imports_itself_through_others():
    def reaches(start: str) -> set[str]:
        seen, todo = set(), list(GRAPH[start])
        while todo:
            module = todo.pop()
            if module not in seen:
                seen.add(module)
                todo += GRAPH[module]
        return seen
    assert [m for m in GRAPH if m in reaches(m)] == []


def test_the_core_imports_nothing_of_the_project_but_the_fmu_runtime():
    outside = {(m, i) for m, imported in GRAPH.items() if m.startswith("cosim.core")
               for i in imported if not i.startswith(("cosim.core", "fmukit"))}
    assert outside == set()
    for name, path in MODULES.items():
        if name.startswith("cosim.core"):                  # where FMUs are is the caller's
            tree = ast.parse(path.read_text())
            docs = {id(n.body[0].value) for n in ast.walk(tree) if isinstance(n, (
                ast.Module, ast.ClassDef, ast.FunctionDef)) and ast.get_docstring(n)}
            named = [n.value for n in ast.walk(tree) if isinstance(n, ast.Constant)
                     and isinstance(n.value, str) and id(n) not in docs
                     and ("fmus/" in n.value or "/fmus" in n.value)]
            named += [n.right.value for n in ast.walk(tree) if isinstance(n, ast.BinOp)
                      and isinstance(n.right, ast.Constant) and n.right.value == "fmus"]
            assert named == [], name


def _layer(name: str) -> int | None:
    return next((k for k, layer in enumerate(LAYERS) for top in layer
                 if name == top or (top != "cosim" and name.startswith(top + "."))), None)


def test_cosim_modules_import_only_from_their_layer_and_those_below():
    upward = {(m, i) for m, imported in GRAPH.items() if _layer(m) is not None
              for i in imported if i.startswith("cosim") and i not in COMMANDS
              and (_layer(i) is None or _layer(i) > _layer(m))}
    assert upward == set()


def test_library_modules_import_no_command():
    assert {(m, i) for m, imported in GRAPH.items() if m not in COMMANDS
            for i in imported & COMMANDS} == set()


@pytest.mark.parametrize("name", sorted(MODULES))
def test_a_module_within_its_lines(name):
    assert len(MODULES[name].read_text().splitlines()) <= MAX_LINES


@pytest.mark.parametrize("where, budget", CLASS_BUDGETS.items(), ids=lambda c: str(c))
def test_the_master_and_the_slave_within_their_budgets(where, budget):
    file, name = where
    (cls,) = [n for n in ast.walk(ast.parse((ROOT / file).read_text()))
              if isinstance(n, ast.ClassDef) and n.name == name]
    assert cls.end_lineno - cls.lineno + 1 <= budget
