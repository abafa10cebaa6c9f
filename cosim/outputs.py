"""A run and what it writes: the one lifecycle behind ``cosim.run`` and any caller of the library.

``run_and_write`` runs a system description with the master (freed however the run
ends) and writes, as ``label`` in a folder: the CSV of every signal at every step
(streamed as the run goes with ``stream``), the metadata JSON (``core.provenance``)
and, for a finished run, its figure (``analysis.kinds``) and an animation if asked.
A previous run's outputs of that label are removed first, so that none is left to
mislead. It prints nothing: the ``Outcome`` says what happened, and the report.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Callable

from .analysis.animation import animate, require_track
from .analysis.cost import LAMBDA, Cost, cost
from .analysis.figures import save_figure
from .analysis.kinds import analysis
from .core.interrupt import StopSignals
from .core.master import Master
from .core.provenance import write_metadata
from .core.recording import Recording
from .core.ssd import SystemDescription

SUFFIXES = (".csv", ".json", ".png", ".svg", ".pdf", ".gif", ".mp4")
"""What a run writes, by suffix: a previous run's files of these are removed first."""


@dataclass(frozen=True)
class Options:
    """How to run and what to write."""

    coupling: str = "gauss-seidel"
    stop_time: float | None = None
    lam: float = LAMBDA
    backend: str = "fmi"
    plot: bool = True
    formats: tuple[str, ...] = ("png",)
    stream: bool = False
    animate: str | None = None          # "gif" or "mp4"


@dataclass
class Outcome:
    """What a run did and wrote."""

    recording: Recording
    csv: Path
    written: list[Path] = field(default_factory=list)
    report: list[str] = field(default_factory=list)   # the report's lines, for a finished run
    cost: Cost | None = None                          # eq (19), for course keeping
    status: int = 0             # 0, 1 if an FMU failed, 130 / 143 if a signal stopped it


def run_and_write(system: SystemDescription, label: str, out: Path,
                  overrides: dict[str, dict[str, Any]] | None = None,
                  options: Options = Options(),
                  progress: Callable[[int, int], None] | None = None,
                  stop: StopSignals | None = None,
                  notes: Callable[[str], None] | None = None) -> Outcome:
    """Run ``system`` and write its outputs as ``label`` in ``out``; see the module docstring.

    ``notes`` hears what the user should know of how it runs (a component through FMI,
    say) as soon as the FMUs are instantiated; ``stop`` ends the run between two steps
    once it has received a signal. ValueError or FileNotFoundError for bad input
    (nothing is removed or written then); FmuCallError if an FMU cannot be instantiated.
    """
    kind = analysis(system.report)
    csv_path = out / f"{label}.csv"
    with Master(system, coupling=options.coupling, overrides=overrides,
                backend=options.backend) as master:
        for note in master.notes:
            if notes is not None:
                notes(note)
        if options.animate:
            require_track(master.columns)
        for old in out.glob(f"{label}.*"):
            if old.suffix in SUFFIXES:
                old.unlink()
        recording = master.run(options.stop_time, progress=progress,
                               csv_path=csv_path if options.stream else None, stop=stop)
        parameters = master.parameters
    if not options.stream:
        recording.write_csv(csv_path)
    outcome = Outcome(recording, csv_path,
                      [csv_path, write_metadata(recording, out / f"{label}.json")])
    if recording.interrupted:
        outcome.status = stop.exit_status          # only a run given ``stop`` is interrupted
        return outcome
    if recording.error:
        outcome.status = 1
        return outcome
    if options.stream:
        return outcome
    outcome.report = kind.report(recording, lam=options.lam, parameters=parameters)
    if options.plot and kind.figure is not None:
        outcome.written += save_figure(recording, kind.figure, out / label, label,
                                       options.formats)
    if options.animate:
        outcome.written.append(animate(recording, out / label, label, options.animate))
    if system.report == "course_keeping":
        outcome.cost = cost(recording, options.lam)
    return outcome
