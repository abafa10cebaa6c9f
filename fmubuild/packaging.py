"""Building a slave script written with fmukit into an FMU that carries exactly its model.

The FMU carries the script, what it imports of fmukit and this project (``imports``), the
modules given with ``--include``, a requirements.txt (numpy), its manifest and its entry
module (``routes``). The Linux binary gets ``exit_fix``, the FMU its documentation
(``documentation``), and the archive is written again reproducibly (``reproducible``);
it must validate with fmpy and instantiate without this checkout (``instantiate``).

A package whose __init__.py holds only a docstring is carried as a namespace package: a
non-Python host runs all its Python FMUs in one interpreter, where the first FMU to import
a package would otherwise own it (the guidance carries ship_fmu.data alone).
"""
from __future__ import annotations

import ast
import contextlib
import importlib
import inspect
import os
import shutil
import sys
import tempfile
from collections.abc import Mapping
from importlib import metadata
from pathlib import Path

from fmukit.manifest import DISTRIBUTION, Manifest, digest_of, sha256, version

from . import documentation, exit_fix, reproducible
from .imports import needed_modules
from .manifest import project_identity
from .project import FMU_DIRS, FMUS, ROOT
from .routes import ROUTES
from .instantiate import InstantiationFailed, instantiate_in_child

RUNTIME_REQUIREMENTS = "numpy\n"
PROJECT_PACKAGES = ("fmukit", "ship_fmu", "autopilot_fmu")


def build(name: str, dest: Path | None = None, fmi: int = 2) -> Path:
    """One FMU of this project built as FMI ``fmi`` to dest/name.fmu (default: FMU_DIRS)."""
    return build_script(ROOT / FMUS[name], PROJECT_PACKAGES,
                        (dest or FMU_DIRS[fmi]) / f"{name}.fmu", project_identity(), fmi)


def python_hosts() -> dict[str, str]:
    """``documentation.PYTHON_HOSTS`` with the Python versions this project runs on."""
    needed = metadata.metadata(DISTRIBUTION)["Requires-Python"]
    python = f"{needed[2:]} or later" if needed.startswith(">=") else needed
    return {platform: needs.format(python=python)
            for platform, needs in documentation.PYTHON_HOSTS.items()}


def build_script(script: Path, packages: tuple[str | Path, ...], dest: Path,
                 identity: Mapping[str, str] | None = None, fmi: int = 2) -> Path:
    """The slave in ``script`` built as FMI ``fmi`` into ``dest`` (a .fmu, or a folder);
    ``packages``: project package names (carried as imported) and paths (carried whole).
    ValueError naming the script if it cannot be built; RuntimeError if invalid."""
    from fmpy.validation import validate_fmu

    if fmi not in ROUTES:
        raise ValueError(f"fmukit builds FMI {' and '.join(f'{v}.0' for v in ROUTES)} "
                         f"FMUs, not FMI {fmi}")
    route = ROUTES[fmi]
    pythonfmu_version = route.gate()
    builder = importlib.import_module(route.pythonfmu).FmuBuilder
    script, dest = Path(script), Path(dest)
    if script.suffix != ".py":
        raise ValueError(f"{script} is not a Python script (.py) to build an FMU from")
    if not script.is_file():
        raise ValueError(f"{script} does not exist")
    includes = [Path(p) for p in packages if not isinstance(p, str)]
    for include in includes:
        if not include.exists():
            raise ValueError(f"{include}, to be carried by {script.name}'s FMU, does not exist")
    project = [p for p in packages if isinstance(p, str)]
    (dest.parent if dest.suffix == ".fmu" else dest).mkdir(parents=True, exist_ok=True)
    with tempfile.TemporaryDirectory(prefix=f"build_{script.stem}_") as tmp, \
            _imports_undone(tmp):
        stage, built = Path(tmp) / "resources", Path(tmp) / "built"
        stage.mkdir()
        modules = _stage(script, project, includes, stage)
        # pythonfmu imports the script by its name: not a module of that name imported before
        shadowed = sys.modules.pop(script.stem, None)
        try:
            sys.path.insert(0, str(stage))
            slave = _slave_class(script.stem)
            model_name = getattr(slave, "model_name", script.stem)
            entry = stage / f"{route.entry_module(model_name)}.py"
            if entry.exists():
                raise ValueError(f"its FMU's entry module would be {entry.name}, which is the "
                                 "name of a module it carries: rename that module")
            entry.write_text(route.entry_source(model_name, script.stem, slave.__name__))
            modules = dict(sorted({**modules, **_carry(entry, project, stage)}.items()))
            manifest = Manifest(model_name, _module_name(script), slave.__name__, modules,
                                digest_of({m: c["sha256"] for m, c in modules.items()}),
                                pythonfmu_version, route.options, version(), fmi,
                                {"module": entry.stem, **_carried(entry, entry.name)})
            (stage / "fmukit_manifest.json").write_text(manifest.to_json())
            sources = {m: _docstring(stage / c["file"].removeprefix("resources/"))
                       for m, c in modules.items()
                       if m.split(".")[0] != "fmukit" and m != manifest.slave_module}
            (stage / "requirements.txt").write_text(RUNTIME_REQUIREMENTS)
            built = Path(builder.build_FMU(
                entry, dest=built, project_files=[p for p in stage.iterdir() if p != entry],
                **route.options))
        except Exception as error:      # the script's own import errors included
            why = str(error).replace(str(stage / script.name), str(script))
            raise ValueError(f"cannot build an FMU from {script}: "
                             f"{type(error).__name__}: {why}") from error
        finally:
            if shadowed is not None:
                sys.modules[script.stem] = shadowed
        fmu = dest if dest.suffix == ".fmu" else dest / built.name
        tool = f"fmukit {version()} ({route.pythonfmu} {pythonfmu_version})"
        reproducible.rewrite(built, lambda entries: documentation.describe(
            exit_fix.patch_binaries(entries, fmu, fmi), tool, identity or {},
            _docstring(script), {m: doc for m, doc in sources.items() if doc},
            python_hosts()), to=fmu)
    problems = validate_fmu(str(fmu))
    if problems:
        raise RuntimeError(f"{fmu} does not validate:\n" + "\n".join(problems))
    try:
        instantiate_in_child(fmu, isolated=True)
    except InstantiationFailed as failed:
        fmu.unlink()
        why = (f"it did not instantiate within {failed.timed_out:g} s (does its class, or a "
               "module it imports, loop or wait at start?)" if failed.timed_out else
               "a module it imports is probably missing from it (carry it with --include)")
        raise RuntimeError(f"{fmu.name} was built but does not instantiate without this "
                           f"checkout, so it was removed; {why}:\n  "
                           + "\n  ".join(failed.last_words)) from None
    return fmu


def _slave_class(module_name: str) -> type:
    """The script's ModelSlave subclass with the longest MRO (as pythonfmu chooses);
    ValueError if there is none, or no single one."""
    module = importlib.import_module(module_name)
    model_slave = importlib.import_module("fmukit.slave").ModelSlave   # the script's fmukit
    classes = [c for _, c in inspect.getmembers(module, inspect.isclass)
               if issubclass(c, model_slave) and c is not model_slave]
    if not classes:
        raise ValueError(f"{module.__file__} defines no subclass of fmukit.slave.ModelSlave "
                         "(the FMU's model)")
    longest = max(len(c.__mro__) for c in classes)
    chosen = [c for c in classes if len(c.__mro__) == longest]
    if len(chosen) > 1:
        raise ValueError(f"{module.__file__} holds {len(chosen)} ModelSlave classes, "
                         f"{', '.join(c.__name__ for c in chosen)}, none of them derived from "
                         "the others: which is the FMU's?")
    return chosen[0]


def _stage(script: Path, packages: list[str], includes: list[Path],
           stage: Path) -> dict[str, dict[str, str]]:
    """Copy into ``stage`` the script, what it imports of ``packages`` and ``includes``;
    the manifest's modules."""
    shutil.copy2(script, stage)
    modules = {_module_name(script): _carried(script, script.name),
               **_carry(script, packages, stage)}
    for include in includes:
        files = ([include] if include.is_file() else
                 sorted(f for f in include.rglob("*") if f.is_file()
                        and "__pycache__" not in f.parts and f.suffix != ".pyc"))
        for file in files:
            relative = file.relative_to(include.parent)
            (stage / relative).parent.mkdir(parents=True, exist_ok=True)
            shutil.copy2(file, stage / relative)
            if file.suffix == ".py":
                module = ".".join(relative.with_suffix("").parts).removesuffix(".__init__")
                modules[module] = _carried(file, relative.as_posix())
    return dict(sorted(modules.items()))


def _carry(file: Path, packages: list[str], stage: Path) -> dict[str, dict[str, str]]:
    """Copy into ``stage`` the modules of ``packages`` that ``file`` imports; the manifest's
    entries."""
    modules = {}
    for module, found in needed_modules(file, {p: ROOT for p in packages}).items():
        if _only_documents(found):
            continue                    # a namespace package in the FMU: see the docstring
        relative = found.relative_to(ROOT)
        (stage / relative).parent.mkdir(parents=True, exist_ok=True)
        shutil.copy2(found, stage / relative)
        modules[module] = _carried(found, relative.as_posix())
    return modules


def _docstring(file: Path) -> str:
    """The docstring of the module in ``file``; empty if it has none."""
    return ast.get_docstring(ast.parse(file.read_bytes())) or ""


def _only_documents(file: Path) -> bool:
    """Whether ``file`` is a package's __init__.py that holds no more than a docstring."""
    if file.name != "__init__.py":
        return False
    body = ast.parse(file.read_bytes()).body
    return all(isinstance(node, ast.Expr) and isinstance(node.value, ast.Constant)
               for node in body)


def _carried(file: Path, relative: str) -> dict[str, str]:
    return {"file": f"resources/{relative}", "sha256": sha256(file)}


def _module_name(script: Path) -> str:
    """How this project imports a slave script: ship_fmu.ship_slave, or a user's by name."""
    try:
        relative = script.resolve().relative_to(ROOT)
    except ValueError:
        return script.stem
    if len(relative.parts) > 1 and relative.parts[0] in PROJECT_PACKAGES:
        return ".".join(relative.with_suffix("").parts)
    return script.stem


@contextlib.contextmanager
def _imports_undone(stage: str):
    """Forget what building imported from ``stage`` or pythonfmu's temporary folders (and
    its sys.path), so the next build or in-process run finds no stale module."""
    path, modules = list(sys.path), set(sys.modules)
    try:
        yield
    finally:
        sys.path[:] = path
        for name in set(sys.modules) - modules:
            file = str(getattr(sys.modules[name], "__file__", None) or "")
            if file.startswith(stage) or (file and not os.path.exists(file)):
                del sys.modules[name]
