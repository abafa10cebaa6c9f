"""What the commands share: scenario and autopilot options, output folders, messages. Only
the commands import this."""
import argparse
import contextlib
import faulthandler
import functools
import math
import os
import re
import signal
import sys
import tempfile
import threading
from pathlib import Path
from typing import Any, Callable

from fmubuild.project import BUILD_HINT, FMU_DIRS, SLAVE_MODULES

from . import scenarios
from .api import parse_port_map, parse_setting
from .core.files import plain_name
from .core.interrupt import Interrupted, StopSignals
from .core.isolation import Isolation, default_memory_limit
from .core.recording import TooManyRows
from .core.values import fmi_value
from .scenarios.autopilot import AutopilotError, check_autopilot


def chosen_scenarios(parser: argparse.ArgumentParser, args: argparse.Namespace) -> list[str]:
    """One SCENARIO (a name or a .ssd path) or --all (the paper's four); --autopilot checked."""
    if args.all == bool(args.scenario):
        took = isinstance(args.isolate, str) and args.isolate not in ("all", "none", "foreign")
        parser.error("give one SCENARIO or --all" + (f" (--isolate took {args.isolate!r} as the "
                     "FMUs to isolate: put it after the scenario, or write --isolate=all)"
                     if took and not args.all else ""))
    names = list(scenarios.PAPER) if args.all else [args.scenario]
    for name in names:
        try:
            scenarios.path(name)
        except (ValueError, FileNotFoundError) as error:
            parser.error(str(error))
    checked_autopilot(parser, args)
    return names


def option(parse: Callable[[str], Any]) -> Callable[[str], Any]:
    """``parse`` as an argparse type: its ValueError is the option's message."""
    def parsed(text: str) -> Any:
        try:
            return parse(text)
        except ValueError as error:
            raise argparse.ArgumentTypeError(str(error)) from None
    return parsed


setting_option = option(parse_setting)      # --set COMPONENT.VARIABLE=VALUE


@option
def number_option(text: str) -> float:
    """A finite number, read as a Real parameter is (no '5_0', no 'inf')."""
    try:
        value = fmi_value("the option", "Real", text)
    except ValueError:
        value = math.nan
    if not math.isfinite(value):
        raise ValueError(f"expected a finite number, got {text!r}")
    return value


def count(text: str) -> int:
    """A whole number >= 1, for argparse."""
    with contextlib.suppress(ValueError):
        if int(text) >= 1:
            return int(text)
    raise argparse.ArgumentTypeError(f"give a whole number >= 1, got {text!r}")


@option
def positive_seconds(text: str) -> float:
    """A time limit in seconds: a finite number > 0."""
    value = number_option(text)
    if not value > 0:
        raise ValueError(f"expected a positive number of seconds, got {text!r}")
    return value


SIZES = {"": 1, "k": 2**10, "m": 2**20, "g": 2**30, "t": 2**40}


@option
def size_option(text: str) -> int:
    """A size in bytes: a number with K, M, G or T (binary multiples; B or iB may follow)."""
    found = re.fullmatch(r"(\d+(?:\.\d*)?)\s*([kmgt]?)(?:i?b)?", text.strip().lower())
    if not found:
        raise ValueError(f"expected a size such as 512M or 4G, got {text!r}")
    return int(float(found[1]) * SIZES[found[2]])


def add_isolation_options(parser: argparse.ArgumentParser, default: str) -> None:
    """--isolate [WHICH] and --memory-limit SIZE."""
    limit = default_memory_limit()
    parser.add_argument("--isolate", nargs="?", const="all", default=default, metavar="WHICH",
                        help="run FMUs each in a process of its own, so that one that crashes, "
                             "exits or hangs fails its run, not the command: all (--isolate "
                             "alone), foreign (FMUs not built from this checkout), none, or "
                             f"component names, e.g. autopilot,guidance (default: {default}; "
                             "docs/robustness.md)")
    parser.add_argument("--memory-limit", type=size_option, metavar="SIZE",
                        help="the address space each isolated FMU's process may take, e.g. 2G; "
                             "past it the FMU's allocations fail and its run fails, naming "
                             "the limit (default: 3/4 of this machine's memory" +
                             (f", {limit / 2**30:.1f}G)" if limit else ")"))


def isolation(parser: argparse.ArgumentParser, args: argparse.Namespace) -> Isolation:
    """The isolation --isolate and --memory-limit ask for (else the parser's error)."""
    if args.memory_limit is not None and args.isolate == "none":
        parser.error("--memory-limit limits the processes of isolated FMUs; add --isolate")
    try:
        return Isolation.of(args.isolate, args.memory_limit)
    except ValueError as error:
        parser.error(str(error).replace("isolate", "--isolate", 1))


def add_fmu_options(parser: argparse.ArgumentParser, also: str) -> None:
    """--fmi, --autopilot, --map and --name; ``also`` says what --all does with the autopilot."""
    parser.add_argument("--fmi", type=int, choices=sorted(FMU_DIRS),
                        help="run this project's FMI 2.0 FMUs (fmus/) or their FMI 3.0 twins "
                             "(fmus/fmi3/, built by python -m fmukit.build --fmi 3) in place "
                             "of those the scenario names (default: as it names them; the "
                             "scenarios here name the FMI 2.0 ones)")
    parser.add_argument("--autopilot", type=Path, metavar="FMU",
                        help="your own autopilot, an FMI 2.0 or 3.0 co-simulation FMU with "
                             "inputs psi (rad), r (rad/s), psi_d (rad) and output delta_c "
                             f"(rad), in place of the scenario's; {also} (see "
                             "docs/own_autopilot.md)")
    add_port_options(parser)


def add_port_options(parser: argparse.ArgumentParser) -> None:
    """--map PORT=NAME and --name NAME, which describe an autopilot FMU."""
    parser.add_argument("--map", action="append", default=[], type=option(parse_port_map),
                        metavar="PORT=NAME",
                        help="the FMU's name of an autopilot port, e.g. psi=heading; repeatable")
    parser.add_argument("--name", type=option(functools.partial(plain_name, what="--name")),
                        help="the autopilot's name in file names and tables "
                             "(default: the FMU's file name)")


def say_error(error: BaseException) -> None:
    """``error: ...`` on standard error, with advice where the error says what mends it."""
    print(f"error: {error}", file=sys.stderr)
    if getattr(error, "ours", False):        # an FMU of ours not built: how to build it
        fmi3 = " --fmi 3" if str(FMU_DIRS[3]) in str(error) else ""
        print(f"  {BUILD_HINT}{fmi3}", file=sys.stderr)
    if isinstance(error, TooManyRows):
        print("  cosim.run --stream writes the rows to the CSV as the run goes", file=sys.stderr)


def say_note(note: str) -> None:
    """``note: ...`` on standard error, and how to rebuild where the note says so."""
    print(f"note: {note}", file=sys.stderr)
    if getattr(note, "stale_module", None) in SLAVE_MODULES:
        print(f"  {BUILD_HINT}", file=sys.stderr)


def checked_autopilot(parser: argparse.ArgumentParser, args: argparse.Namespace) -> None:
    """Check --autopilot against the port contract before anything runs (else status 2)."""
    if args.autopilot is None and (args.map or args.name):
        parser.error("--map and --name describe an --autopilot FMU; give one")
    try:
        if args.autopilot is not None:
            check_autopilot(args.autopilot, dict(args.map), trial=True)
    except AutopilotError as error:
        say_error(error)
        raise SystemExit(2) from None


def entry(main: Callable[[], int]) -> int:
    """Run a command's main: quiet when its output pipe closes; on Ctrl-C or SIGTERM,
    "interrupted" and status 130 or 143, not a traceback."""
    signal.signal(signal.SIGPIPE, signal.SIG_DFL)
    faulthandler.enable()           # a crash in an FMU here shows its traceback, naming it
    try:
        with StopSignals(raising=True):
            return main()
    except Interrupted as interrupted:
        print(interrupted, file=sys.stderr)
        return interrupted.exit_status


def leave(status: int) -> None:
    """End the command with ``status``, even if an FMU in this process left a thread of its
    own running (Python would wait for it for ever), saying so."""
    left = [t.name for t in threading.enumerate()
            if not t.daemon and t is not threading.main_thread()]
    if not left:
        sys.exit(status)
    print(f"note: threads still running after the command ({', '.join(left)}), started by an "
          "FMU in this process; ending without them (--isolate runs FMUs apart)",
          file=sys.stderr)
    sys.stdout.flush()
    sys.stderr.flush()
    os._exit(status)


def writable_folder(path: Path) -> Path:
    """Create the folder and prove it is writable, before anything is simulated."""
    try:
        path.mkdir(parents=True, exist_ok=True)
        with tempfile.NamedTemporaryFile(dir=path):
            pass
    except OSError as error:        # bad input: status 2, as every refusal of a command
        print(f"error: output folder {path} is not writable ({error.strerror})",
              file=sys.stderr)
        raise SystemExit(2) from None
    return path
