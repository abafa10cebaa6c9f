"""What a new user reads when bringing an autopilot of their own: every message names the
input it refuses and says what was expected (issue 27).

Each test builds a small FMU of its own into the test's folder, as a user would, from a
script written here.
"""
from __future__ import annotations

import textwrap
from pathlib import Path

import pytest

from cosim import simulate
from cosim.api import SimulationError
from fmubuild.packaging import build_script

FAILING_PILOT = '''\
"""A PD autopilot of a user's own that divides by zero once t reaches t_fail."""
from fmukit.autopilot import INPUTS, rudder_command
from fmukit.slave import ModelSlave, Var


class Law:
    def __init__(self, t_fail: float):
        self.t_fail = t_fail

    def do_step(self, t: float) -> None:
        if t >= self.t_fail:
            print(1.0 / 0.0)

    def snapshot(self) -> dict:
        return {}

    def restore(self, saved: dict) -> None:
        pass


class FailingPilot(ModelSlave):
    model_name = "failing_pilot"
    description = "a user's autopilot with a bug"
    variables = (*INPUTS,
                 rudder_command(("psi", "psi_d"), lambda s: 2.0 * (s.psi - s.psi_d)),
                 Var.parameter("t_fail", 1.0, "s", "when it divides by zero", 0.0, 1e6))

    def build_model(self) -> Law:
        return Law(self.t_fail)

    def step_model(self, t: float, h: float) -> None:
        self.model.do_step(t)
'''


def _script(folder: Path, name: str, text: str) -> Path:
    folder.mkdir(parents=True, exist_ok=True)
    script = folder / name
    script.write_text(textwrap.dedent(text))
    return script


def _line_of(script: Path, text: str) -> int:
    """The number of the line of ``script`` that holds ``text``."""
    return next(i for i, line in enumerate(script.read_text().splitlines(), 1) if text in line)


@pytest.fixture(scope="module")
def failing_pilot(tmp_path_factory) -> Path:
    folder = tmp_path_factory.mktemp("failing")
    return build_script(_script(folder, "failing_pilot.py", FAILING_PILOT), ("fmukit",), folder)


@pytest.mark.timeout(300)
def test_an_exception_in_a_users_fmu_names_their_file_and_line(fmu_paths, failing_pilot):
    with pytest.raises(SimulationError) as failed:
        simulate("calm_pd", autopilot=failing_pilot, stop_time=3.0)
    line = _line_of(failing_pilot.with_name("failing_pilot.py"), "1.0 / 0.0")
    message = str(failed.value)
    assert (f"failing_pilot.py:{line} in do_step: ZeroDivisionError: float division by zero"
            in message), message
    assert "Traceback" not in message and "slave.py" not in message
