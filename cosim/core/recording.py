"""What a run records, row k holding t_k and one value per column: held in memory, or
streamed to a CSV file in chunks (memory stays flat; the ``Recording`` then holds no rows)."""
from __future__ import annotations

import contextlib
import dataclasses
import os
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import IO, Any, Sequence

import numpy as np

CHUNK_ROWS = 10_000                     # rows streamed to CSV at a time


@dataclass
class Recording:
    """What a run recorded: row k holds every signal at t_k."""

    columns: list[str]
    time: np.ndarray                    # the rows held in memory: time, and
    data: np.ndarray                    # one column per signal
    rows: int = 0                       # rows the run recorded: held, or written to ``path``
    error: str | None = None            # why the run stopped early, if it did
    interrupted: str | None = None      # the signal that stopped it, if one did
    meta: dict[str, Any] = field(default_factory=dict)
    path: Path | None = None            # where the rows went, if streamed to CSV
    units: dict[str, str] = field(default_factory=dict)   # column: unit ("" if none)

    def __getitem__(self, column: str) -> np.ndarray:
        return self.data[:len(self.t), self.columns.index(column)]     # ``t``: if held

    @property
    def t(self) -> np.ndarray:
        if len(self.time) < self.rows:
            raise ValueError(f"the {self.rows} rows of this run were streamed to {self.path}; "
                             "read them from there")
        return self.time

    def holding(self, columns: Sequence[str]) -> Recording:
        """This recording with only ``columns``; ValueError naming any it lacks."""
        check_signals(columns, self.columns)
        return dataclasses.replace(self, columns=list(columns),
                                   data=self.data[:, [self.columns.index(c) for c in columns]],
                                   units={c: self.units.get(c, "") for c in columns})

    def write_csv(self, path: str | Path) -> None:
        with _open_csv(path, self.columns) as file:
            _write_rows(file, self.t, self.data)


def check_signals(signals: Sequence[str], recorded: Sequence[str]) -> None:
    """ValueError naming each of ``signals`` that a run recording ``recorded`` lacks."""
    missing = [c for c in signals if c not in recorded]
    if missing:
        raise ValueError(f"signals {', '.join(missing)}: the run records {', '.join(recorded)}")


def _open_csv(path: str | Path, columns: list[str]) -> IO[str]:
    file = open(path, "w")
    file.write(",".join(["time", *columns]) + "\n")
    return file


def _write_rows(file: IO[str], times: np.ndarray, data: np.ndarray) -> None:
    """Rows of a CSV file, floats in their shortest exact form."""
    file.writelines(",".join(map(repr, row)) + "\n"
                    for row in np.column_stack([times, data]).tolist())


class Recorder:
    """Takes a run's rows one at a time; with ``csv_path``, streams them in chunks."""

    def __init__(self, columns: list[str], rows: int, csv_path: str | Path | None = None,
                 meta: dict[str, Any] | None = None, units: dict[str, str] | None = None):
        self.columns, self.meta, self.units = columns, meta or {}, units or {}
        self.path = None if csv_path is None else Path(csv_path)
        if csv_path is None:
            require_memory(rows, len(columns) + 1)
        else:
            rows, self.file = min(CHUNK_ROWS, rows), _open_csv(self.path, columns)
        self.time, self.data = np.empty(rows), np.full((rows, len(columns)), np.nan)
        self.held = self.written = 0         # rows in the buffer, and rows written
        self.interrupted: str | None = None
        self.started = time.perf_counter()

    @property
    def rows(self) -> int:
        return self.written + self.held

    def append(self, t: float, values: list[float]) -> None:
        row = self.held
        self.time[row], self.data[row] = t, values
        self.held = row + 1
        if self.path is not None and self.held == len(self.time):
            self._flush()

    def _flush(self) -> None:
        _write_rows(self.file, self.time[:self.held], self.data[:self.held])
        self.file.flush()
        self.written, self.held = self.written + self.held, 0

    def close(self, error: str | None = None) -> Recording:
        """The recording, its meta with ``wall_time_s`` since this recorder began."""
        self.meta["wall_time_s"] = time.perf_counter() - self.started
        if self.path is not None:
            self._flush()
            self.file.close()
        return Recording(self.columns, self.time[:self.held], self.data[:self.held], self.rows,
                         error, self.interrupted, self.meta, self.path, self.units)


class TooManyRows(ValueError):
    """A run whose rows would not fit in memory: to be streamed to CSV instead."""


def require_memory(rows: int, columns: int) -> None:
    """TooManyRows if ``rows`` x ``columns`` floats would not fit in 80 % of the memory
    available to a new allocation (Linux's MemAvailable; else all RAM)."""
    available = os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES")
    with contextlib.suppress(OSError, StopIteration), open("/proc/meminfo") as meminfo:
        available = next(int(line.split()[1]) * 1024 for line in meminfo
                         if line.startswith("MemAvailable:"))
    needed = rows * columns * 8
    if needed > 0.8 * available:
        raise TooManyRows(f"the run would hold {rows} rows of {columns} values in memory, "
                          f"{needed / 2**30:,.1f} GiB, more than the {available / 2**30:,.1f} "
                          "GiB available: stream the rows to a CSV file as the run goes "
                          "(Master.run's csv_path)")
