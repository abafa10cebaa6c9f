"""Helpers shared by the tests."""
from __future__ import annotations

import csv
import subprocess
import sys
from pathlib import Path


def fmpy_cli(*args: str, cwd: Path) -> None:
    """Run fmpy's command line in a subprocess."""
    subprocess.run([sys.executable, "-m", "fmpy.cli", *args], cwd=cwd, check=True,
                   capture_output=True, text=True, timeout=120)


def read_csv(path: Path) -> list[dict[str, float]]:
    with open(path) as f:
        return [{k: float(v) for k, v in row.items()} for row in csv.DictReader(f)]
