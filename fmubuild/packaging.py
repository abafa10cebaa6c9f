"""A slave script built into an FMU that carries exactly its model (the script, what it
imports of fmukit and this project, the ``--include``s), reproducibly."""
from __future__ import annotations

import ast
import contextlib
import hashlib
import importlib.util
import inspect
import os
import re
import shutil
import sys
import tempfile
import traceback
import uuid
import zipfile
from collections.abc import Iterable, Iterator, Mapping
from pathlib import Path

from fmukit.manifest import Manifest, digest_of, sha256, version

from . import documentation
from .instantiate import InstantiationFailed, instantiate_in_child
from .project import DATA, FMU_DIRS, FMUS, ROOT, ROUTES, project_identity

PROJECT_PACKAGES = ("fmukit", "ship_fmu", "autopilot_fmu")
_IMPORT_ERRORS = {"ImportError", "ModuleNotFoundError", "Exception", "BaseException"}
_GUID = re.compile(rb'\s(guid|instantiationToken)="[^"]*"')


def build(name: str, dest: Path | None = None, fmi: int = 2) -> Path:
    """One FMU of this project built as FMI ``fmi`` to dest/name.fmu (default: FMU_DIRS)."""
    carried = (*PROJECT_PACKAGES, *(ROOT / file for file in DATA.get(name, ())))
    return build_script(ROOT / FMUS[name], carried, (dest or FMU_DIRS[fmi]) / f"{name}.fmu",
                        project_identity(), fmi)


def build_script(script: Path, packages: tuple[str | Path, ...], dest: Path,
                 identity: Mapping[str, str] | None = None, fmi: int = 2) -> Path:
    """The slave in ``script`` built into ``dest`` (a .fmu, or a folder); ``packages``:
    package names (carried as imported) and paths (carried whole). ValueError naming the
    script if it cannot be built; RuntimeError if invalid."""
    route, script, dest = ROUTES[fmi], Path(script), Path(dest)
    adapter = importlib.import_module(route.adapter)
    if not adapter.ACTIVE:
        raise RuntimeError(f"{route.pythonfmu} {adapter.PYTHONFMU_VERSION} is installed; fmukit "
                           f"builds FMI {fmi}.0 FMUs with {route.pythonfmu} {route.known} only, "
                           f"whose defects {route.adapter} compensates (pip install "
                           f"{route.pythonfmu}=={route.known}, or check the new version and "
                           f"extend {route.adapter})")
    folder = script.resolve().parent        # as imported: ship_fmu.ship_slave, a user's by name
    slave_module = (f"{folder.name}.{script.stem}" if folder.parent == ROOT
                    and folder.name in PROJECT_PACKAGES else script.stem)
    with _imports_undone(), tempfile.TemporaryDirectory(prefix=f"build_{script.stem}_") as tmp:
        stage = Path(tmp) / "resources"
        staged = {slave_module: _copy(script, stage / script.name)}     # module: its copy
        for include in (Path(p) for p in packages if not isinstance(p, str)):
            for file in [include] if include.is_file() else sorted(
                    f for f in include.rglob("*") if f.is_file()
                    and "__pycache__" not in f.parts and f.suffix != ".pyc"):
                relative = file.relative_to(include.parent)
                _copy(file, stage / relative)
                if file.suffix == ".py":
                    module = ".".join(relative.with_suffix("").parts)
                    staged[module.removesuffix(".__init__")] = stage / relative
        # pythonfmu imports the script by its name: not a module of that name imported before
        sys.modules.pop(script.stem, None)
        try:
            sys.path.insert(0, str(stage))
            slave = _slave_class(script.stem)
            model_name = getattr(slave, "model_name", script.stem)
            entry = stage / f"{model_name}_fmi{fmi}.py"
            if entry.exists():
                raise ValueError(f"its FMU's entry module would be {entry.name}, which is the "
                                 "name of a module it carries: rename that module")
            entry.write_text(route.entry_source(model_name, script.stem, slave.__name__))
            project = [p for p in packages if isinstance(p, str)]
            for module, found in needed_modules([script, entry], project).items():
                if found.name != "__init__.py" or not all(
                        isinstance(node, ast.Expr) and isinstance(node.value, ast.Constant)
                        for node in parsed(found).body):  # else a namespace package: a
                    # host runs its FMUs in one interpreter, where the first would own it
                    staged[module] = _copy(found, stage / found.relative_to(ROOT))
            modules = {m: _carried(path, stage) for m, path in sorted(staged.items())}
            manifest = Manifest(model_name, slave_module, slave.__name__, modules,
                                digest_of({m: c["sha256"] for m, c in modules.items()}),
                                adapter.PYTHONFMU_VERSION, route.options, version(), fmi,
                                {"module": entry.stem, **_carried(entry, stage)})
            (stage / "fmukit_manifest.json").write_text(manifest.to_json())
            (stage / "requirements.txt").write_text("numpy\n")
            sources = {m: doc for m, path in sorted(staged.items()) if m != slave_module
                       and m.split(".")[0] != "fmukit" and (doc := ast.get_docstring(parsed(path)))}
            built = importlib.import_module(route.pythonfmu).FmuBuilder.build_FMU(
                entry, dest=Path(tmp) / "built",
                project_files=[p for p in stage.iterdir() if p != entry], **route.options)
        except Exception as error:      # the script's own import errors included
            why = str(error).replace(str(stage / script.name), str(script))
            raise ValueError(f"cannot build an FMU from {script}: "
                             f"{type(error).__name__}: {why}") from error
        fmu = dest if dest.suffix == ".fmu" else dest / Path(built).name
        with zipfile.ZipFile(built) as package:     # the Linux binary with its exit fixed
            entries = {name: fix_exit(package.read(name), f"{fmu}:{name}", fmi)
                       if name.startswith(f"binaries/{route.linux}/") else package.read(name)
                       for name in package.namelist() if not name.endswith("/")}
    tool = f"fmukit {version()} ({route.pythonfmu} {adapter.PYTHONFMU_VERSION})"
    overview = ast.get_docstring(parsed(script)) or ""
    write_fmu(fmu, documentation.describe(entries, tool, identity or {}, overview, sources,
                                          documentation.PYTHON_HOSTS), derive_guid=True)
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


def write_fmu(fmu: Path, entries: Mapping[str, bytes], derive_guid: bool = False) -> Path:
    """``fmu`` written reproducibly from ``entries`` (name: bytes), validated by fmpy; with
    ``derive_guid``, its GUID (instantiation token) derived from its contents."""
    from fmpy.validation import validate_fmu
    if derive_guid:
        blank = {**entries, "modelDescription.xml": _GUID.sub(
            rb' \1=""', entries["modelDescription.xml"], 1)}
        contents = b"".join(name.encode() + b"\0" + hashlib.sha256(blank[name]).digest()
                            for name in sorted(blank))
        guid = uuid.uuid5(uuid.NAMESPACE_OID, hashlib.sha256(contents).hexdigest())
        entries = {**blank, "modelDescription.xml": _GUID.sub(
            rb' \1="{%s}"' % str(guid).encode(), blank["modelDescription.xml"], 1)}
    fmu.parent.mkdir(parents=True, exist_ok=True)
    temporary = fmu.with_name(f".{fmu.name}.tmp")
    try:
        with zipfile.ZipFile(temporary, "w", zipfile.ZIP_DEFLATED) as package:
            for name in sorted(entries):
                info = zipfile.ZipInfo(name, (1980, 1, 1, 0, 0, 0))     # the earliest
                info.compress_type = zipfile.ZIP_DEFLATED
                info.external_attr = (0o755 if name.startswith("binaries/") else 0o644) << 16
                package.writestr(info, entries[name])
        temporary.replace(fmu)
    finally:
        temporary.unlink(missing_ok=True)
    problems = validate_fmu(str(fmu))
    if problems:
        raise RuntimeError(f"{fmu} does not validate:\n" + "\n".join(problems))
    return fmu


def fix_exit(binary: bytes, where: str, fmi: int = 2) -> bytes:
    """A pythonfmu Linux binary fixed: its static destructor frees the global
    ``shared_ptr<PyState>`` at exit, then ``onLibraryUnload`` assigns to the dead pointer (an
    intermittent SIGABRT of every host). The destructor already shuts Python down, so
    ``onLibraryUnload`` becomes a plain return, in a binary the adapter knows by SHA-256;
    RuntimeError naming ``where`` if it knows none."""
    route, digest = ROUTES[fmi], hashlib.sha256(binary).hexdigest()
    fix = importlib.import_module(route.adapter).KNOWN_BINARIES.get(digest)
    if fix is None:
        raise RuntimeError(f"{where} is not the {route.pythonfmu} {route.known} {route.linux} "
                           f"binary whose exit-time heap corruption fmubuild knows how "
                           f"to fix (SHA-256 {digest}); check the new binary and extend "
                           f"{route.adapter}")
    end = fix.offset + len(fix.code)
    fixed = binary[:fix.offset] + fix.patched + binary[end:]
    if binary[fix.offset:end] != fix.code or hashlib.sha256(fixed).hexdigest() != fix.fixed_sha256:
        raise RuntimeError(f"{where}: the patched binary is not the one fmukit expects")
    return fixed


def needed_modules(scripts: Iterable[Path], packages: Iterable[str]) -> dict[str, Path]:
    """Module: file, for the modules of ``packages`` that ``scripts`` import, directly or not."""
    found: dict[str, Path] = {}
    todo = [(None, script) for script in scripts]
    while todo:
        name, path = todo.pop()
        package = name if path.name == "__init__.py" else (name or "").rpartition(".")[0]
        for module, _ in imports(path, package):
            parts = module.split(".")
            if parts[0] not in packages:
                continue
            for i in range(1, len(parts) + 1):      # a.b.c: a, a.b and a.b.c
                parent, base = ".".join(parts[:i]), ROOT.joinpath(*parts[:i])
                file = next((f for f in (base / "__init__.py", base.with_suffix(".py"))
                             if f.is_file()), None)
                if file is None:
                    break                           # a name imported from a module
                if parent not in found:
                    found[parent] = file
                    todo.append((parent, file))
    return dict(sorted(found.items()))


def imports(path: Path, package: str = "") -> Iterator[tuple[str, bool]]:
    """(module, optional) for each import in ``path``, a module of ``package``: for ``from a
    import b``, a and a.b; optional if inside a try that catches ImportError."""
    tree = parsed(path)
    optional = {id(node) for block in ast.walk(tree) if isinstance(block, ast.Try)
                and any(handler.type is None or _IMPORT_ERRORS & {
                    n.id for n in ast.walk(handler.type) if isinstance(n, ast.Name)}
                        for handler in block.handlers)
                for statement in block.body for node in ast.walk(statement)}
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            yield from ((alias.name, id(node) in optional) for alias in node.names)
        elif isinstance(node, ast.ImportFrom) and (package or not node.level):
            base = importlib.util.resolve_name("." * node.level + (node.module or ""), package) \
                if node.level else node.module
            yield from ((name, id(node) in optional) for name in
                        [base, *(f"{base}.{alias.name}" for alias in node.names)])


def parsed(path: Path) -> ast.Module:
    """The syntax tree of ``path``; ValueError naming the file and line, with a caret."""
    try:
        return ast.parse(path.read_bytes(), str(path))
    except SyntaxError as error:
        quoted = "".join(traceback.format_exception_only(error)[1:-1]).rstrip()
        raise ValueError(f"{path}:{error.lineno}: {type(error).__name__}: {error.msg}"
                         + (f"\n{quoted}" if quoted else "")) from None


def _slave_class(module_name: str) -> type:
    """The script's ModelSlave subclass with the longest MRO (as pythonfmu chooses)."""
    module = importlib.import_module(module_name)
    model_slave = importlib.import_module("fmukit.slave").ModelSlave   # the script's fmukit
    classes = [c for _, c in inspect.getmembers(module, inspect.isclass)
               if issubclass(c, model_slave) and c is not model_slave]
    if not classes:
        raise ValueError(f"{module.__file__} defines no subclass of fmukit.slave.ModelSlave "
                         "(the FMU's model)")
    chosen = [c for c in classes if len(c.__mro__) == max(len(c.__mro__) for c in classes)]
    if len(chosen) > 1:
        raise ValueError(f"{module.__file__} holds {len(chosen)} ModelSlave classes, "
                         f"{', '.join(c.__name__ for c in chosen)}, none of them derived from "
                         "the others: which is the FMU's?")
    return chosen[0]


def _copy(file: Path, to: Path) -> Path:
    to.parent.mkdir(parents=True, exist_ok=True)
    return Path(shutil.copy2(file, to))


def _carried(file: Path, stage: Path) -> dict[str, str]:      # its entry in the manifest
    return {"file": file.relative_to(stage.parent).as_posix(), "sha256": sha256(file)}


@contextlib.contextmanager
def _imports_undone() -> Iterator[None]:
    """sys.path and earlier modules restored; modules from the build's folders forgotten."""
    path, modules = list(sys.path), dict(sys.modules)
    try:
        yield
    finally:
        sys.path[:] = path
        for name in sys.modules.keys() - modules.keys():
            file = getattr(sys.modules[name], "__file__", None)
            if file and not os.path.exists(file):
                del sys.modules[name]
        sys.modules.update(modules)
