"""A learned autopilot (``cosim.train``): delta_c from the heading error e = psi - psi_d
(wrapped, as in eq 20) and the yaw rate r through a small network, tanh hidden layers and
a linear output. Its sums run in one fixed order of + and *, so a float and a numpy array
of many policies' weights give the same bits (docs/rl.md)."""
from __future__ import annotations

import json
import math
from dataclasses import dataclass
from typing import Any, Callable, Sequence

from fmukit.numerics import wrap

FEATURES = ("e", "r")           # what an autopilot's ports give: rad, rad/s


@dataclass(frozen=True)
class Policy:
    layers: tuple               # ((rows of weights, biases), ...): tanh between, linear out
    scale: tuple = (1.0, 1.0)   # e and r are divided by these first (rad, rad/s)

    @staticmethod
    def sizes(hidden: Sequence[int]) -> list[tuple[int, int]]:
        """(inputs, outputs) of each layer of a network with ``hidden`` tanh layers."""
        widths = [len(FEATURES), *hidden, 1]
        return list(zip(widths[:-1], widths[1:]))

    @classmethod
    def count(cls, hidden: Sequence[int]) -> int:
        """The parameters (weights and biases) of a network with ``hidden`` tanh layers."""
        return sum(n_in * n_out + n_out for n_in, n_out in cls.sizes(hidden))

    @classmethod
    def from_vector(cls, theta: Sequence, hidden: Sequence[int], scale: Sequence) -> Policy:
        """The network of the parameters ``theta`` (each a float, or an array: many)."""
        if cls.count(hidden) != len(theta):
            raise ValueError(f"a policy with hidden layers {list(hidden)} has "
                             f"{cls.count(hidden)} parameters, not {len(theta)}")
        layers, at = [], 0
        for n_in, n_out in cls.sizes(hidden):
            rows = tuple(tuple(theta[at + j * n_in:at + (j + 1) * n_in]) for j in range(n_out))
            at += n_in * n_out
            layers.append((rows, tuple(theta[at:at + n_out])))
            at += n_out
        return cls(tuple(layers), tuple(scale))

    @classmethod
    def from_json(cls, text: str) -> Policy:
        """ValueError saying what is wrong with ``text`` (``to_json``'s form)."""
        try:
            data = json.loads(text)
            theta = [float(x) for x in data["theta"]]
            policy = cls.from_vector(theta, [int(n) for n in data["hidden"]],
                                     [float(x) for x in data["scale"]])
        except (ValueError, KeyError, TypeError) as error:
            raise ValueError(f"parameter policy: not a policy's JSON ({type(error).__name__}: "
                             f"{error})") \
                from None
        if len(policy.scale) != len(FEATURES) or not all(
                math.isfinite(x) for x in (*theta, *policy.scale)) or min(policy.scale) <= 0:
            raise ValueError("parameter policy: its weights must be finite and its scales > 0")
        return policy

    def to_json(self, **about: Any) -> str:
        theta = [x for rows, biases in self.layers for x in (*sum(rows, ()), *biases)]
        hidden = [len(biases) for _, biases in self.layers[:-1]]
        return json.dumps({"hidden": hidden, "scale": list(self.scale),
                           "theta": [float(x) for x in theta], **about})

    def act(self, e: Any, r: Any, tanh: Callable = math.tanh) -> Any:
        """delta_c, rad, of e (rad) and r (rad/s); ``tanh`` for arrays: one exact per element."""
        layer = [e / self.scale[0], r / self.scale[1]]
        for depth, (rows, biases) in enumerate(self.layers):
            out = []
            for row, bias in zip(rows, biases):
                total = bias
                for weight, x in zip(row, layer):
                    total = total + weight * x
                out.append(total)
            layer = out if depth == len(self.layers) - 1 else [tanh(x) for x in out]
        return layer[0]

    def command(self, psi: float, r: float, psi_d: float) -> float:
        return self.act(wrap(psi - psi_d), r)

    def snapshot(self) -> dict:
        return {}                           # memoryless

    def restore(self, snapshot: dict) -> None:
        pass
