"""What the command-line modules share: scenario arguments, output folders, the progress bar.

Only the commands (``cosim.run``, ``cosim.sweep``, ``cosim.export``, ...) import this.
"""
from __future__ import annotations

import argparse
import sys
import tempfile
from pathlib import Path

from . import scenarios


def chosen_scenarios(parser: argparse.ArgumentParser, scenario: str | None,
                     paper: bool) -> list[str]:
    """One SCENARIO (a name or a .ssd path) or --all (the paper's four); checked, or the
    parser exits naming the problem."""
    if paper == bool(scenario):
        parser.error("give one SCENARIO or --all")
    names = list(scenarios.PAPER) if paper else [scenario]
    for name in names:
        try:
            scenarios.path(name)
        except (ValueError, FileNotFoundError) as error:
            parser.error(str(error))
    return names


def writable_folder(path: Path) -> Path:
    """Create the folder and prove it is writable, before anything is simulated."""
    try:
        path.mkdir(parents=True, exist_ok=True)
        with tempfile.NamedTemporaryFile(dir=path):
            pass
    except OSError as error:
        raise SystemExit(f"error: output folder {path} is not writable ({error.strerror})")
    return path


class Progress:
    """A progress bar on standard error that appears only for runs longer than a second."""

    def __init__(self, label: str):
        self.label, self.bar = label, None

    def __call__(self, k: int, n: int) -> None:
        if self.bar is None:
            from tqdm import tqdm
            self.bar = tqdm(total=n, desc=self.label, unit="step", delay=1.0, leave=False,
                            file=sys.stderr)
        self.bar.update(k - self.bar.n)

    def close(self) -> None:
        if self.bar is not None:
            self.bar.close()
