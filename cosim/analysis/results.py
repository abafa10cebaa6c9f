"""A course-keeping run's result files from any FMI tool, read into a ``Recording`` that the
scorecard's criteria take: OMSimulator's CSV ("model.root.ship.psi"), fmpy's and ours
("ship.psi"), or libcosim's one file per component ("ship_20261203_212512_739930.csv":
"Time", "StepCount", "psi"). At a time given twice (OMSimulator's events) the last row counts."""
from __future__ import annotations

import csv
import re
from pathlib import Path

import numpy as np

from ..core.recording import Recording

NEEDED = ("guidance.psi_d", "guidance.wp_index", "ship.psi", "ship.delta", "ship.x", "ship.y")
_LIBCOSIM = re.compile(r"([A-Za-z_]\w*?)_\d{8}_\d{6}_\d+")      # its files' names


def read_results(paths: list[Path], parameters: dict[str, dict]) -> Recording:
    """The ``NEEDED`` signals of ``paths``, the run's ``parameters`` (the route, the stops)
    in its metadata; ValueError naming the file, or the signals none of them holds."""
    signals, times = {}, []
    for path in paths:
        try:
            with open(path, newline="", encoding="utf-8") as file:
                header, *rows = list(csv.reader(file))
            libcosim = _LIBCOSIM.fullmatch(Path(path).stem)
            names = [f"{libcosim[1]}.{h}" if libcosim else ".".join(h.split(".")[-2:])
                     for h in header]
            wanted = [0, *(i for i, name in enumerate(names) if name in NEEDED)]
            table = np.array([[float(row[i]) for i in wanted] for row in rows], ndmin=2)
        except (OSError, UnicodeDecodeError, csv.Error, ValueError, IndexError) as error:
            raise ValueError(f"result file {path} is not a CSV of numbers with a header "
                             f"row ({type(error).__name__}: {error})") from None
        last = np.append(table[1:, 0] != table[:-1, 0], True)
        times.append(table[last, 0])
        signals.update(zip((names[i] for i in wanted[1:]), table[last, 1:].T))
        if not np.array_equal(times[0], times[-1]):
            raise ValueError(f"result file {path} has other times than {paths[0]}")
    missing = [name for name in NEEDED if name not in signals]
    if missing or not times or len(times[0]) < 2:
        raise ValueError(f"the result files hold no {', '.join(missing) or 'rows'}: a "
                         f"course-keeping run records {', '.join(NEEDED)}")
    return Recording(list(NEEDED), times[0], np.column_stack([signals[n] for n in NEEDED]),
                     len(times[0]), meta={"parameters": parameters,
                                          "step_size": float(times[0][1] - times[0][0])})
