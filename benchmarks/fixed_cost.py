#!/usr/bin/env python
"""The fixed cost of a run beside the import floor: the paper's plate (`make demo`) as a whole
process, its solve, and its pictures, side by side in one run (the goals: the fixed cost at
most 1.5x the floor, the pictures 1.5x more).

    python benchmarks/fixed_cost.py [--repeat 5] [--before OLD/src] [--case CASE.toml] [--fixed-only]

Each repeat runs, in turn (and for each source tree when --before is given):
- floor: `python -c "import numpy, scipy.sparse"`;
- off: `axiform run CASE -q` with output.vtu and output.plots off;
- vtu: the same with the VTU series on (plots off);
- default: the case's default outputs (VTU and the three pictures);
- and, to read the others by: the imports of a run (`axiform.app.run`, the case schema and
  the plate's tables, the results writer, the solver), the schema library's own floor (pydantic
  imported, one model made, one value validated) and matplotlib's imports (`matplotlib.figure`,
  its Agg canvas), each beside NumPy and scipy.sparse, less the floor.
A run is `axiform.cli.main` in a fresh Python, whose `solve`
is wrapped to record its wall and CPU time (the solve as summary.json's wall_time_s counts it:
the steps and their per-step files), and the results writer's `_plot` (the three pictures,
matplotlib's import included).
Wall time is measured from outside, CPU time is user + system of the child process.  The
table gives the least of the repeats of each quantity: the fixed cost (whole process minus
its solve, per run, then the least), the pictures (timed in the run; default minus vtu as a
check) and the VTU series (vtu minus off), each also as a multiple of the floor.  The runs
write their bytecode caches (PYTHONDONTWRITEBYTECODE is dropped), as an installed axiform has
them; one unmeasured run of each tree comes first.  --fixed-only: the floor, a run's imports,
the schema library's floor and the run with outputs off alone (the fixed cost's rows of the table).
"""

from __future__ import annotations

import argparse
import json
import math
import os
import sys
import tempfile
from pathlib import Path

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent
sys.path.insert(0, str(HERE))
from speed import timed  # noqa: E402  (wall, CPU of the child, its output)

OFF = ["--set", "output.plots=false", "--set", "output.vtu=false"]
KINDS = {"off": OFF, "vtu": ["--set", "output.plots=false"], "default": []}
IMPORTS = {
    "floor": "import numpy, scipy.sparse",
    "imports": "import numpy, scipy.sparse, axiform.app.run, axiform.case.schema, axiform.case.material, "
    "axiform.case.monitor, axiform.io.results, axiform.solve.solver",
    "mpl": "import numpy, scipy.sparse, matplotlib.figure, matplotlib.backends.backend_agg",
    # the schema library's own floor: pydantic imported, one model made and one value validated
    "schema": "import numpy, scipy.sparse, pydantic\n"
    "class A(pydantic.BaseModel):\n    x: float\nA.model_validate({'x': 1.0})",
}

# the child: axiform's command line, its solve and its pictures (the results writer's _plot)
# timed (wall, CPU) into the file argv[1]
CHILD = """
import sys, time, json
import axiform.solve.solver as s
import axiform.io.results as r
spans = {"solve": [], "pictures": []}
def timing(name, inner):
    def timed(*a, **k):
        w, c = time.perf_counter(), time.process_time()
        try:
            return inner(*a, **k)
        finally:
            spans[name].append((time.perf_counter() - w, time.process_time() - c))
    return timed
s.solve = timing("solve", s.solve)
r.ResultsWriter._plot = timing("pictures", r.ResultsWriter._plot)
import axiform.cli
try:
    code = axiform.cli.main(sys.argv[2:])
finally:
    open(sys.argv[1], "w").write(json.dumps(spans))
sys.exit(code)
"""


def measure(src: Path, case: Path, work: Path, kind: str) -> dict[str, float]:
    """One process of `kind` (floor, imports, mpl, off, vtu, default): its wall and CPU, and
    for a run its solve's wall and CPU."""
    env = dict(os.environ, PYTHONPATH=str(src))
    env.pop("PYTHONDONTWRITEBYTECODE", None)
    if kind in IMPORTS:
        wall, cpu, _ = timed([sys.executable, "-c", IMPORTS[kind]], env, ROOT)
        return {"wall": wall, "cpu": cpu}
    spans = work / "solve.json"
    out = work / kind
    argv = ["run", str(case), "--out", str(out), "-q", *KINDS[kind]]
    wall, cpu, _ = timed([sys.executable, "-c", CHILD, str(spans), *argv], env, ROOT)
    timings = json.loads(spans.read_text())
    (solve_wall, solve_cpu), *_ = timings["solve"]
    out = {"wall": wall, "cpu": cpu, "solve_wall": solve_wall, "solve_cpu": solve_cpu}
    if timings["pictures"]:
        out["pictures_wall"], out["pictures_cpu"] = timings["pictures"][0]
    return out


def least(runs: list[dict[str, float]], key) -> float:
    return min(key(r) for r in runs)


def summary(runs: dict[str, list[dict[str, float]]]) -> dict[str, float]:
    """The least of the repeats: floor, whole processes, solve, fixed cost, pictures, VTU, the
    imports above the floor (wall and CPU); NaN for what was not run."""
    nan = float("nan")
    out = {}
    for clock in ("wall", "cpu"):
        floor = least(runs["floor"], lambda r, c=clock: r[c])
        for kind in ("imports", "schema", "mpl"):
            out[f"{kind}_{clock}"] = least(runs[kind], lambda r, c=clock: r[c]) - floor if runs[kind] else nan
        off = least(runs["off"], lambda r, c=clock: r[c])
        vtu = least(runs["vtu"], lambda r, c=clock: r[c]) if runs["vtu"] else nan
        default = least(runs["default"], lambda r, c=clock: r[c]) if runs["default"] else nan
        pictures = least(runs["default"], lambda r, c=clock: r[f"pictures_{c}"]) if runs["default"] else nan
        out |= {
            f"floor_{clock}": floor,
            f"off_{clock}": off,
            f"solve_{clock}": least(runs["off"], lambda r, c=clock: r[f"solve_{c}"]),
            f"fixed_{clock}": least(runs["off"], lambda r, c=clock: r[c] - r[f"solve_{c}"]),
            f"vtu_{clock}": vtu - off,
            f"pictures_{clock}": pictures,
            f"difference_{clock}": default - vtu,
            f"default_{clock}": default,
        }
    return out


def table(results: dict[str, dict[str, float]]) -> str:
    """A markdown table: a column per tree and clock, the ratios to the floor beneath."""
    heads = [(label, clock) for label in results for clock in ("cpu", "wall")]
    lines = [
        "| quantity (s; least of the repeats) | " + " | ".join(f"{label} {clock}" for label, clock in heads) + " |",
        "|---|" + "---:|" * len(heads),
    ]
    names = {
        "floor": "import floor `python -c 'import numpy, scipy.sparse'`",
        "off": "whole process, VTU and plots off",
        "solve": "its solve",
        "fixed": "**fixed cost** (whole process minus solve)",
        "vtu": "the VTU series (vtu minus off)",
        "pictures": "**the three pictures** (the writer's plotting, timed in the run)",
        "difference": "the same as default minus vtu (two least values: noisier)",
        "default": "whole process, default outputs",
        "imports": "a run's imports (app.run, the plate's case tables, writer, solver), less the floor",
        "schema": "pydantic's import, one model and one validation, less the floor",
        "mpl": "matplotlib's imports (figure, Agg canvas), less the floor",
    }
    names = {k: v for k, v in names.items() if not all(math.isnan(results[lb][f"{k}_{c}"]) for lb, c in heads)}
    for key, name in names.items():  # the rows of what was run
        lines.append(f"| {name} | " + " | ".join(f"{results[lb][f'{key}_{c}']:.3f}" for lb, c in heads) + " |")
    for key in [k for k in ("fixed", "pictures", "imports", "schema", "mpl") if k in names]:
        lines.append(
            f"| {key} / floor | "
            + " | ".join(f"**{results[lb][f'{key}_{c}'] / results[lb][f'floor_{c}']:.2f}**" for lb, c in heads)
            + " |"
        )
    return "\n".join(lines)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=5)
    parser.add_argument("--before", type=Path, help="another source tree (its src/), run in turn with this one")
    parser.add_argument("--after", type=Path, default=ROOT / "src")
    parser.add_argument("--case", type=Path, default=ROOT / "examples" / "hughes_carnoy_plate.toml")
    parser.add_argument("--fixed-only", action="store_true", help="the fixed cost's rows alone")
    args = parser.parse_args()
    trees = {"after": args.after.resolve()}
    if args.before is not None:
        trees = {"before": args.before.resolve(), **trees}
    everything = ("floor", "imports", "schema", "mpl", "off", "vtu", "default")
    kinds = ("floor", "imports", "schema", "off") if args.fixed_only else everything
    runs: dict[str, dict[str, list[dict[str, float]]]] = {label: {kind: [] for kind in everything} for label in trees}
    print(f"load average at start: {os.getloadavg()[0]:.2f}", flush=True)
    with tempfile.TemporaryDirectory(prefix="axiform-fixed-cost-") as tmp:
        work = {label: Path(tmp) / label for label in trees}
        for label, src in trees.items():  # bytecode caches written, nothing measured
            work[label].mkdir()
            measure(src, args.case.resolve(), work[label], kinds[-1])
        for _ in range(args.repeat):
            for kind in kinds:
                for label, src in trees.items():
                    runs[label][kind].append(measure(src, args.case.resolve(), work[label], kind))
    print(f"load average at end: {os.getloadavg()[0]:.2f}\n")
    results = {label: summary(r) for label, r in runs.items()}
    print(f"{args.case.name}, {args.repeat} repeats, {os.cpu_count()} cores\n")
    print(table(results))


if __name__ == "__main__":
    main()
