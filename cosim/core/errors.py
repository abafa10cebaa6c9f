"""The core's errors about an FMU file, and the advice a message ends with ("did you mean")."""
from __future__ import annotations

import difflib
from typing import Iterable


class _FmuFileError(Exception):
    """``ours``: the file is named as one of the FMUs the caller builds (a command may say how)."""

    def __init__(self, message: str, ours: bool):
        super().__init__(message)
        self.ours = ours


class FmuNotFound(_FmuFileError, FileNotFoundError):
    """No FMU file where a component's source says."""


class FmuUnreadable(_FmuFileError, ValueError):
    """A file that is not a readable FMU."""


def close_matches(name: str, names: Iterable[str]) -> list[str]:
    """The names a user who typed ``name`` likely meant, best first: equal but for case, then
    up to three alike (difflib's ratio 0.7: 'ship' for 'shp', not 'wave_seed' for 'wave_height')."""
    names = list(dict.fromkeys(names))
    folded = {n.lower(): n for n in reversed(names)}            # the first of each
    close = [folded[n] for n in difflib.get_close_matches(name.lower(), list(folded), 3, 0.7)]
    same = [n for n in names if n.lower() == name.lower()]
    return list(dict.fromkeys(n for n in [*same, *close] if n != name))


def did_you_mean(matches: list[str]) -> str:
    """"; did you mean 'Hs'?" for ``matches``; '' for none."""
    if not matches:
        return ""
    *rest, last = [f"'{n}'" for n in matches]
    return f"; did you mean {', '.join(rest) + ' or ' if rest else ''}{last}?"
