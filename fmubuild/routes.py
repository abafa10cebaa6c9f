"""The FMI versions fmubuild builds, each by the one pythonfmu version its adapter knows, and
the entry module written into each FMU: the slave class composed as ``fmukit.compose`` does."""
from __future__ import annotations

from dataclasses import asdict, dataclass
from pathlib import Path

from fmukit.manifest import Manifest

_ENTRY = '''"""The FMI {fmi}.0 entry of the FMU {model_name}, written by fmubuild.routes: {cls}
of {module} as an FMI {fmi}.0 co-simulation FMU of {pythonfmu} {known}."""
from {pythonfmu} import Fmi{fmi}Slave

from {adapter}.slave import {imported}
from {module} import {cls} as _Model
{calls}

class {cls}(Fmi{fmi}Entry, _Model, Fmi{fmi}Slave):
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
    linux: str                      # the platform folder of the FMU's Linux binary
    namespace_calls: tuple[str, ...] = ()   # the entry module calls them on its globals()

    def entry_source(self, model_name: str, module: str, cls: str) -> str:
        """The entry module's source: ``cls`` of ``module`` composed for this version."""
        return _ENTRY.format(**asdict(self), model_name=model_name, module=module, cls=cls,
                             imported=", ".join([f"Fmi{self.fmi}Entry", *self.namespace_calls]),
                             calls="".join(f"{f}(globals())\n" for f in self.namespace_calls))


ROUTES = {
    # pythonfmu 0.7 releases the entry module's namespace once per instantiation.
    2: Route(2, "pythonfmu", "0.7.0", "fmukit.pythonfmu07",
             {"canGetAndSetFMUstate": True, "canSerializeFMUstate": True}, "linux64",
             ("hold_namespace",)),
    # canHandleVariableCommunicationStepSize given, else pythonfmu3 0.3.4 writes a stale value.
    3: Route(3, "pythonfmu3", "0.3.4", "fmukit.pythonfmu3_03",
             {"canGetAndSetFMUState": True, "canSerializeFMUState": True,
              "canHandleVariableCommunicationStepSize": True}, "x86_64-linux"),
}


def entry_source(manifest: Manifest) -> str:
    """The entry module this build writes for ``manifest``'s FMU."""
    module = Path(manifest.modules[manifest.slave_module]["file"]).stem
    return ROUTES[manifest.fmi].entry_source(manifest.model_name, module, manifest.slave_class)
