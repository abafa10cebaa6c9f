"""Which modules a slave script needs: its imports of the given packages, followed through.

Read from the sources (``ast``), not by importing them: ``import a.b``, ``from a.b
import c`` (``c`` a module or a name), and relative imports; each module comes with
the ``__init__`` files of the packages above it. Imports of anything else (the
standard library, numpy, pythonfmu) are the host's, and not followed.
"""
from __future__ import annotations

import ast
from pathlib import Path


def needed_modules(script: Path, packages: dict[str, Path]) -> dict[str, Path]:
    """Module name: file, for every module of ``packages`` (top-level name: the folder
    that holds it) that ``script`` imports, directly or through another. ValueError
    naming the file and the module if an import of one of them finds no file."""
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
    for node in ast.walk(ast.parse(path.read_bytes(), str(path))):
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
