"""Run a scenario of the Tomera (2010) study as an FMI co-simulation.

Examples:
  python -m cosim.run calm_pd                  the PD autopilot on the route, calm water
  python -m cosim.run waves_smc --out /tmp/w   the sliding-mode autopilot in waves
  python -m cosim.run calm_pd --set ship.Hs=0.003 --set autopilot.Kd=30
  python -m cosim.run --all                    the paper's four runs, Tables 1-2

Each scenario is an SSP system structure file in cosim/scenarios/ (the FMUs, their
parameters and connections). A run writes every signal at every 0.1 s step to
SCENARIO.csv and a figure like the paper's Figs 2-3 to SCENARIO.png in the output
folder, and prints the cost of eq (19) (or the manoeuvre's figures).
"""
from __future__ import annotations

import argparse
import os
import sys
import tempfile
from pathlib import Path

from .master import BACKENDS, COUPLINGS, Master
from .plots import save_figure
from .report import LAMBDA, PAPER, REPORTS, cost, tables
from .ssd import read_ssd

SCENARIO_DIR = Path(__file__).resolve().parent / "scenarios"
PAPER_SCENARIOS = list(PAPER)


def scenarios() -> list[str]:
    return sorted(p.stem for p in SCENARIO_DIR.glob("*.ssd"))


def parse_setting(text: str) -> tuple[str, str, int | float | str]:
    """'fmu.var=value' -> (fmu, var, value); numbers become int or float."""
    target, sep, raw = text.partition("=")
    component, dot, variable = target.partition(".")
    if not (sep and dot and component and variable):
        raise argparse.ArgumentTypeError(f"--set expects FMU.VARIABLE=VALUE, got {text!r}")
    for convert in (int, float):
        try:
            return component, variable, convert(raw)
        except ValueError:
            pass
    return component, variable, raw


def writable_folder(path: Path) -> Path:
    """Create the folder and prove it is writable, before anything is simulated."""
    try:
        path.mkdir(parents=True, exist_ok=True)
        with tempfile.NamedTemporaryFile(dir=path):
            pass
    except OSError as error:
        raise SystemExit(f"error: output folder {path} is not writable ({error.strerror})")
    return path


class _Progress:
    """A progress bar that appears only for runs longer than a second."""

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


def scenario_path(scenario: str) -> Path:
    """A scenario's .ssd: a name in cosim/scenarios, or a path to a .ssd file."""
    if scenario.endswith(".ssd"):
        return Path(scenario)
    return SCENARIO_DIR / f"{scenario}.ssd"


def run_scenario(name: str, out: Path, overrides: dict, coupling: str, stop_time: float | None,
                 lam: float, plot: bool = True, backend: str = "fmi",
                 stream: bool = False) -> tuple[int, object]:
    """Simulate one scenario, write its CSV and figure, print its report."""
    system = read_ssd(scenario_path(name))
    name = Path(name).stem
    master = Master(system, coupling=coupling, overrides=overrides, backend=backend)
    progress = _Progress(name)
    csv_path = out / f"{name}.csv"
    try:
        recording = master.run(stop_time, progress=progress,
                               csv_path=csv_path if stream else None)
    finally:
        progress.close()
        master.free()
    if not stream:
        recording.write_csv(csv_path)
    print(f"{name}: {system.description}")
    if recording.error:
        print(f"error: {recording.error}", file=sys.stderr)
        print(f"  the {recording.recorded} rows recorded before the error are in {csv_path}",
              file=sys.stderr)
        return 1, None
    if stream:
        print(f"  {recording.recorded} rows streamed to {csv_path} "
              "(no report or figure in --stream mode)")
        return 0, None
    for line in REPORTS[system.report](recording, lam=lam, parameters=master.parameters):
        print(f"  {line}")
    written = [csv_path]
    if plot and save_figure(recording, system.report, out / f"{name}.png",
                            f"{name}: {system.description}"):
        written.append(out / f"{name}.png")
    print(f"  wrote {', '.join(str(p) for p in written)}")
    return 0, cost(recording, lam) if system.report == "course_keeping" else None


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(
        prog="python -m cosim.run", description=__doc__.split("\n\n")[0],
        epilog="\n\n".join(__doc__.split("\n\n")[1:]),
        formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("scenario", nargs="?",
                        help=f"one of: {', '.join(scenarios())}; or a path to a .ssd file")
    parser.add_argument("--all", action="store_true",
                        help="run the paper's four scenarios and print Tables 1-2 beside the "
                             "paper's")
    parser.add_argument("--out", type=Path,
                        help="output folder (default: results/SCENARIO, or results/ with --all)")
    parser.add_argument("--stop-time", type=float, metavar="T",
                        help="end of the run in s (default: the scenario's, 400 s)")
    parser.add_argument("--set", action="append", default=[], type=parse_setting,
                        metavar="FMU.VAR=VALUE",
                        help="override a parameter, e.g. ship.Hs=0.01 (SI units, radians); "
                             "repeatable")
    parser.add_argument("--coupling", choices=COUPLINGS, default="gauss-seidel",
                        help="gauss-seidel: along the signal flow, as the paper's Simulink "
                             "model (default); jacobi: all FMUs on the previous step's outputs")
    parser.add_argument("--lambda", dest="lam", type=float, default=LAMBDA,
                        help=f"weight of eq (19) (default {LAMBDA:.4f}, calibrated on calm_pd)")
    parser.add_argument("--backend", choices=BACKENDS, default="fmi",
                        help="fmi: load the FMUs from fmus/ (default); inprocess: call the "
                             "FMUs' Python classes directly, without FMI")
    parser.add_argument("--no-plot", action="store_true", help="skip the figure")
    parser.add_argument("--stream", action="store_true",
                        help="write rows to the CSV in chunks as the run goes: flat memory "
                             "for long runs (--stop-time 86400); no report or figure")
    args = parser.parse_args(argv)

    if args.all == bool(args.scenario):
        parser.error("give one SCENARIO or --all")
    names = PAPER_SCENARIOS if args.all else [args.scenario]
    for name in names:
        if name.endswith(".ssd"):
            if not Path(name).is_file():
                parser.error(f"no system structure file {name}")
        elif name not in scenarios():
            parser.error(f"unknown scenario {name!r}; valid scenarios: {', '.join(scenarios())}")
    overrides: dict[str, dict] = {}
    for component, variable, value in args.set:
        overrides.setdefault(component, {})[variable] = value

    status, costs = 0, {}
    for name in names:
        out = args.out or Path("results") / Path(name).stem
        if args.all and args.out:
            out = args.out / name
        writable_folder(out)
        try:
            code, result = run_scenario(name, out, overrides, args.coupling, args.stop_time,
                                        args.lam, plot=not args.no_plot, backend=args.backend,
                                        stream=args.stream)
        except (ValueError, FileNotFoundError) as error:
            print(f"error: {error}", file=sys.stderr)
            return 2
        status = max(status, code)
        if result is not None:
            costs[name] = result
    if args.all and costs:
        print()
        print(tables(costs))
    return status


if __name__ == "__main__":
    sys.exit(main())
