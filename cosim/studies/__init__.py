"""Studies on the co-simulation core: sweeps, scorecard, benchmarks, accuracy
(docs/architecture.md lists the modules); ``table`` for their Markdown, ``in_child``."""
from __future__ import annotations

import subprocess
import sys
from typing import Iterable, Sequence


def table(header: Sequence[str], rows: Iterable[Sequence[str]],
          text_columns: int | None = None) -> list[str]:
    """A Markdown table's lines; the columns after the first ``text_columns`` aligned right
    (by default none)."""
    left = len(header) if text_columns is None else text_columns
    lines = ["| " + " | ".join(cells) + " |" for cells in (header, *rows)]
    return [lines[0], "|" + "---|" * left + "---:|" * (len(header) - left), *lines[1:]]


def in_child(what: str, code: str, *args: str, env: dict[str, str] | None = None,
             timeout: float | None = None) -> str:
    """``python -c code args``'s output; RuntimeError naming ``what`` if it fails."""
    done = subprocess.run([sys.executable, "-c", code, *args], env=env, capture_output=True,
                          text=True, timeout=timeout)
    if done.returncode:
        raise RuntimeError(f"{what} failed (status {done.returncode}): "
                           f"{done.stderr.strip().splitlines()[-1:]}")
    return done.stdout
