"""Which FMUs run in a process of their own (``core.isolated``), and the memory each may take."""
from __future__ import annotations

import os
from dataclasses import dataclass
from typing import Iterable


def default_memory_limit() -> int | None:
    """Three quarters of this machine's memory, in bytes (None where it cannot be read)."""
    try:
        return os.sysconf("SC_PHYS_PAGES") * os.sysconf("SC_PAGE_SIZE") * 3 // 4
    except (AttributeError, ValueError, OSError):
        return None


@dataclass(frozen=True)
class Isolation:
    """Which components run in a process of their own: "none", "all", "foreign" (an FMU not
    built from this checkout) or their names; each child's address-space limit in bytes."""
    chosen: str | tuple[str, ...] = "none"
    memory_limit: int | None = default_memory_limit()

    @classmethod
    def of(cls, which: bool | str | Iterable[str] | None,
           memory_limit: int | None = None) -> Isolation:
        """From what a user gives: True ("all"), False or None ("none"), "all", "none",
        "foreign", "name,name" or names; ``memory_limit`` in bytes (None: the default);
        ValueError for anything else."""
        if which is None or isinstance(which, bool):
            chosen: str | tuple[str, ...] = "all" if which else "none"
        elif which in ("all", "none", "foreign"):
            chosen = which
        elif isinstance(which, (str, list, tuple, set, frozenset)):
            chosen = tuple(n.strip() for n in (which.split(",") if isinstance(which, str)
                                               else which) if isinstance(n, str) and n.strip())
        else:
            chosen = ()
        if not chosen:
            raise ValueError(f"isolate: expected all, none, foreign or component names, "
                             f"got {which!r}")
        if memory_limit is not None and chosen == "none":
            raise ValueError("the memory limit limits the processes of isolated FMUs; "
                             "isolate some")
        if memory_limit is not None and (isinstance(memory_limit, bool) or not isinstance(
                memory_limit, int) or not 2**20 <= memory_limit < 2**62):
            raise ValueError(f"the memory limit must be a whole number of bytes from 1 MiB "
                             f"to 4 EiB, got {memory_limit!r}")
        return cls(chosen, default_memory_limit() if memory_limit is None else memory_limit)

    def isolates(self, name: str, foreign: bool) -> bool:
        if isinstance(self.chosen, str):
            return self.chosen == "all" or (self.chosen == "foreign" and foreign)
        return name in self.chosen

    def check(self, components: Iterable[str]) -> Isolation:
        """ValueError naming a component to isolate that the system does not have."""
        unknown = [] if isinstance(self.chosen, str) else \
            [name for name in self.chosen if name not in components]
        if unknown:
            raise ValueError(f"isolate names {', '.join(unknown)}, which the system does not "
                             f"have; its components: {', '.join(components)}")
        return self
