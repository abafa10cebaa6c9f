"""Which modules a slave script needs: its imports of the given packages, read from the sources
(``ast``) and followed through; ``uncarried`` finds those a host would not have either.
"""
from __future__ import annotations

import ast
import sys
from collections.abc import Iterable
from dataclasses import dataclass
from importlib.machinery import ModuleSpec, PathFinder
from pathlib import Path

from .project import ROOT


def needed_modules(script: Path, packages: dict[str, Path]) -> dict[str, Path]:
    """Module: file, for every module of ``packages`` (name: its folder) that ``script``
    imports, directly or not; ValueError if one has no file."""
    found: dict[str, Path] = {}
    todo = [(None, script)]
    while todo:
        name, path = todo.pop()
        for module, required in _imports(path, name):
            if module.split(".")[0] not in packages:
                continue
            for parent in _parents(module):
                if parent in found:
                    continue
                file = _file(parent, packages)
                if file is None:
                    if required:
                        raise ValueError(f"{path} imports {module}, which has no file in "
                                         f"{packages[module.split('.')[0]]}")
                    break                      # a name imported from a module, not a module
                found[parent] = file
                todo.append((parent, file))
    return dict(sorted(found.items()))


def _imports(path: Path, module: str | None) -> list[tuple[str, bool]]:
    """(module, must exist) for what ``path`` (module ``module``, None for a script)
    imports; for ``from a import b``, a and, as may-exist, a.b (b may be a module)."""
    package = (module if path.name == "__init__.py" else module.rpartition(".")[0]) \
        if module else ""
    names = []
    for node in ast.walk(parsed(path)):
        if isinstance(node, ast.Import):
            names += [(alias.name, True) for alias in node.names]
        elif isinstance(node, ast.ImportFrom):
            base = node.module or ""
            if node.level:
                parts = package.split(".") if package else []
                parts = parts[:len(parts) - (node.level - 1)] if node.level > 1 else parts
                base = ".".join([*parts, *([base] if base else [])])
            if base:
                names.append((base, True))
            names += [(f"{base}.{alias.name}" if base else alias.name, False)
                      for alias in node.names if alias.name != "*"]
    return names


def _parents(module: str) -> list[str]:
    """'a.b.c' -> ['a', 'a.b', 'a.b.c']."""
    parts = module.split(".")
    return [".".join(parts[:i + 1]) for i in range(len(parts))]


def _file(module: str, packages: dict[str, Path]) -> Path | None:
    base = packages[module.split(".")[0]].joinpath(*module.split("."))
    for candidate in (base / "__init__.py", base.with_suffix(".py")):
        if candidate.is_file():
            return candidate
    return None


def parsed(path: Path) -> ast.Module:
    """The syntax tree of ``path``; ValueError naming the file and line, with a caret."""
    try:
        return ast.parse(path.read_bytes(), str(path))
    except SyntaxError as error:
        raise ValueError(f"{path}:{error.lineno}: {type(error).__name__}: {error.msg}"
                         f"{_quoted(error)}") from None


def _quoted(error: SyntaxError) -> str:
    """The offending line of a syntax error, indented, with a caret under its column."""
    line = (error.text or "").rstrip()
    if not line.strip():
        return ""
    text = line.lstrip()
    column = max(0, min(len(text), (error.offset or 1) - 1 - (len(line) - len(text))))
    return f"\n    {text}\n    {' ' * column}^"


@dataclass(frozen=True)
class Uncarried:
    """A module ``importer`` imports that a host would not have; ``found``: where it is here."""

    module: str
    importer: Path
    found: Path | None


def uncarried(script: Path, includes: Iterable[Path], carried: Iterable[str]
              ) -> list[Uncarried]:
    """The top-level modules ``script`` or ``includes`` import (outside a try that catches
    ImportError) that a host would not have: not standard, not installed in this Python
    (this checkout and the local folders do not count), not ``carried``, not included."""
    includes = [Path(p) for p in includes]
    provided = {*carried, *(p.stem if p.is_file() else p.name for p in includes)}
    local = [script.resolve().parent, Path.cwd().resolve(), ROOT,
             *(p.resolve().parent for p in includes)]
    host = [p for p in sys.path if p and Path(p).exists() and Path(p).resolve() not in local]
    missing: dict[str, Uncarried] = {}
    for file in [script, *_python_files(includes)]:
        for module in _top_level_imports(parsed(file)):
            if module in provided or module in sys.stdlib_module_names or module in missing \
                    or module in sys.builtin_module_names or PathFinder.find_spec(module, host):
                continue
            missing[module] = Uncarried(module, file, _where(PathFinder.find_spec(
                module, [str(folder) for folder in local])))
    return list(missing.values())


def _python_files(includes: list[Path]) -> list[Path]:
    return [f for p in includes for f in ([p] if p.is_file() else sorted(p.rglob("*.py")))
            if f.suffix == ".py"]


def _top_level_imports(tree: ast.Module) -> list[str]:
    """The first name of every absolute import in ``tree`` outside a try that catches
    ImportError."""
    optional = {id(node) for block in ast.walk(tree) if isinstance(block, ast.Try)
                and any(_catches_import_error(h) for h in block.handlers)
                for statement in block.body for node in ast.walk(statement)}
    names = []
    for node in ast.walk(tree):
        if id(node) in optional:
            continue
        if isinstance(node, ast.Import):
            names += [alias.name.split(".")[0] for alias in node.names]
        elif isinstance(node, ast.ImportFrom) and not node.level and node.module:
            names.append(node.module.split(".")[0])
    return list(dict.fromkeys(names))


def _catches_import_error(handler: ast.ExceptHandler) -> bool:
    caught = handler.type
    names = [caught] if not isinstance(caught, ast.Tuple) else caught.elts
    return caught is None or any(isinstance(n, ast.Name) and n.id in (
        "ImportError", "ModuleNotFoundError", "Exception", "BaseException") for n in names)


def _where(spec: ModuleSpec | None) -> Path | None:
    """The file of a module, or the folder of a package."""
    if spec is None:
        return None
    if spec.submodule_search_locations:
        return Path(next(iter(spec.submodule_search_locations)))
    return Path(spec.origin) if spec.origin else None
