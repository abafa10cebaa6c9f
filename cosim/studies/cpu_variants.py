"""Does a run depend on the CPU? The same run in a child process under other CPUs' numpy
dispatch, OpenBLAS kernels and libm FMA variants (read at start-up), compared on its CSV's bytes;
and how many of its digits mean something (``spread``): the largest change of each figure of
eq (19) with u0 and psi_w moved by a few ulps, as a CPU that rounds otherwise could move it."""
from __future__ import annotations

import json
import math
import os
import tempfile
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from ..analysis.metrics import LAMBDA, Cost, cost
from ..core.master import Master
from ..core.ssd import SystemDescription
from . import in_child, table

_AVX512 = "AVX512F AVX512CD AVX512_SKX AVX512_CLX AVX512_CNL AVX512_ICL AVX512_SPR X86_V4"
VARIANTS: dict[str, dict[str, str]] = {     # "default": this machine as it is
    "default": {},
    "numpy without AVX-512": {"NPY_DISABLE_CPU_FEATURES": _AVX512},
    "numpy at its baseline": {"NPY_DISABLE_CPU_FEATURES": f"X86_V3 AVX2 FMA3 {_AVX512}"},
    "OpenBLAS Haswell": {"OPENBLAS_CORETYPE": "Haswell"},
    "OpenBLAS SkylakeX": {"OPENBLAS_CORETYPE": "SkylakeX"},
    "OpenBLAS Zen": {"OPENBLAS_CORETYPE": "Zen"},
    "OpenBLAS Sandybridge": {"OPENBLAS_CORETYPE": "Sandybridge"},
    "OpenBLAS Prescott": {"OPENBLAS_CORETYPE": "Prescott"},
    "glibc without FMA": {"GLIBC_TUNABLES": "glibc.cpu.hwcaps=-AVX2,-FMA"},
}
TIMEOUT = 300.0         # s: the most one child run may take
FIGURES = ("psi_E", "delta_E", "J")
PERTURBED = (("ship", "u0"), ("ship", "psi_w"))     # moved by a few ulps, one at a time

_CHILD = ("import json, sys; from cosim import simulate; simulate(sys.argv[1], stop_time="
          "json.loads(sys.argv[3]), backend='inprocess').write_csv(sys.argv[2])")


def difference(a: Path, b: Path) -> str | None:
    """None if two CSVs are the same bytes; else where they first differ."""
    if a.read_bytes() == b.read_bytes():
        return None
    header = a.read_text().split("\n", 1)[0].split(",")
    x, y = (np.loadtxt(p, delimiter=",", skiprows=1, ndmin=2) for p in (a, b))
    if x.shape != y.shape:
        return f"{len(x)} rows against {len(y)}"
    rows, columns = np.nonzero(x != y)
    first = int(np.argmin(rows))
    return (f"from t = {x[rows[first], 0]:g} s ({header[columns[first]]}), "
            f"{len(set(columns.tolist()))} of {len(header)} columns")


def audit(scenario_names: list[str], variants: list[str] | None = None,
          stop_time: float | None = None) -> dict[str, dict[str, str | None]]:
    """{scenario: {variant: difference from "default"}}, each run in a child process."""
    variants = [v for v in (variants or list(VARIANTS)) if v != "default"]
    with tempfile.TemporaryDirectory(prefix="cosim-cpus-") as folder, \
            ThreadPoolExecutor(2) as pool:
        def run(scenario: str, variant: str) -> Path:
            csv = Path(folder) / f"{scenario} {variant}.csv"
            in_child(f"{scenario} under {variant!r}", _CHILD, scenario, str(csv),
                     json.dumps(stop_time), env={**os.environ, **VARIANTS[variant]},
                     timeout=TIMEOUT)
            return csv
        jobs = [(s, v) for s in scenario_names for v in ["default", *variants]]
        paths = dict(zip(jobs, pool.map(lambda job: run(*job), jobs)))
        return {s: {v: difference(paths[(s, "default")], paths[(s, v)]) for v in variants}
                for s in scenario_names}


def audit_table(results: dict[str, dict[str, str | None]]) -> str:
    """The audit as a Markdown table: 'same' or where the run first differs."""
    return "\n".join(table(["scenario", *next(iter(results.values()))], (
        [scenario, *("same" if d is None else f"differs {d}" for d in by_variant.values())]
        for scenario, by_variant in results.items())))


def nudged(value: float, ulps: int) -> float:
    """``value`` moved by ``ulps`` units in the last place (toward -inf for ulps < 0)."""
    direction = math.copysign(math.inf, ulps)
    for _ in range(abs(ulps)):
        value = math.nextafter(value, direction)
    return value


@dataclass(frozen=True)
class Spread:
    """How far one last bit moves each figure of eq (19): the run's value and the largest
    change from it (not the range: another CPU's run may diverge either way)."""

    runs: int
    nominal: dict[str, float]       # figure: the unperturbed run's value
    deviation: dict[str, float]     # figure: the largest |member - nominal|

    def describe(self) -> str:
        """'psi_E 472.76 +- 18.67, J 612.45 +- 20.18': the figures whose value +- deviation
        shows at 2 decimals; or 'every figure as printed'."""
        value, change = self.nominal, self.deviation
        wide = [f"{f} {value[f]:.2f} +- {change[f]:.2f}" for f in FIGURES
                if f"{value[f] - change[f]:.2f}" != f"{value[f] + change[f]:.2f}"]
        return ", ".join(wide) or "every figure as printed"


def spread(system: SystemDescription, overrides: dict[str, dict[str, Any]] | None = None,
           ulps: int = 20, lam: float = LAMBDA, coupling: str = "gauss-seidel",
           stop_time: float | None = None) -> Spread:
    """The run and those with each of ``PERTURBED`` moved by -ulps ... +ulps, in-process;
    ValueError if the system lacks one; RuntimeError naming a failed run."""
    overrides = overrides or {}
    members = [(None, 0), *((p, k) for p in PERTURBED for j in range(1, ulps + 1) for k in (-j, j))]
    costs: list[Cost] = []
    with Master(system, coupling=coupling, backend="inprocess", overrides=overrides) as master:
        for component, name in PERTURBED:
            instance = master.instances.get(component)
            if instance is None or name not in instance.variables:
                raise ValueError(f"spread: the system {system.name!r} has no "
                                 f"{component}.{name} to perturb")
        held: dict[str, dict[str, Any]] = {}     # the values the unperturbed run used
        for parameter, k in members:
            if parameter is not None:
                component, name = parameter
                value = nudged(float(held[component][name]), k)
                master.configure({**overrides, component: {**overrides.get(component, {}),
                                                           name: value}})
                master.reset()
            recording = master.run(stop_time)
            if recording.error:
                moved = f"{'.'.join(parameter)} moved by {k} ulp" if parameter else "nominal"
                raise RuntimeError(f"spread: the run ({moved}) failed: {recording.error}")
            if parameter is None:
                held = master.parameter_values
            costs.append(cost(recording, lam))
    nominal = {f: getattr(costs[0], f) for f in FIGURES}
    deviation = {f: max(abs(getattr(c, f) - nominal[f]) for c in costs) for f in FIGURES}
    return Spread(len(costs), nominal, deviation)
