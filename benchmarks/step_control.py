#!/usr/bin/env python
"""Steps, failed attempts, Newton iterations, model evaluations and solve time of examples,
with two source trees side by side (interleaved repeats, the minimum time of each).

    python benchmarks/step_control.py --before OLD/src [--after src] [--before-examples OLD/examples]
        [--repeat 1] [EXAMPLE ...]   (default: the examples whose runs cut a step before this study)

Each run is `solve` on the example's case as `axiform run` builds it, in a process of its own
with PYTHONPATH set to the tree; the paths' `attempt` is wrapped to count the attempted steps
(failed = attempted - converged) and System.evaluate to count the model evaluations (Newton
iterations, line-search halvings, predictors and failed attempts together).  `asked`: the
case's solver.steps.  --before-examples: a folder of examples the old tree runs instead (those
whose settings changed with the study; the others from examples/).  Prints a markdown table.

    python benchmarks/step_control.py --optimize [--before OLD/src] [--repeat 3]

The heater example's optimize against plain runs of it (the goal: at most 8 forward
runs' time): each repeat runs, for each tree in turn (the one of --before, if given, then
--after), `axiform run examples/cup_heater_programming.toml` (its default outputs) and
`axiform optimize` on it as docs/guide.md gives it (`--vary temperature`, the target
examples/cup_heater_target.csv), whole processes, one thread per library.  The table: per
tree the least wall and CPU time (user + system of the child) of each over the repeats,
their ratio optimize / plain run (of the least times, and the least of the repeats' own
ratios), the forward solves and the max deviation of optimize.json.
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
HEATER = ROOT / "examples" / "cup_heater_programming.toml"
HEATER_TARGET = ROOT / "examples" / "cup_heater_target.csv"
EXAMPLES = (
    "cup_heater_programming",
    "cup_thermoforming",
    "cup_cold_mould",
    "dxf_cup_mould",
    "bottle_blow_moulding",
    "stretch_blow_moulding",
    "parison_bottle",
    "die_drawing",
)

WORKER = r"""
import json, sys, time
from pathlib import Path
from axiform.case.schema import build, parse, read
from axiform.model.system import System
import axiform.solve.paths as paths
import axiform.solve.arc_length as arc
from axiform.solve.solver import solve

case = Path(sys.argv[1])
built = build(parse(read(case, [])), case.parent)
count = {"attempts": 0, "evaluations": 0}
for cls in (paths.LoadPath, paths.DisplacementPath, arc.ArcLengthPath):
    def attempt(self, size, _orig=cls.attempt):
        count["attempts"] += 1
        return _orig(self, size)
    cls.attempt = attempt
evaluate = System.evaluate
def counted(self, *args, **kwargs):
    count["evaluations"] += 1
    return evaluate(self, *args, **kwargs)
System.evaluate = counted
t = time.perf_counter()
result = solve(built.model, built.control, built.options, keep=1)
seconds = time.perf_counter() - t
print(json.dumps({
    "status": result.status, "steps": result.n_steps, "asked": getattr(built.control, "steps", 0),
    "failed": count["attempts"] - result.n_steps, "iterations": result.newton_iterations,
    "evaluations": count["evaluations"], "seconds": seconds,
}))
"""


def measure(src: Path, folder: Path, example: str) -> dict:
    env = dict(os.environ, PYTHONPATH=str(src), OMP_NUM_THREADS="1", OPENBLAS_NUM_THREADS="1", MKL_NUM_THREADS="1")
    case = folder / f"{example}.toml"
    if not case.exists():  # the example did not change
        case = ROOT / "examples" / f"{example}.toml"
    out = subprocess.run(
        [sys.executable, "-c", WORKER, str(case)], env=env, cwd=ROOT, check=True, capture_output=True, text=True
    )
    return json.loads(out.stdout.strip().splitlines()[-1])


def optimize_against_runs(trees: dict[str, Path], repeat: int) -> None:
    """The heater example's optimize against plain runs, side by side (module docstring)."""
    sys.path.insert(0, str(ROOT / "benchmarks"))
    from speed import env_for, timed

    times: dict[str, dict[str, list[tuple[float, float]]]] = {name: {"run": [], "optimize": []} for name in trees}
    found: dict[str, dict] = {}
    with tempfile.TemporaryDirectory() as tmp:
        for r in range(repeat):
            for name, src in trees.items():
                env = env_for(src.resolve())
                out = Path(tmp) / f"{name}-{r}"
                cli = [sys.executable, "-m", "axiform.cli"]
                times[name]["run"].append(timed([*cli, "run", str(HEATER), "--out", str(out / "run"), "-q"], env)[:2])
                opt = [*cli, "optimize", str(HEATER), "--target", str(HEATER_TARGET), "--vary", "temperature"]
                times[name]["optimize"].append(timed([*opt, "--out", str(out / "opt"), "-q"], env)[:2])
                found[name] = json.loads((out / "opt" / "optimize.json").read_text())
                run, optimize = times[name]["run"][-1], times[name]["optimize"][-1]
                print(f"# {name} {r + 1}: run {run[0]:.1f} s, optimize {optimize[0]:.1f} s wall", file=sys.stderr)
    print(
        "| tree | plain run s (wall / CPU) | optimize s (wall / CPU) | optimize / run, least times (wall / CPU) "
        "| least of the repeats' ratios (wall / CPU) | forward solves | max deviation |\n"
        "|---|---:|---:|---:|---:|---:|---:|"
    )
    for name in trees:
        run, opt = times[name]["run"], times[name]["optimize"]
        least = [(min(t[i] for t in run), min(t[i] for t in opt)) for i in (0, 1)]
        paired = [min(o[i] / p[i] for p, o in zip(run, opt, strict=True)) for i in (0, 1)]
        print(
            f"| {name} | {least[0][0]:.1f} / {least[1][0]:.1f} | {least[0][1]:.1f} / {least[1][1]:.1f} "
            f"| {least[0][1] / least[0][0]:.2f} / {least[1][1] / least[1][0]:.2f} "
            f"| {paired[0]:.2f} / {paired[1]:.2f} | {found[name]['forward_solves']} "
            f"| {100 * found[name]['max_rel_deviation']:.3f} % |"
        )


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--before", type=Path)
    ap.add_argument("--after", type=Path, default=ROOT / "src")
    ap.add_argument("--before-examples", type=Path, default=ROOT / "examples")
    ap.add_argument("--repeat", type=int, default=1)
    ap.add_argument("--optimize", action="store_true", help="the heater's optimize against plain runs")
    ap.add_argument("examples", nargs="*", default=list(EXAMPLES))
    args = ap.parse_args()
    if args.optimize:
        trees = {"before": args.before} if args.before else {}
        optimize_against_runs({**trees, "after": args.after}, args.repeat)
        return
    if args.before is None:
        ap.error("--before is required (but with --optimize)")
    print(
        "| example | asked | steps before → after | failed attempts | Newton iterations | evaluations "
        "| solve s (min) | time after / before |\n|---|---:|---:|---:|---:|---:|---:|---:|"
    )
    for ex in args.examples:
        runs: dict[str, list[dict]] = {"before": [], "after": []}
        for _ in range(args.repeat):
            for name, src, folder in (
                ("before", args.before, args.before_examples),
                ("after", args.after, ROOT / "examples"),
            ):
                runs[name].append(measure(src.resolve(), folder.resolve(), ex))
        b, a = runs["before"][0], runs["after"][0]
        tb = min(r["seconds"] for r in runs["before"])
        ta = min(r["seconds"] for r in runs["after"])
        status = "" if a["status"] == b["status"] == "finished" else f" ({b['status']} → {a['status']})"
        print(
            f"| {ex}{status} | {a['asked']} | {b['steps']} → {a['steps']} | {b['failed']} → {a['failed']} "
            f"| {b['iterations']} → {a['iterations']} | {b['evaluations']} → {a['evaluations']} "
            f"| {tb:.1f} → {ta:.1f} | {ta / tb:.2f} |"
        )


if __name__ == "__main__":
    main()
