"""A sweep's rows as tables: results.parquet, .csv and .json, the printed summary, and
comparison.md (every controller against the baseline, seed by seed)."""
from __future__ import annotations

import itertools
import json
from pathlib import Path

import numpy as np

from ..core.files import write_atomically
from .sweep_spec import Spec
from .sweep_task import METRICS


def write_tables(rows: list[dict], out: Path, csv: bool) -> list[Path]:
    """results.parquet (each metric's unit in its field metadata), results.csv with ``csv``,
    and results.json: the unit of every column."""
    import pyarrow as pa
    import pyarrow.csv as pacsv
    import pyarrow.parquet as pq

    table = pa.Table.from_pylist([{k: (json.dumps(v) if isinstance(v, (list, dict)) else v)
                                   for k, v in row.items() if k != "track"} for row in rows])
    units = {name: METRICS.get(name, "s" if name == "seconds" else "")
             for name in table.column_names}
    table = table.cast(pa.schema([field.with_metadata({"unit": units[field.name]})
                                  for field in table.schema]))
    written = [write_atomically(out / "results.parquet", lambda p: pq.write_table(table, p)),
               write_atomically(out / "results.json", lambda p: p.write_text(
                   json.dumps({"units": units}, indent=1) + "\n"))]
    if csv:
        written.append(write_atomically(out / "results.csv",
                                        lambda p: pacsv.write_csv(table, p)))
    return written


def summary(spec: Spec, rows: list[dict], shown_failures: int = 10) -> str:
    """Runs, ok and failed; J by controller; each failed run with its message."""
    ok = [r for r in rows if r["status"] == "ok"]
    lines = [f"{spec.name}: {len(rows)} runs, {len(ok)} ok, {len(rows) - len(ok)} failed"]
    for controller in spec.controllers:
        J = np.array([r["J"] for r in ok if r["controller"] == controller])
        if J.size:
            lines.append(f"  {controller:>14}: J median {np.median(J):9.2f}, mean {J.mean():9.2f}"
                         f", 5-95 % {np.percentile(J, 5):9.2f} - {np.percentile(J, 95):9.2f}"
                         f" ({J.size} runs)")
    failed = [r for r in rows if r["status"] != "ok"]
    for r in failed[:shown_failures]:
        axes = ", ".join(f"{a} = {r[a]}" for a in spec.axes)
        said = [line.strip() for line in r["error"].splitlines()[:2]]   # the call, the FMU's words
        lines.append(f"  failed {r['controller']} ({axes}): {' / '.join(said)[:300]}")
    if len(failed) > shown_failures:
        lines.append(f"  ... and {len(failed) - shown_failures} more failed runs (results.parquet "
                     "has every message)")
    return "\n".join(lines)


def comparison(spec: Spec, rows: list[dict], baseline: str = "pd",
               monte_carlo: str = "wave_seed") -> str:
    """Markdown table: per setting of the other axes, median J and wins against the baseline.

    Runs are paired by the Monte Carlo axis (the same sea for both controllers); a
    controller wins a pair when its J is lower. The share of wins and the median J
    ratio are given for every controller other than the baseline.
    """
    others = [c for c in spec.controllers if c != baseline]
    axes = [a for a in spec.axes if a != monte_carlo]
    ok = {(r["controller"], *(json.dumps(r[a]) for a in spec.axes)): r
          for r in rows if r["status"] == "ok"}
    header = [*axes, f"J {baseline}", *(f"J {c}" for c in others),
              *(f"{c} wins" for c in others), *(f"J {c} / J {baseline}" for c in others)]
    lines = ["| " + " | ".join(header) + " |", "|" + "---|" * len(header)]
    for setting in itertools.product(*(spec.axes[a] for a in axes)):
        where = dict(zip(axes, setting))
        seeds = spec.axes.get(monte_carlo, [None])

        def J(controller: str) -> np.ndarray:
            keys = [(controller, *(json.dumps(where.get(a, seed)) for a in spec.axes))
                    for seed in seeds]
            return np.array([ok[k]["J"] if k in ok else np.nan for k in keys])

        def median(values: np.ndarray) -> str:
            return f"{np.nanmedian(values):.1f}" if np.isfinite(values).any() else "-"

        base = J(baseline)
        cells = [str(v) for v in setting] + [median(base)]
        wins, ratios = [], []
        for controller in others:
            J_c = J(controller)
            cells.append(median(J_c))
            decided = np.isfinite(J_c) & np.isfinite(base) & (J_c != base)
            wins.append(f"{int(np.sum(J_c[decided] < base[decided]))}/{int(decided.sum())}")
            defined = np.isfinite(J_c) & (base > 1e-9)
            ratios.append(f"{np.median(J_c[defined] / base[defined]):.2f}" if defined.any()
                          else "-")
        lines.append("| " + " | ".join(cells + wins + ratios) + " |")
    return "\n".join(lines)
