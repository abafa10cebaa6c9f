"""Saved FMU states as plain dicts (pythonfmu serialises them as JSON). Restoring rebuilds
the model from the parameters and hands it its ``snapshot()``: the run continues bit for bit.
"""
from __future__ import annotations

import json
from typing import Any


def capture(slave: Any) -> dict[str, Any]:
    """The whole state of a ``ModelSlave``: phase, variables but outputs, model, failure."""
    return {"phase": slave.sequence.phase,
            "values": {v.name: getattr(slave, v.name) for v in slave.vars.values()
                       if v.causality.name != "output"},
            "model": slave._model.snapshot() if slave._model is not None else None,
            "failure": slave.failure, "failure_cause": slave.failure_cause}


def restore(slave: Any, state: dict[str, Any]) -> None:
    """Return a ``ModelSlave`` to a captured state; ValueError if it is not one."""
    if "invalid" in state:
        raise ValueError(f"cannot restore FMU state: {state['invalid']}")
    for name, value in state["values"].items():
        setattr(slave, name, value)
    slave.sequence.phase = state["phase"]
    slave.failure, slave.failure_cause = state.get("failure"), state.get("failure_cause", "model")
    slave._model = None
    if state["model"] is not None:
        slave._model = slave.build_model()
        slave._model.restore(state["model"])


def decode(data: bytes) -> dict[str, Any]:
    """A serialised state, or ``{"invalid": why}`` for ``restore`` to refuse (pythonfmu
    calls this on the class, where an exception cannot be made safe)."""
    try:
        decoded = json.loads(data.decode("utf-8"))
        if not {"phase", "values", "model"} <= set(decoded):
            raise ValueError("not a state of this FMU")
        return decoded
    except (ValueError, UnicodeDecodeError, TypeError) as error:
        return {"invalid": f"serialized state unreadable ({error})"}
