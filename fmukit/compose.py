"""An FMU's class composed in code, as its entry module defines it, for a host that runs the
model in its own process (it uses ``registry``, ``plans`` and ``fmukit.entry.unguarded``)."""
from __future__ import annotations

import functools
import importlib

from .slave import ModelSlave

ADAPTERS = {2: "fmukit.pythonfmu07.slave", 3: "fmukit.pythonfmu3_03.slave"}   # FMI version: adapter


@functools.cache
def fmu_class(model: type[ModelSlave], fmi: int) -> type[ModelSlave]:
    """The FMI ``fmi`` (2 or 3) FMU class of ``model``; ValueError for another version."""
    if fmi not in ADAPTERS:
        raise ValueError(f"FMI {fmi} is not one fmukit builds; it builds "
                         f"{' and '.join(f'FMI {v}.0' for v in ADAPTERS)}")
    adapter = importlib.import_module(ADAPTERS[fmi])
    bases = (getattr(adapter, f"Fmi{fmi}Entry"), model, getattr(adapter, f"Fmi{fmi}Slave"))
    return type(model.__name__, bases, {"__module__": model.__module__,
                                        "__qualname__": model.__qualname__})
