"""A sweep's journal: one JSON row per finished run, appended and flushed as runs complete.

It is what a sweep resumes from, so it survives a kill mid-write: a torn last line is
skipped with a warning and its run done again. Its one writer holds the folder's
``core.files.FolderLock``.
"""
from __future__ import annotations

import json
import os
import sys
from pathlib import Path


def read_rows(path: Path, quiet: bool = False) -> dict[str, dict]:
    """The rows of a journal by run id (a later row for a run replaces an earlier); a line
    that is not a whole row is skipped, with a warning naming the file and line."""
    rows: dict[str, dict] = {}
    if not path.exists():
        return rows
    for number, line in enumerate(path.read_text().splitlines(), 1):
        if not line.strip():
            continue
        try:
            row = json.loads(line)
            rows[row["run_id"]] = row
        except (ValueError, KeyError, TypeError):
            if not quiet:
                print(f"warning: {path}:{number} is not a whole journal row (a write cut "
                      "short?); skipped, its run is done again", file=sys.stderr)
    return rows


class Journal:
    """The journal of one sweep, opened by its writer: its rows, and ``add``."""

    def __init__(self, path: Path):
        self.path = path
        self.rows = read_rows(path)
        if path.exists() and path.stat().st_size:   # a torn last line: its own
            with open(path, "rb+") as f:
                f.seek(-1, os.SEEK_END)
                if f.read(1) != b"\n":
                    f.write(b"\n")

    def add(self, row: dict) -> None:
        """Append a row and flush it to the file."""
        with open(self.path, "a") as f:
            f.write(json.dumps(row) + "\n")
            f.flush()
            os.fsync(f.fileno())
        self.rows[row["run_id"]] = row
