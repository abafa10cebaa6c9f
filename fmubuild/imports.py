"""Which modules a slave script needs: its imports of the given packages, read from the sources
(``ast``) and followed through; ``uncarried`` finds those a host would not have either.
"""
from __future__ import annotations

import ast
import importlib.util
import sys
import traceback
from collections.abc import Iterable
from importlib.machinery import PathFinder
from pathlib import Path

from .project import ROOT

_IMPORT_ERRORS = {"ImportError", "ModuleNotFoundError", "Exception", "BaseException"}
"""What an ``except`` that makes an import optional catches."""


def needed_modules(scripts: Iterable[Path], packages: Iterable[str]) -> dict[str, Path]:
    """Module: file, for every module of ``packages`` (of this checkout) that ``scripts``
    imports, directly or not; ValueError if one has no file."""
    found: dict[str, Path] = {}
    todo = [(None, script) for script in scripts]
    while todo:
        name, path = todo.pop()
        for module, required in _imports(path, name):
            parts = module.split(".")
            if parts[0] not in packages:
                continue
            for i in range(1, len(parts) + 1):      # a.b.c: a, a.b and a.b.c
                parent, base = ".".join(parts[:i]), ROOT.joinpath(*parts[:i])
                file = next((f for f in (base / "__init__.py", base.with_suffix(".py"))
                             if f.is_file()), None)
                if file is None and required:
                    raise ValueError(f"{path} imports {module}, which has no file in {ROOT}")
                if file is None:
                    break                           # a name imported from a module
                if parent not in found:
                    found[parent] = file
                    todo.append((parent, file))
    return dict(sorted(found.items()))


def _imports(path: Path, module: str | None) -> list[tuple[str, bool]]:
    """(module, must exist) for what ``path`` (module ``module``, None for a script)
    imports; for ``from a import b``, a and, as may-exist, a.b (b may be a module)."""
    package = module if path.name == "__init__.py" else (module or "").rpartition(".")[0]
    names = []
    for node in ast.walk(parsed(path)):
        if isinstance(node, ast.Import):
            names += [(alias.name, True) for alias in node.names]
        elif isinstance(node, ast.ImportFrom):
            base = node.module or ""
            if node.level and package:
                base = importlib.util.resolve_name("." * node.level + base, package)
            names += [(base, True)] if base else []
            names += [(f"{base}.{alias.name}".lstrip("."), False) for alias in node.names
                      if alias.name != "*"]
    return names


def parsed(path: Path) -> ast.Module:
    """The syntax tree of ``path``; ValueError naming the file and line, with the line and a
    caret under the error."""
    try:
        return ast.parse(path.read_bytes(), str(path))
    except SyntaxError as error:
        quoted = "".join(traceback.format_exception_only(error)[1:-1]).rstrip()
        raise ValueError(f"{path}:{error.lineno}: {type(error).__name__}: {error.msg}"
                         + (f"\n{quoted}" if quoted else "")) from None


def uncarried(script: Path, includes: Iterable[Path], carried: Iterable[str]
              ) -> list[tuple[str, Path, Path | None]]:
    """(module, importer, where it is here or None) for the top-level modules ``script`` or
    ``includes`` import (outside a try that catches ImportError) that a host would not have:
    not standard, not installed in this Python (this checkout and the local folders do not
    count), not ``carried``, not included."""
    includes = [Path(p) for p in includes]
    provided = {*carried, *(p.stem if p.is_file() else p.name for p in includes)}
    local = [script.resolve().parent, Path.cwd().resolve(), ROOT,
             *(p.resolve().parent for p in includes)]
    host = [p for p in sys.path if p and Path(p).exists() and Path(p).resolve() not in local]
    files = [f for p in includes for f in ([p] if p.is_file() else sorted(p.rglob("*.py")))]
    missing: dict[str, tuple[str, Path, Path | None]] = {}
    for file in [script, *(f for f in files if f.suffix == ".py")]:
        for module in _top_level_imports(parsed(file)):
            if module in provided or module in sys.stdlib_module_names or module in missing \
                    or module in sys.builtin_module_names or PathFinder.find_spec(module, host):
                continue
            spec = PathFinder.find_spec(module, [str(folder) for folder in local])
            where = spec and (spec.submodule_search_locations or [spec.origin])  # a package's
            missing[module] = (module, file, Path(next(iter(where))) if where else None)
    return list(missing.values())


def _top_level_imports(tree: ast.Module) -> list[str]:
    """The first name of every absolute import in ``tree`` outside a try that catches
    ImportError."""
    optional = {id(node) for block in ast.walk(tree) if isinstance(block, ast.Try)
                and any(handler.type is None or _IMPORT_ERRORS & {
                    n.id for n in ast.walk(handler.type) if isinstance(n, ast.Name)}
                        for handler in block.handlers)
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
