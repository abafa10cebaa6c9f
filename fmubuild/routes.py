"""The FMI versions fmubuild builds, each with its pythonfmu through its fmukit adapter.

A ``Route`` says, for one FMI version, which pythonfmu builds it (pythonfmu 0.7.0 for
FMI 2.0, pythonfmu3 0.3.4 for FMI 3.0: the one version its adapter knows, the
adapter's ``ACTIVE``; the build refuses any other), the options its builder gets, where
its FMU keeps the Linux binary (which ``exit_fix`` patches), where the FMUs of the
project go, and the entry module the build writes into each FMU.

The slave scripts are the same for both versions: a ``ModelSlave`` is no pythonfmu
class (``fmukit.slave``). The entry module, ``<model_name>_fmi<N>.py`` beside the
script in the FMU's resources and named in ``slavemodule.txt``, defines the FMU's class:
the slave class composed with the adapter's mixin and pythonfmu's slave class, under
the slave class's own name (``fmukit.compose.fmu_class`` composes the same in code).
It is what each pythonfmu looks for: pythonfmu 0.7 takes the module's Fmi2Slave
subclass with the longest MRO, pythonfmu3 the first class whose ``class`` line names
Fmi3Slave between its parentheses (a regular expression, in its builder and again in
its C++ at instantiation), which a slave script's ``class X(ModelSlave)`` is not.
"""
from __future__ import annotations

import importlib
from dataclasses import dataclass
from pathlib import Path

from .project import FMU_DIRS

_ENTRY = '''"""The FMI {fmi}.0 entry of the FMU {model_name}, written by fmubuild.routes: {cls}
of {module} as an FMI {fmi}.0 co-simulation FMU of {pythonfmu} {known}."""
from {pythonfmu} import {base}

from {adapter}.slave import {imported}
from {module} import {cls} as _Model
{calls}

class {cls}({mixin}, _Model, {base}):
    """{cls} of {module}, on FMI {fmi}.0."""
'''


@dataclass(frozen=True)
class Route:
    """How an FMU of one FMI version is built."""

    fmi: int
    pythonfmu: str                  # the package that builds it (its import name)
    known: str                      # the one version of it that the adapter knows
    adapter: str                    # fmukit's adapter package
    options: dict[str, bool]        # the builder's options (FMI 2.0 and 3.0 spell them apart)
    linux_binaries: str             # the folder of the FMU's Linux binary
    namespace_calls: tuple[str, ...] = ()   # functions of the adapter's slave module that
                                            # the entry module calls on its globals()

    @property
    def dest(self) -> Path:
        """Where this project's FMUs of this version are built."""
        return FMU_DIRS[self.fmi]

    def gate(self) -> str:
        """The installed version of this route's pythonfmu; RuntimeError unless it is the
        one the adapter knows, whose defects it compensates."""
        adapter = importlib.import_module(self.adapter)
        installed = adapter.PYTHONFMU_VERSION
        if not adapter.ACTIVE:
            raise RuntimeError(f"{self.pythonfmu} {installed} is installed; fmukit builds FMI "
                               f"{self.fmi}.0 FMUs with {self.pythonfmu} {self.known} only, "
                               f"whose defects {self.adapter} compensates (pip install "
                               f"{self.pythonfmu}=={self.known}, or check the new version and "
                               f"extend {self.adapter})")
        return installed

    def entry_module(self, model_name: str) -> str:
        """The name of the FMU's entry module."""
        return f"{model_name}_fmi{self.fmi}"

    def entry_source(self, model_name: str, module: str, cls: str) -> str:
        """The entry module's source: ``cls`` of ``module`` (as the FMU imports it) composed
        for this version."""
        mixin = f"Fmi{self.fmi}Entry"
        return _ENTRY.format(fmi=self.fmi, model_name=model_name, module=module, cls=cls,
                             pythonfmu=self.pythonfmu, known=self.known, adapter=self.adapter,
                             base=f"Fmi{self.fmi}Slave", mixin=mixin,
                             imported=", ".join([mixin, *self.namespace_calls]),
                             calls="".join(f"{call}(globals())\n"
                                           for call in self.namespace_calls))


ROUTES = {
    # hold_namespace: pythonfmu 0.7 releases the entry module's namespace once per
    # instantiation (fmukit.pythonfmu07.slave.hold_namespace).
    2: Route(2, "pythonfmu", "0.7.0", "fmukit.pythonfmu07",
             {"canGetAndSetFMUstate": True, "canSerializeFMUstate": True}, "binaries/linux64/",
             ("hold_namespace",)),
    # canHandleVariableCommunicationStepSize: pythonfmu3 0.3.4 writes the value of another
    # option for it (a loop variable left over); given, its builder writes it.
    3: Route(3, "pythonfmu3", "0.3.4", "fmukit.pythonfmu3_03",
             {"canGetAndSetFMUState": True, "canSerializeFMUState": True,
              "canHandleVariableCommunicationStepSize": True}, "binaries/x86_64-linux/"),
}
"""FMI version: its route."""
