"""The master's in-process backend: the FMUs' Python classes, called without FMI.

An ``InProcessInstance`` has the same interface as ``cosim.core.fmi.FmuInstance`` but
instantiates the slave class an FMU was built from (``fmukit.packaging.FMUS``) in this
process and calls its methods directly. A run on this backend differs from a
co-simulation only by the FMI layer (C wrapper, fmpy, ctypes), which is what the
equality tests compare: every column of every row is the same, bit for bit.

What FMI imposes and Python need not is dropped; what makes a run trustworthy is
kept. The master's loop gets, per component, the slave's own plans for its lists
of value references (``fmukit.fastpath``: one attribute read for the ship's
states, outputs evaluated under one ``try``, inputs set as attributes), resolved
once per run instead of dispatched per call by name. Steps go through the
slave's ``do_step``, with its checks of the call sequence, the step and every
input, and parameters through ``exitInitializationMode``'s checks: an invalid
value refuses the run with the same message as through FMI.
"""
from __future__ import annotations

import importlib
import inspect
import re
import zipfile
from dataclasses import dataclass
from functools import cache
from pathlib import Path
from typing import Any
from xml.etree import ElementTree

from fmukit.entry import explain, unguarded, unnamed
from fmukit.packaging import BUILD_HINT, FMUS, ROOT
from fmukit.slave import ModelSlave

from .instance import FmuCallError, Instance, logged_error

_FMI_TYPE = {float: "Real", int: "Integer", str: "String"}


@dataclass(frozen=True)
class VariableInfo:
    name: str
    valueReference: int
    type: str
    causality: str
    unit: str


def slave_class(fmu_name: str) -> type[ModelSlave]:
    """The ModelSlave subclass that this project's FMU ``fmu_name`` is built from."""
    if fmu_name not in FMUS:
        raise ValueError(f"no FMU named '{fmu_name}' is built by this project "
                         f"(known: {', '.join(FMUS)})")
    module_name = FMUS[fmu_name][0].removesuffix(".py").replace("/", ".")
    module = importlib.import_module(module_name)
    return next(cls for _, cls in inspect.getmembers(module, inspect.isclass)
                if issubclass(cls, ModelSlave) and getattr(cls, "model_name", None) == fmu_name)


def in_process_refusal(path: str | Path) -> str | None:
    """Why the FMU at ``path`` cannot run in-process, or None if it can: it must be one
    this project builds (by its modelName, whatever its file name), declare the
    variables, units and dependencies its class declares, and carry the same Python
    sources this process runs, so that both routes compute the same."""
    path = Path(path)
    stat = path.stat()
    key = (path.resolve(), stat.st_size, stat.st_mtime_ns)
    if key not in _refusals:
        _refusals[key] = _refusal(path)
    return _refusals[key]


_refusals: dict[tuple, str | None] = {}


def fallback_note(name: str, path: str | Path) -> str | None:
    """The note for component ``name`` when its FMU must run through FMI instead of
    in-process (``in_process_refusal``), or None."""
    refusal = in_process_refusal(path)
    return None if refusal is None else (f"{name} ({Path(path).name}) runs through FMI, "
                                         f"not in-process: {refusal}")


def _refusal(path: Path) -> str | None:
    try:
        with zipfile.ZipFile(path) as fmu:
            declared = ElementTree.fromstring(fmu.read("modelDescription.xml"))
            name = declared.get("modelName")
            if name not in FMUS:
                return f"its model '{name}' is not one of this project's Python FMUs"
            ours = slave_class(name)(instance_name=name).to_xml()
            for section in _DECLARATIONS:
                if _canonical(declared.find(section)) != _canonical(ours.find(section)):
                    return (f"its {section} differ from those of this project's '{name}' "
                            f"(another FMU of that name, or ours before a change: {BUILD_HINT})")
            script = Path(FMUS[name][0])
            module = fmu.read("resources/slavemodule.txt").decode().strip()
            if module != script.stem:
                return (f"its slave is {module}.py, not this project's {script.name} "
                        f"(another FMU of the name '{name}')")
            for entry in fmu.namelist():
                relative = entry.removeprefix("resources/")
                if relative == entry or not relative.endswith(".py") \
                        or relative.startswith("pythonfmu/"):     # pythonfmu's own
                    continue
                here = _source_here(relative, script)
                if here is None:
                    return (f"it carries {relative}, which this project's '{name}' does not "
                            "(another FMU of that name)")
                if not here.is_file() or here.read_bytes() != fmu.read(entry):
                    return (f"it was built from other sources than this process runs "
                            f"({relative} differs: another FMU of that name, or ours "
                            f"before a change: {BUILD_HINT})")
    except (OSError, KeyError, UnicodeDecodeError, zipfile.BadZipFile,
            ElementTree.ParseError) as error:
        return f"it cannot be read as an FMU ({type(error).__name__}: {error})"
    return None


_DECLARATIONS = ("ModelVariables", "UnitDefinitions", "ModelStructure")


def _canonical(element: ElementTree.Element | None) -> str:
    return "" if element is None else ElementTree.canonicalize(ElementTree.tostring(element),
                                                               strip_text=True)


def _source_here(relative: str, script: Path) -> Path | None:
    """This process's file for a Python source an FMU carries: its slave script, or a module
    of this project's packages; None for anything else."""
    if relative == script.name:
        return ROOT / script
    package = relative.split("/", 1)[0]
    return ROOT / relative if "/" in relative and package in _PACKAGES else None


_PACKAGES = {p for _, packages in FMUS.values() for p in packages}


class InProcessInstance(Instance):
    """A slave class instantiated and driven in this process."""

    def __init__(self, path: str | Path, name: str, same_sources: bool = True):
        """The class of the FMU at ``path``; ValueError if it cannot run in-process
        (``in_process_refusal``), or, without ``same_sources``, only if it is not one of
        ours (``cosim.studies.direct``: the modules as they are, whatever the FMU)."""
        self.path, self.name = Path(path), name
        description = _description(self.path)
        self.model_name, self.guid = description.get("modelName"), description.get("guid")
        refusal = in_process_refusal(self.path)
        if refusal and (same_sources or self.model_name not in FMUS):
            raise ValueError(f"FMU '{name}' ({self.path.name}) cannot run in-process: "
                             f"{refusal}")
        self.slave = slave_class(self.model_name)(instance_name=name)
        self.variables = {}
        for vr, var in self.slave.registry.by_vr.items():
            self.variables[var.name] = VariableInfo(var.name, vr, _FMI_TYPE[var.kind],
                                                    var.causality,
                                                    var.unit if var.is_real else "")
        inputs = {v.name for v in self.slave.variables if v.causality == "input"}
        self.feedthrough = {v.name: frozenset(v.depends) & inputs
                            for v in self.slave.variables if v.causality == "output"}

    def call(self, what: str, function, *args, time: float | None = None,
             strict: bool = False) -> Any:
        """Call a slave method; an exception, a refused step or (``strict``) an error logged
        becomes FmuCallError."""
        try:
            result = function(*args)
        except Exception as error:
            raise self._failure(what, time, error) from error
        if result is False or self.slave.log_queue:
            self._judge(what, time, result, strict)
        return result

    def _failure(self, what: str, time: float | None, error: Exception) -> FmuCallError:
        return FmuCallError(self.name, what, time, "fatal",      # as pythonfmu logs it
                            [*self._drain(), f"[fatal] {unnamed(self.name, explain(error))}"])

    def _judge(self, what: str, time: float | None, result: Any, strict: bool) -> None:
        """FmuCallError if a call refused (returned False) or, ``strict``, logged an error;
        the log is drained either way."""
        messages = self._drain()
        if result is False:
            raise FmuCallError(self.name, what, time, "discard", messages)
        if strict and logged_error(messages):
            raise FmuCallError(self.name, what, time, "OK but logged an error", messages)

    def _drain(self) -> list[str]:
        messages = [f"[{m.status.name}] {unnamed(self.name, m.msg)}"
                    for m in self.slave.log_queue]
        self.slave.log_queue.clear()
        return messages

    def fmi(self, name: str):
        """The slave method behind an FMI call name: setReal -> set_real."""
        return getattr(self.slave, _method_name(name))

    # Prepared calls: the slave's own plans, valid until ``reset`` makes a new slave.
    def reader(self, vrs: list[int]):
        return self._prepared(self.slave.plans.real_reader(vrs), super().reader(vrs))

    def integer_reader(self, vrs: list[int]):
        return self._prepared(self.slave.plans.integer_reader(vrs), super().integer_reader(vrs))

    @staticmethod
    def _prepared(plan, through_fmi):
        """The slave's plan for a read; through the FMI entry where it has none (the slave
        names the problem) or where the plan raises (to report it as FMI would)."""
        if plan is None:
            return through_fmi

        def read() -> list:
            try:
                return plan()
            except Exception:
                return through_fmi()
        return read

    def writer(self, vrs: list[int]):
        write = self.slave.plans.input_writer(vrs)
        return super().writer(vrs) if write is None else write

    def stepper(self):
        do_step, queue = unguarded(self.slave.do_step), self.slave.log_queue

        def step(t: float, h: float) -> None:
            try:
                done = do_step(t, h)
            except Exception as error:
                raise self._failure("doStep", t, error) from error
            if done is not True or queue:
                self._judge("doStep", t, done, False)
        return step

    def enter_initialization(self, start_time: float = 0.0) -> None:
        self.call("setupExperiment", self.slave.setup_experiment, start_time)
        self.call("enterInitializationMode", self.slave.enter_initialization_mode)

    def reset(self) -> None:
        """A fresh slave object, as pythonfmu's fmi2Reset makes one."""
        self.slave = type(self.slave)(instance_name=self.name)

    def free(self) -> None:
        """Terminate, if the slave was initialised (as fmi2FreeInstance may follow any call)."""
        if self.slave.sequence.phase == "step":
            self.slave.terminate()


def _description(path: Path) -> ElementTree.Element:
    """The root of an FMU's modelDescription.xml."""
    with zipfile.ZipFile(path) as fmu:
        return ElementTree.fromstring(fmu.read("modelDescription.xml"))


@cache
def _method_name(fmi_name: str) -> str:
    return re.sub(r"(?<!^)([A-Z])", r"_\1", fmi_name).lower()
