"""python -m cosim.train: a heading autopilot learned on the ship's vector environment by the
cross-entropy method (numpy only), scored against the PD on wave seeds it never saw, and
built as an autopilot FMU, FMI 2.0 and 3.0 (docs/rl.md).

  python -m cosim.train                              # waves_pd, a tanh layer of 8, ~5 min
  python -m cosim.train --hidden --name linear       # a linear policy: a PD with a bias
  python -m cosim.run waves_pd --autopilot results/rl/learned.fmu   # then as any FMU
"""
import argparse
import sys
import time
from pathlib import Path

from tqdm import tqdm

from autopilot_fmu.policy import Policy
from fmubuild.project import FMU_DIR

from ._cli import count, entry, say_error, writable_folder
from .analysis.figures import comparison, save
from .analysis.metrics import cost
from .api import simulate
from .core.files import OutputError, whole_file
from .rl.cem import PD, TRAIN_SEEDS, Settings, average, evaluate, train
from .rl.policy_fmu import build_policy_fmu, checked_name
from .rl.report import learning_figure, policy_figure, table


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m cosim.train",
                                     description=__doc__.split("\n\n")[0],
                                     epilog="\n\n".join(__doc__.split("\n\n")[1:]),
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    default = Settings()
    parser.add_argument("--scenario", default=default.scenario,
                        help="a course-keeping scenario of this project (default waves_pd)")
    parser.add_argument("--hidden", type=count, nargs="*", default=list(default.hidden),
                        metavar="N", help="widths of the tanh layers (default: one of 8; "
                                          "none: a linear policy, a PD with a bias)")
    parser.add_argument("--generations", type=count, default=default.generations,
                        help=f"default {default.generations}")
    parser.add_argument("--population", type=count, default=default.population,
                        help=f"candidates per generation, at least 4 (default "
                             f"{default.population})")
    parser.add_argument("--seeds", type=count, default=default.seeds,
                        help="wave seeds per candidate and generation (generation g: "
                             f"{TRAIN_SEEDS} + g SEEDS ...; default {default.seeds})")
    parser.add_argument("--seed", type=int, default=0,
                        help="of the candidates' draws (default 0)")
    parser.add_argument("--eval-seeds", type=count, default=20,
                        help="score on wave seeds 1 .. N, which training never sees (default "
                             "20)")
    parser.add_argument("--name", default="learned",
                        help="the FMU's model and the files' names, an identifier (default "
                             "learned)")
    parser.add_argument("--out", type=Path, default=Path("results/rl"),
                        help="output folder (default results/rl)")
    args = parser.parse_args(argv)
    seeds = list(range(1, args.eval_seeds + 1))
    try:
        settings = Settings(args.scenario, tuple(args.hidden), args.population, args.seeds,
                            args.generations, seed=args.seed)
        name, out = checked_name(args.name), writable_folder(args.out)
        started = time.perf_counter()
        with tqdm(total=args.generations, desc="training", unit="generation", file=sys.stderr,
                  disable=None) as bar:
            policy, curve = train(settings, lambda g, c: (
                bar.update(), bar.set_postfix_str(f"best J {c.best[-1]:.1f}")))
        minutes = (time.perf_counter() - started) / 60
        J = evaluate({"PD (eq 20)": PD, name: policy}, args.scenario, seeds)
        about = {"scenario": args.scenario, "trained_on_wave_seeds": [
                     TRAIN_SEEDS, TRAIN_SEEDS + args.generations * args.seeds - 1],
                 "settings": vars(settings), "minutes": round(minutes, 2),
                 "J_mean": {k: average(v) for k, v in J.items()},
                 "evaluated_on_wave_seeds": [seeds[0], seeds[-1]]}
        with whole_file(out / f"{name}.json") as tmp:
            tmp.write_text(policy.to_json(**about))
        fmus = [build_policy_fmu(policy, out / sub / f"{name}.fmu", fmi, **about)
                for sub, fmi in (("", 2), ("fmi3", 3))]
        pd_mean = average(J["PD (eq 20)"])
        trained = evaluate({"PD": PD}, args.scenario, range(TRAIN_SEEDS, about[
            "trained_on_wave_seeds"][1] + 1))["PD"]
        figures = save(learning_figure(curve, average(trained), f"{name} on "
                                       f"{args.scenario}, {args.population} candidates x "
                                       f"{args.seeds} seeds a generation"),
                       out / f"{name}_learning.png")
        runs = {label: simulate(args.scenario, fmu, {"ship.wave_seed": seeds[0]})
                for label, fmu in (("PD (eq 20)", FMU_DIR / "pd_autopilot.fmu"),
                                   (name, fmus[0]))}
        figures += save(comparison(runs, f"{args.scenario}, wave seed {seeds[0]}: PD and "
                                   f"{name}"), out / f"{name}_vs_pd.png")
        figures += save(policy_figure({"PD (eq 20)": PD, name: policy}, runs[name], (
            f"the rudder commands; shaded: where {name} kept the ship on {args.scenario}, "
            f"wave seed {seeds[0]}")), out / f"{name}_map.png")
    except (ValueError, FileNotFoundError, OutputError) as error:
        say_error(error)
        return 2
    print("\n".join([f"trained in {minutes:.1f} min: {Policy.count(settings.hidden)} "
                      f"weights, tanh layers "
                      f"{list(settings.hidden)}", "",
                     *table(J, seeds), "",
                     f"through its FMU, wave seed {seeds[0]}: J = {cost(runs[name]).J:.4f} "
                     f"(the environment: {J[name][0]:.4f}; PD {pd_mean:.2f} on average)",
                     f"wrote {out / f'{name}.json'}, {', '.join(map(str, [*fmus, *figures]))}"]))
    return 0


if __name__ == "__main__":
    sys.exit(entry(main))
