"""Saved FMU states: get and set FMU state (fmi2GetFMUstate, fmi3GetFMUState, ...) and their
serialised form.

A state is a plain dict that pythonfmu (and pythonfmu3) serialises as JSON: the phase of
the call sequence, the value of every parameter and input, the model's own
``snapshot()`` (None while there is no model), and why the FMU failed, if it has
(FMI 3.0's adapter adds its independent variable ``time``). Restoring rebuilds the
model from the restored parameters and hands it the snapshot, so a restored run
continues bit for bit.
"""
from __future__ import annotations

import json
from typing import Any

_KEYS = {"phase", "values", "model"}


def capture(slave: Any) -> dict[str, Any]:
    """The whole state of a ``ModelSlave``."""
    return {
        "phase": slave.sequence.phase,
        "values": {v.name: getattr(slave, v.name) for v in slave.variables
                   if v.causality != "output"},
        "model": slave._model.snapshot() if slave._model is not None else None,
        "failure": slave.failure,
        "failure_cause": slave.failure_cause,
    }


def restore(slave: Any, state: dict[str, Any]) -> None:
    """Return a ``ModelSlave`` to a captured state; ValueError if it is not one."""
    if "invalid" in state:
        raise ValueError(f"cannot restore FMU state: {state['invalid']}")
    for name, value in state["values"].items():
        setattr(slave, name, value)
    slave.sequence.phase = state["phase"]
    slave.failure = state.get("failure")
    slave.failure_cause = state.get("failure_cause", "model")
    slave._model = None
    if state["model"] is not None:
        slave._model = slave.build_model()
        slave._model.restore(state["model"])


def decode(data: bytes) -> dict[str, Any]:
    """A serialised state, or ``{"invalid": why}`` for ``restore`` to refuse.

    pythonfmu calls the decoder on the class, where an exception cannot be made
    safe (``fmukit.entry``): the problem travels in the state instead.
    """
    try:
        decoded = json.loads(data.decode("utf-8"))
        if not _KEYS <= set(decoded):
            raise ValueError("not a state of this FMU")
        return decoded
    except (ValueError, UnicodeDecodeError, TypeError) as error:
        return {"invalid": f"serialized state unreadable ({error})"}
