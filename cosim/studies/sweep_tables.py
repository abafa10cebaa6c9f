"""A sweep's rows as tables: results.parquet, .csv and .json, summary.csv and the printed
summary (per setting and controller, each run counted once), and comparison.md's table."""
from __future__ import annotations

import itertools
import json
import math
from pathlib import Path
from typing import Any

import numpy as np

from ..core.files import write_atomically
from .merit import METRICS
from .sweep_spec import Spec

TIMES = {"seconds": "s", "sim_seconds": "s"}    # the task's wall time; the run's (or its share)
MONTE_CARLO = "wave_seed"           # the axis statistics are taken over, that pairs runs
STATISTICS = ("median", "q25", "q75", "min", "max")     # of each figure, in summary.csv
MOST_PRINTED = 48                   # lines of the printed table, past which it pools axes
SHOWN_FAILURES = 10                 # failed runs the summary names


def headed(name: str, unit: str) -> str:
    """A column header with its unit: 'J [rad^2]'; the name alone where it has none."""
    return f"{name} [{unit}]" if unit else name


def write_tables(rows: list[dict], out: Path, csv: bool, spec: Spec) -> list[Path]:
    """results.parquet (units in its field metadata), results.csv if ``csv`` (units in its
    headers), results.json (every column's unit) and summary.csv; the paths."""
    import pyarrow as pa
    import pyarrow.csv as pacsv
    import pyarrow.parquet as pq

    table = pa.Table.from_pylist([{k: (json.dumps(v) if isinstance(v, (list, dict)) else v)
                                   for k, v in row.items() if k != "track"} for row in rows])
    known = {**spec.units(), **METRICS, **TIMES}
    unit = {name: known.get(name, "") for name in table.column_names}
    table = table.cast(pa.schema([field.with_metadata({"unit": unit[field.name]})
                                  for field in table.schema]))
    written = [write_atomically(out / "results.parquet", lambda p: pq.write_table(table, p)),
               write_atomically(out / "results.json", lambda p: p.write_text(
                   json.dumps({"units": unit}, indent=1) + "\n"))]
    if csv:
        with_units = table.rename_columns([headed(n, unit[n]) for n in table.column_names])
        written.append(write_atomically(out / "results.csv",
                                        lambda p: pacsv.write_csv(with_units, p)))
    header, *lines = summary_table(spec, rows)
    summary = pa.Table.from_pylist([dict(zip(header, line)) for line in lines])
    written.append(write_atomically(out / "summary.csv", lambda p: pacsv.write_csv(summary, p)))
    return written


def _settings(spec: Spec) -> tuple[list[str], list[dict[str, Any]]]:   # axes but MONTE_CARLO
    axes = [a for a in spec.axes if a != MONTE_CARLO]
    return axes, [dict(zip(axes, values))
                  for values in itertools.product(*(spec.axes[a] for a in axes))]


def select(rows: list[dict], controller: str, where: dict[str, Any]) -> list[dict]:
    """The rows of ``controller`` at the axis values ``where``."""
    return [r for r in rows if r["controller"] == controller
            and all(json.dumps(r[a]) == json.dumps(v) for a, v in where.items())]


def distinct(rows: list[dict]) -> list[dict]:
    """One row per run: a result shared by several combinations counts once."""
    return list({r.get("ran_as", r["run_id"]): r for r in rows}.values())


def _statistics(values: np.ndarray) -> list[float]:
    if not values.size:
        return [math.nan] * len(STATISTICS)
    return [float(v) for v in np.percentile(values, [50, 25, 75, 0, 100])]   # as STATISTICS


def summary_table(spec: Spec, rows: list[dict]) -> list[list]:
    """summary.csv: per setting and controller, the runs ok and failed, each ``STATISTICS``."""
    axes, settings = _settings(spec)
    lines = [[*axes, "controller", "runs ok", "runs failed",
              *(headed(f"{metric} {name}", unit) for metric, unit in METRICS.items()
                for name in STATISTICS)]]
    for where, controller in itertools.product(settings, spec.controllers):
        mine = distinct(select(rows, controller, where))
        ok = [r for r in mine if r["status"] == "ok"]
        lines.append([*where.values(), controller, len(ok), len(mine) - len(ok), *(
            value for metric in METRICS for value in _statistics(
                np.array([r[metric] for r in ok if metric in r], dtype=float)))])
    return lines


def summary(spec: Spec, rows: list[dict]) -> str:
    """Runs ok and failed, J per setting (or axis value) and controller, the failed runs."""
    runs = distinct(rows)
    ok = [r for r in runs if r["status"] == "ok"]
    shared = len(rows) - len(runs)
    axes, settings = _settings(spec)
    groups = [(" ".join(str(v) for v in where.values()), where) for where in settings]
    pooled = len(groups) * len(spec.controllers) > MOST_PRINTED
    if pooled:
        groups = [(f"{a} {v}", {a: v}) for a in axes for v in spec.axes[a]]
    per = "per value of each axis (pooled over the other axes)" if pooled else "per setting"
    over = f"over {MONTE_CARLO}; " if MONTE_CARLO in spec.axes else ""
    label = "setting" if pooled else " ".join(axes) or "all"
    wide = max(len(label), *(len(name) for name, _ in groups))
    named = max(len("controller"), *(len(c) for c in spec.controllers))
    lines = [f"{spec.name}: " + (f"{len(rows)} combinations in {len(runs)} runs ({shared} "
                                 "share an equivalent run's result)" if shared else
                                 f"{len(rows)} runs")
             + f", {len(ok)} ok, {len(runs) - len(ok)} failed",
             f"J of eq (19) [rad^2] {per} and controller: median, IQR (interquartile range, "
             f"25th to 75th percentile), least and greatest of its runs ok ({over}a run shared "
             "by several combinations counted once)"
             + ("; summary.csv has every setting" if pooled else ""),
             f"  {label:<{wide}}  {'controller':<{named}}  runs    median  "
             f"{'IQR':^19}  {'least - greatest':^19}".rstrip()]
    for (name, where), controller in itertools.product(groups, spec.controllers):
        J = np.array([r["J"] for r in select(ok, controller, where)], dtype=float)
        median, q25, q75, least, greatest = _statistics(J)
        lines.append(f"  {name:<{wide}}  {controller:<{named}}  {J.size:>4}  " + (
            f"{median:8.2f}  {q25:8.2f} - {q75:8.2f}  {least:8.2f} - {greatest:8.2f}"
            if J.size else f"{'-':>8}"))
    failed = [r for r in runs if r["status"] != "ok"]
    for r in failed[:SHOWN_FAILURES]:
        at = ", ".join(f"{a} = {r[a]}" for a in spec.axes)
        said = [line.strip() for line in r["error"].splitlines()[:2]]   # the call, the FMU's words
        lines.append(f"  failed {r['controller']} ({at}): {' / '.join(said)[:300]}")
    if len(failed) > SHOWN_FAILURES:
        lines.append(f"  ... and {len(failed) - SHOWN_FAILURES} more failed runs (results.parquet "
                     "has every message)")
    return "\n".join(lines)


def write_comparison(spec: Spec, rows: list[dict], out: Path) -> list[Path]:
    """comparison.md (where there are pd and others): per setting, each controller's median J,
    wins and J ratio to the PD; its path."""
    if "pd" not in spec.controllers or len(spec.controllers) == 1:
        return []
    others = [c for c in spec.controllers if c != "pd"]
    axes, settings = _settings(spec)
    ok = {(r["controller"], *(json.dumps(r[a]) for a in spec.axes)): r
          for r in rows if r["status"] == "ok"}
    header = [*axes, "J pd median", *(f"J {c} median" for c in others),
              *(f"{c} wins" for c in others), *(f"J {c} / J pd median" for c in others)]
    pairs = (f"paired by {MONTE_CARLO} (the same sea)" if MONTE_CARLO in spec.axes
             else "one run each")
    lines = [f"# {spec.name}: each controller against pd\n\nJ of eq (19) in rad^2, lower is "
             f"better; per setting, the median over its runs and, {pairs}, the runs where the "
             "controller's J is lower than pd's and the median of their ratio. A run shared by "
             "several combinations (every seed in calm water) counts once.\n",
             "| " + " | ".join(header) + " |", "|" + "---|" * len(header)]
    for where in settings:
        runs = {controller: [ok.get((controller, *(json.dumps(where.get(a, seed))
                                                   for a in spec.axes)))
                             for seed in spec.axes.get(MONTE_CARLO, [None])]
                for controller in spec.controllers}
        cells = [str(v) for v in where.values()] + [_median_J(runs["pd"])]
        wins, ratios = [], []
        for controller in others:
            cells.append(_median_J(runs[controller]))
            pairs = list({(a.get("ran_as", a["run_id"]), b.get("ran_as", b["run_id"])):
                          (a["J"], b["J"]) for a, b in zip(runs[controller], runs["pd"])
                          if a is not None and b is not None}.values())
            decided = [(J_c, J_b) for J_c, J_b in pairs if J_c != J_b]
            wins.append(f"{sum(J_c < J_b for J_c, J_b in decided)}/{len(decided)}")
            defined = [J_c / J_b for J_c, J_b in pairs if J_b > 1e-9]
            ratios.append(f"{np.median(defined):.2f}" if defined else "-")
        lines.append("| " + " | ".join(cells + wins + ratios) + " |")
    table = "\n".join(lines) + "\n"
    return [write_atomically(out / "comparison.md", lambda path: path.write_text(table))]


def _median_J(found: list[dict | None]) -> str:
    J = [r["J"] for r in distinct([r for r in found if r is not None])]
    return f"{np.median(J):.1f}" if J else "-"
