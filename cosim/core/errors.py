"""The core's errors about an FMU file, with what a command needs to advise its user."""
from __future__ import annotations


class FmuNotFound(FileNotFoundError):
    """No FMU file where a component's source says; ``ours``: one this project builds."""

    def __init__(self, message: str, ours: bool):
        super().__init__(message)
        self.ours = ours


class FmuUnreadable(ValueError):
    """A file that is not a readable FMU; ``ours``: named as one this project builds."""

    def __init__(self, message: str, ours: bool):
        super().__init__(message)
        self.ours = ours
