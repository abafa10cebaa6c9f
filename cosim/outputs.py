"""A run and what it writes, the one lifecycle behind ``cosim.run`` and any library caller:
the outputs are staged and put in place together (a refused run, a full disk or a second
Ctrl-C leaves the folder as it was), by one process a folder at a time; nothing printed."""
import signal
from dataclasses import dataclass, field
from importlib import import_module
from pathlib import Path
from typing import Any, Callable

from .analysis.metrics import LAMBDA, Cost, cost
from .analysis.reports import course_keeping_report, title, turning_circle_report, zigzag_report
from .core.files import FolderLock, Outputs
from .core.instance import FmuCallError
from .core.interrupt import Interrupted, StopSignals
from .core.isolation import Isolation
from .core.master import Master
from .provenance import write_metadata
from .core.recording import Recording
from .core.ssd import SystemDescription
from .core.watchdog import Limits, Watchdog

SUFFIXES = (".csv", ".json", ".png", ".svg", ".pdf", ".gif", ".mp4")   # a run's files
# A scenario's kind (its .ssd's ``report``): the report printed, and the "module.function" of
# cosim.analysis drawing its figure, imported only to draw (a run without one loads no matplotlib)
KINDS: dict[str, tuple[Callable[..., list[str]], str | None]] = {
    "course_keeping": (course_keeping_report, "figures.course_keeping_figure"),
    "turning_circle": (turning_circle_report, "plates.turning_circle_plate"),
    "zigzag": (zigzag_report, "plates.zigzag_plate"),
    "none": (lambda recording, **_: [], None),
}


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
    limits: Limits = Limits()           # step and run time limits (``core.watchdog``)
    isolation: Isolation = Isolation()  # which FMUs run in a process of their own


@dataclass
class Outcome:
    """What a run did and wrote."""
    recording: Recording
    csv: Path
    written: list[Path] = field(default_factory=list)
    report: list[str] = field(default_factory=list)   # the report's lines, for a finished run
    cost: Cost | None = None                          # eq (19), for course keeping
    status: int = 0             # 0, 1 if an FMU failed, 130 / 143 if a signal stopped it
    late_signal: bool = False   # a signal came after the last step: the outputs are whole


def run_and_write(system: SystemDescription, label: str, out: Path,
                  overrides: dict[str, dict[str, Any]] | None = None,
                  options: Options = Options(),
                  progress: Callable[[int, int], None] | None = None,
                  stop: StopSignals | None = None,
                  notes: Callable[[str], None] = lambda note: None) -> Outcome:
    """Run ``system`` and write its CSV, JSON and, once finished, figure and animation as
    ``label`` in ``out``; ``stop`` ends it between steps on a signal. An exception (ValueError,
    FileNotFoundError, FmuCallError, FolderBusy, OutputError) leaves ``out`` as it was."""
    if system.report not in KINDS:
        raise ValueError(f"unknown report kind {system.report!r}; known: {', '.join(KINDS)}")
    with FolderLock(out):
        with Outputs(out, [out / f"{label}{suffix}" for suffix in SUFFIXES], label) as outputs:
            forget = stop.keep(lambda: _discard(outputs, label)) if stop else lambda: None
            master: Master | None = None
            finished: list[Recording] = []    # the run, once it has returned

            def salvage(reason: str) -> str:      # the watchdog's, if the run never returns
                recording = finished[0] if finished else \
                    master.abandon(reason) if master is not None else None
                if recording is None or not recording.rows:
                    return f"nothing was written; {_discard(outputs, label)}"
                _write_rows(recording, outputs, label, options.stream)
                csv, meta = outputs.commit()
                return f"the {recording.rows} rows recorded are in {csv}, with {meta}"

            try:
                with Watchdog(options.limits, stop, salvage) as watchdog:
                    watchdog.beat(f"instantiating {', '.join(system.components)}")
                    try:
                        master = Master(system, coupling=options.coupling, overrides=overrides,
                                        backend=options.backend, isolation=options.isolation)
                    except FmuCallError:            # a child killed after a signal
                        if stop is not None and stop.received:
                            raise Interrupted(stop.received) from None
                        raise
                    with master:
                        for note in master.notes:
                            notes(note)
                        if options.animate:
                            from .analysis.animation import require_track   # matplotlib
                            require_track(master.columns)
                        with outputs.writing(f"{label}.csv") as csv_path:
                            recording = master.run(options.stop_time, progress=progress,
                                                   csv_path=csv_path if options.stream else None,
                                                   stop=stop, watchdog=watchdog)
                        finished.append(recording)
                        parameters = master.parameters
                        watchdog.beat("terminating and freeing the FMUs")
                outcome = Outcome(recording, out / f"{label}.csv")
                if recording.interrupted:
                    outcome.status = 128 + int(signal.Signals[recording.interrupted])
                elif recording.error:
                    outcome.status = 1
                if outcome.status and not recording.rows:
                    outputs.discard()       # nothing was computed: the earlier outputs stay
                    return outcome
                outcome.written = _write_rows(recording, outputs, label, options.stream)
                if not (recording.error or options.stream):
                    _analyse(outcome, system, label, outputs, options, parameters)
                outcome.written = [outputs.final(path) for path in outcome.written]
            finally:
                forget()
    if options.stream:
        recording.path = outcome.csv
    if stop is not None and stop.received and not recording.interrupted:
        outcome.status, outcome.late_signal = stop.exit_status, True
    return outcome


def _discard(outputs: Outputs, label: str) -> str:
    outputs.discard()
    return f"the earlier outputs of {label} in {outputs.folder}, if any, are as they were"


def _write_rows(recording: Recording, outputs: Outputs, label: str, streamed: bool
                ) -> list[Path]:
    with outputs.writing(f"{label}.csv") as csv_path:
        if not streamed:
            recording.write_csv(csv_path)
    with outputs.writing(f"{label}.json") as json_path:
        write_metadata(recording, json_path)
    return [csv_path, json_path]


def figure(kind: str) -> Callable[..., Any] | None:
    """The function drawing a kind's figure, or None; importing it loads matplotlib."""
    if KINDS[kind][1] is None:
        return None
    module, name = KINDS[kind][1].split(".")
    return getattr(import_module(f"{__package__}.analysis.{module}"), name)


def _analyse(outcome: Outcome, system: SystemDescription, label: str, outputs: Outputs,
             options: Options, parameters: dict) -> None:
    recording = outcome.recording
    outcome.report = KINDS[system.report][0](recording, lam=options.lam, parameters=parameters)
    if options.plot and (draw := figure(system.report)) is not None:
        from .analysis.figures import save
        fig = draw(recording, lam=options.lam)
        fig.suptitle(title(label, recording.meta), fontsize=8)
        with outputs.writing(f"{label}.{options.formats[0]}") as path:
            outcome.written += save(fig, path.with_suffix(""), options.formats)
    if options.animate:
        from .analysis.animation import animate
        with outputs.writing(f"{label}.{options.animate}") as path:
            outcome.written.append(animate(recording, path.with_suffix(""), label,
                                           options.animate))
    if system.report == "course_keeping":
        outcome.cost = cost(recording, options.lam)
