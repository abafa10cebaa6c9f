"""Studies on the co-simulation core: sweeps, scorecard, benchmarks, accuracy
(docs/architecture.md lists the modules); ``table`` for their Markdown."""
from __future__ import annotations

from typing import Iterable, Sequence


def table(header: Sequence[str], rows: Iterable[Sequence[str]],
          text_columns: int | None = None) -> list[str]:
    """A Markdown table's lines; columns after the first ``text_columns`` (default: none)
    aligned right."""
    left = len(header) if text_columns is None else text_columns
    lines = ["| " + " | ".join(cells) + " |" for cells in (header, *rows)]
    return [lines[0], "|" + "---|" * left + "---:|" * (len(header) - left), *lines[1:]]
