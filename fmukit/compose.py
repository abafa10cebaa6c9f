"""An FMU's class composed in code, for a host that runs the model in its own process.

    from fmukit.compose import fmu_class
    slave = fmu_class(PDAutopilotSlave, 3)(instance_name="pd")   # FMI 3.0's class

``ModelSlave`` is not an FMU by itself: it is FMI-version neutral. ``fmu_class(model,
fmi)`` is the class that the FMU's entry module (written by the build:
``resources/<model_name>_fmi<fmi>.py``, named in ``slavemodule.txt`` and the manifest)
defines, ``class <Model>(Fmi<fmi>Entry, <Model>, Fmi<fmi>Slave)``: the adapter's mixin
(``fmukit.pythonfmu07.slave`` for FMI 2.0, ``fmukit.pythonfmu3_03.slave`` for FMI 3.0),
the model's class, pythonfmu's slave class. The same model and version give the same
class. Instantiated without pythonfmu's ``logger`` keyword, the slave knows its host is
in this process: it logs to ``log_queue`` only, never to standard error.

What both versions' instances offer such a host:

- ``registry.by_vr``: the declared variables (``fmukit.variables.Var``) by value
  reference, which the master uses in place of the model description. FMI 3.0's value
  references are FMI 2.0's plus one: FMI 3.0's independent variable ``time`` is value
  reference 0, and is not a declared variable (it is not in the registry);
- ``plans`` (``fmukit.fastpath``), ``sequence.phase``, ``failure``, ``variables``;
- ``fmukit.entry.unguarded(slave.do_step)``: the step without its FMI guard, which
  raises ``fmukit.refusals.Refused`` for every refusal, in both versions;
- ``log_queue``: pythonfmu's log messages (``status``, ``category``, ``msg``), which
  the host clears;
- ``TYPE_NAMES`` (Python type: the FMI type's name) and ``FMI_VERSION`` (2 or 3).

The calls, by version:

- FMI 2.0 (pythonfmu 0.7): ``setup_experiment(start_time)``,
  ``enter_initialization_mode()``, ``exit_initialization_mode()``, ``do_step(t, h)``
  (True, or an exception: fmi2Fatal), ``terminate()``, ``get_real``/``set_real``,
  ``get_integer``/``set_integer``, ``get_string``/``set_string``; statuses
  ``Fmi2Status``;
- FMI 3.0 (pythonfmu3 0.3.4): no ``setup_experiment`` (pythonfmu3 drops the start
  time of fmi3EnterInitializationMode, so the FMU's messages name none),
  ``enter_initialization_mode()``, ``exit_initialization_mode()``, ``do_step(t, h)``
  returning ``Fmi3StepResult`` whose ``status`` is ``Fmi3Status.ok``, or
  ``Fmi3Status.error`` for a refused step (logged, non-fatal; every other refusal is an
  exception: fmi3Fatal), ``terminate()``, ``get_float64``/``set_float64``,
  ``get_int32``/``set_int32``, ``get_string``/``set_string``; statuses ``Fmi3Status``.

A refusal's message has the category ``fmukit.<cause>`` (``fmukit.refusals.CAUSES``) in
both; pythonfmu's own messages name their status (``logStatusFatal``).
"""
from __future__ import annotations

import importlib

from .slave import ModelSlave

ADAPTERS = {2: "fmukit.pythonfmu07.slave", 3: "fmukit.pythonfmu3_03.slave"}
"""FMI version: the adapter module whose ``on_fmi<version>`` composes the class."""


def fmu_class(model: type[ModelSlave], fmi: int) -> type[ModelSlave]:
    """The FMI ``fmi`` (2 or 3) FMU class of ``model``, as its FMU's entry module defines it;
    ValueError for another version."""
    if fmi not in ADAPTERS:
        raise ValueError(f"FMI {fmi} is not one fmukit builds; it builds "
                         f"{' and '.join(f'FMI {v}.0' for v in ADAPTERS)}")
    adapter = importlib.import_module(ADAPTERS[fmi])
    return getattr(adapter, f"on_fmi{fmi}")(model)
