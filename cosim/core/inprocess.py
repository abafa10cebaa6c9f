"""The master's in-process backend: an FMU built with fmukit run as its Python class, without
FMI, if it is current here (then a run equals one through FMI bit for bit)."""
from __future__ import annotations

import hashlib
import importlib
import re
import zipfile
from functools import cache
from pathlib import Path
from typing import Any
from xml.etree import ElementTree

from fmukit.compose import fmu_class
from fmukit.entry import unguarded
from fmukit.manifest import Manifest, read, staleness
from fmukit.refusals import Refused, explain, naming
from fmukit.slave import ModelSlave

from .fmi import CALLS, described, read_description
from .instance import FmuCallError, Instance, LogRecord, logged_error

_PYTHONFMU = ("resources/pythonfmu/", "resources/pythonfmu3/")   # what they carry of their own


class Reason(str):
    """Why an FMU runs through FMI; ``stale_module``: the slave module whose sources changed
    since the FMU was built (a rebuild mends it), else None."""

    def __new__(cls, text: str, stale_module: str | None = None) -> Reason:
        reason = super().__new__(cls, text)
        reason.stale_module = stale_module
        return reason


def slave_class(manifest: Manifest) -> type[ModelSlave]:
    """The model class an FMU's manifest names, composed for its FMI version."""
    module = importlib.import_module(manifest.slave_module)
    return fmu_class(getattr(module, manifest.slave_class), manifest.fmi)


def in_process_refusal(path: str | Path) -> Reason | None:
    """Why the FMU at ``path`` cannot run in-process, or None: it must be built with fmukit,
    hold what its manifest lists, declare what its class declares and be current here."""
    stat = Path(path).stat()
    return _refusal(Path(path).resolve(), stat.st_size, stat.st_mtime_ns)


def fallback_note(name: str, path: str | Path) -> Reason | None:
    """The note for component ``name`` whose FMU must run through FMI, not in-process."""
    refusal = in_process_refusal(path)
    return refusal and Reason(f"{name} ({Path(path).name}) runs through FMI, not in-process: "
                              f"{refusal}", refusal.stale_module)


@cache
def _refusal(path: Path, size: int, mtime_ns: int) -> Reason | None:     # cached by version
    try:
        manifest = read(path)
        if manifest is None:
            return Reason("it was not built with fmukit (it has no manifest)")
        described = read_description(path)
        if described.modelName != manifest.model_name:
            return Reason(f"its model description names the model '{described.modelName}', "
                          f"its manifest '{manifest.model_name}'")
        with zipfile.ZipFile(path) as fmu:
            refusal = _contents_refusal(fmu, manifest)
            declared = ElementTree.fromstring(fmu.read("modelDescription.xml"))
        if refusal:
            return Reason(refusal)
        stale = staleness(manifest)
        if stale is not None:
            return Reason(stale, manifest.slave_module)
        # an FMI version other than the manifest's declares other ModelVariables, too
        ours = slave_class(manifest)(instance_name=manifest.model_name).to_xml()
        for section in ("ModelVariables", "UnitDefinitions", "ModelStructure"):
            if _canonical(declared.find(section)) != _canonical(ours.find(section)):
                return Reason(f"its {section} differ from those its class "
                              f"{manifest.slave_module}.{manifest.slave_class} declares")
        return None
    except (OSError, KeyError, UnicodeDecodeError, ValueError, ImportError, AttributeError,
            zipfile.BadZipFile, ElementTree.ParseError) as error:
        return Reason("it cannot be read as an FMU built with fmukit "
                      f"({type(error).__name__}: {error})")


def _contents_refusal(fmu: zipfile.ZipFile, manifest: Manifest) -> str | None:
    """Why the FMU does not hold exactly the Python modules its manifest lists, or None."""
    listed = {c["file"]: c["sha256"] for c in manifest.modules.values()}
    entry = manifest.entry or manifest.modules[manifest.slave_module]
    listed[entry["file"]] = entry["sha256"]
    carried = {n for n in fmu.namelist() if n.startswith("resources/") and n.endswith(".py")
               and not n.startswith(_PYTHONFMU)}
    for name in sorted(carried - set(listed)):
        return f"it carries {name.removeprefix('resources/')}, which its manifest does not list"
    for name, digest in sorted(listed.items()):
        if name not in carried:
            return f"it lacks {name.removeprefix('resources/')}, which its manifest lists"
        if hashlib.sha256(fmu.read(name)).hexdigest() != digest:
            return f"its {name.removeprefix('resources/')} is not the source its manifest lists"
    module = fmu.read("resources/slavemodule.txt").decode().strip()
    if f"resources/{module}.py" != entry["file"]:
        return (f"its slave module is {module}.py, not "
                f"{entry['file'].removeprefix('resources/')} (its manifest)")
    return None


def _canonical(element: ElementTree.Element | None) -> str:
    return "" if element is None else ElementTree.canonicalize(ElementTree.tostring(element),
                                                               strip_text=True)


class InProcessInstance(Instance):
    """A slave class instantiated and driven in this process."""

    def __init__(self, path: str | Path, name: str):
        """For an FMU that ``in_process_refusal`` passes: its variables are its class's."""
        description, manifest = read_description(self.path, name), read(self.path)
        self.slave = slave_class(manifest)(instance_name=name)
        self.fmi_version, self.guid = manifest.fmi, description.guid
        self.variables, self.feedthrough = described(description)

    def call(self, what: str, function, *args, time: float | None = None,
             strict: bool = False) -> Any:
        try:
            result = function(*args)
        except Exception as error:
            raise self._failure(what, time, error) from error
        if result is False or self.slave.log_queue:
            self._judge(what, time, result, strict)
        return result

    def _failure(self, what: str, time: float | None, error: Exception,
                 status: str = "fatal") -> FmuCallError:
        """The refusal as FMI reports it, with the FMU's log or, if it logged no cause, ours."""
        records = self._drain()
        if not any(r.cause for r in records):
            category = error.category if isinstance(error, Refused) else None
            records.append(LogRecord(status, category, naming(self.name, explain(error))))
        return FmuCallError(self.name, what, time, status, records)

    def _judge(self, what: str, time: float | None, result: Any, strict: bool) -> None:
        """FmuCallError if a call refused or, ``strict``, logged an error; drains the log."""
        records = self._drain()
        status = getattr(result, "status", None)                # an FMI 3.0 step's
        failed = "discard" if result is False else getattr(status, "name", None)
        if failed in ("discard", "error", "fatal"):
            raise FmuCallError(self.name, what, time, failed, records)
        if strict and logged_error(records):
            raise FmuCallError(self.name, what, time, "OK but logged an error", records)

    def _drain(self) -> list[LogRecord]:
        records = [LogRecord(m.status.name, m.category or None, m.msg)    # pythonfmu3's: ""
                   for m in self.slave.log_queue]
        self.slave.log_queue.clear()
        return records

    def fmi(self, name: str):
        """The slave method behind a call name: setReal -> set_real (set_float64 on FMI 3.0)."""
        return getattr(self.slave, _method_name(CALLS.get(name, name) if self.fmi_version == 3
                                                else name))

    # Prepared calls: the slave's own plans (until ``reset``), else or if one raises: as FMI
    def reader(self, vrs: list[int], kind: str = "Real"):
        plan = getattr(self.slave.plans, f"{kind.lower()}_reader")(vrs)
        return _prepared(plan, super().reader(vrs, kind))

    def writer(self, vrs: list[int]):
        return self.slave.plans.input_writer(vrs) or super().writer(vrs)

    def stepper(self):
        do_step, queue = unguarded(self.slave.do_step), self.slave.log_queue
        refused = "error" if self.fmi_version == 3 else "fatal"   # as through FMI

        def step(t: float, h: float) -> None:
            try:
                done = do_step(t, h)
            except Exception as error:
                raise self._failure("doStep", t, error, refused) from error
            if done is not True or queue:          # FMI 3.0's: a Fmi3StepResult
                self._judge("doStep", t, done, False)
        return step

    def enter_initialization(self, start_time: float = 0.0) -> None:
        """As through FMI: pythonfmu3 drops fmi3EnterInitializationMode's start time."""
        if self.fmi_version == 2:
            self.call("setupExperiment", self.slave.setup_experiment, start_time)
        self.call("enterInitializationMode", self.slave.enter_initialization_mode)

    def reset(self) -> None:
        """A fresh slave object, as pythonfmu's fmi2Reset makes one."""
        self.slave = type(self.slave)(instance_name=self.name)

    def free(self) -> None:
        if self.slave.sequence.phase == "step":
            self.slave.terminate()


def _prepared(plan, through_fmi):
    if plan is None:
        return through_fmi

    def read() -> list:
        try:
            return plan()
        except Exception:
            return through_fmi()
    return read


@cache
def _method_name(fmi_name: str) -> str:
    return re.sub(r"(?<!^)([A-Z])", r"_\1", fmi_name).lower()
