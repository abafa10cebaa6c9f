"""Does a run depend on the CPU? The same run in a child process under other CPUs' numpy
dispatch, OpenBLAS kernels and libm FMA variants (read at start-up), compared on its CSV's bytes."""
from __future__ import annotations

import json
import os
import tempfile
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

import numpy as np

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
