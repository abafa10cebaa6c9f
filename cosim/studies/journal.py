"""A sweep's journal: one JSON row per finished run, appended and flushed as runs complete.

The journal is what a sweep resumes from, so it must survive what ends a process
mid-write: a torn last line (a write cut by a kill) is skipped with a warning, and
its run is done again. One sweep writes a journal at a time: a second writer is
refused with a message naming the holder of the lock (process, host, since when).
The lock file (runs.jsonl.lock) is removed when the writer closes the journal (if it
is still that writer's file); one left by a killed process is stale, and the next
writer takes it over.
Tables derived from it are written atomically (``cosim.core.files``).
"""
from __future__ import annotations

import fcntl
import json
import os
import socket
import sys
import time
from pathlib import Path
from typing import TextIO


class JournalLocked(RuntimeError):
    """Another process writes this journal."""


def read_rows(path: Path, quiet: bool = False) -> dict[str, dict]:
    """The rows of a journal by run id; lines that are not whole rows are skipped, with a
    warning naming the file and line (a later row for the same run replaces an earlier)."""
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


def _same_file(handle: TextIO, path: Path) -> bool:
    """Whether ``path`` is still the file open as ``handle``."""
    try:
        facts = os.stat(path)
    except FileNotFoundError:
        return False
    mine = os.fstat(handle.fileno())
    return (facts.st_dev, facts.st_ino) == (mine.st_dev, mine.st_ino)


class Journal:
    """The journal of one sweep, locked for writing while open (``with Journal(path)``)."""

    def __init__(self, path: Path):
        self.path = path
        self.rows = read_rows(path)
        self._lock_file: TextIO | None = None

    def __enter__(self) -> Journal:
        lock = self.path.with_name(self.path.name + ".lock")
        while True:
            handle = open(lock, "a+")
            try:
                fcntl.flock(handle, fcntl.LOCK_EX | fcntl.LOCK_NB)
            except BlockingIOError:
                handle.seek(0)
                holder = handle.read().strip() or "another process"
                handle.close()
                raise JournalLocked(f"{self.path} is being written by {holder}; wait for "
                                    "that sweep to end, or give this one another --out") from None
            if _same_file(handle, lock):
                break
            handle.close()          # its writer removed it as we opened it: take the new one
        handle.seek(0)
        handle.truncate()
        handle.write(f"process {os.getpid()} on {socket.gethostname()} since "
                     f"{time.strftime('%Y-%m-%d %H:%M:%S')}\n")
        handle.flush()
        self._lock_file = handle
        self._repair_tail()
        return self

    def __exit__(self, *exc) -> None:
        if self._lock_file is not None:
            # Removed while still held (whoever opened it meanwhile sees it is gone, above),
            # and only if it is still this writer's: a lock file someone deleted and another
            # sweep made again is that sweep's.
            lock = Path(self._lock_file.name)
            if _same_file(self._lock_file, lock):
                lock.unlink(missing_ok=True)
            fcntl.flock(self._lock_file, fcntl.LOCK_UN)
            self._lock_file.close()
            self._lock_file = None

    def _repair_tail(self) -> None:
        """End the file with a newline, so that a torn last line stays a line of its own."""
        if self.path.exists() and self.path.stat().st_size:
            with open(self.path, "rb+") as f:
                f.seek(-1, os.SEEK_END)
                if f.read(1) != b"\n":
                    f.write(b"\n")

    def add(self, row: dict) -> None:
        """Append a row and flush it to the file."""
        if self._lock_file is None:
            raise RuntimeError("a Journal is written within 'with', which locks it")
        with open(self.path, "a") as f:
            f.write(json.dumps(row) + "\n")
            f.flush()
            os.fsync(f.fileno())
        self.rows[row["run_id"]] = row
