"""Studies on the co-simulation core: sweeps on Dask (``campaign`` runs one), the scorecard,
the benchmarks (``timing``, ``sweep_timing``, ``memory``), the accuracy study
(``integration_error``, ``coupling_error``), ``cpu_variants`` and ``spread``."""
from __future__ import annotations

from typing import Iterable, Sequence


def table(header: Sequence[str], rows: Iterable[Sequence[str]],
          text_columns: int | None = None) -> list[str]:
    """A Markdown table's lines; columns after the first ``text_columns`` (default: none)
    aligned right."""
    left = len(header) if text_columns is None else text_columns
    lines = ["| " + " | ".join(cells) + " |" for cells in (header, *rows)]
    return [lines[0], "|" + "---|" * left + "---:|" * (len(header) - left), *lines[1:]]
