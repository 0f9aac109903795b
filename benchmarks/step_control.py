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
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
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


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--before", type=Path, required=True)
    ap.add_argument("--after", type=Path, default=ROOT / "src")
    ap.add_argument("--before-examples", type=Path, default=ROOT / "examples")
    ap.add_argument("--repeat", type=int, default=1)
    ap.add_argument("examples", nargs="*", default=list(EXAMPLES))
    args = ap.parse_args()
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
