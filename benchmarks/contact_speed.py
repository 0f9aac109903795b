#!/usr/bin/env python
"""Contact at the speed of the solid: two source trees side by side (`--before` and
`--after`, e.g. the branch point and this tree), each in its own child processes, in turn.

Sections (each can be run alone with --only):

* scaling   `Polyline.local` (global search + local projection + the choice of the contact
            piece) against the number of slave nodes N = 1e2 ... 1e5, on a bottle-like mould
            of 9 exact pieces (lines and arcs) and on the same outline faceted into 400
            straight pieces.  The nodes lie along the inside of the mould (the first 60 % within
            [-0.5, 2] node spacings of it, the rest bulging away, as in contact_search.py),
            their last converged positions a random step of 0.3 spacings away, depth = half a
            spacing.  Median time per call over the repeats; the projections of the two trees
            are compared (largest absolute difference of every field).
* process   whole-process wall time of `axiform run` on the three process examples
            (bottle_blow_moulding, cup_thermoforming, stretch_blow_moulding), outputs as in
            the case files; before and after in turn, `--repeat` times; min and median.
* profile   cProfile of the cup example in each tree: cumulative time of the contact
            functions and of the solid's evaluation.
* share     the share of contact in the solver's time: wall time inside the contact terms'
            evaluations (and nothing else of contact runs outside them) against the time
            inside the load path's steps (every evaluation, factorization, solve and
            predictor), over whole runs of the cup (its mesh, 2 and 4 times finer), the die
            drawing, the bottle and the stretch blow moulding, plots off.

`--examples DIR` takes the three process examples (and the share's cases) from DIR: the case
files of an older tree, which it can run, against which the whole process is measured.

Run:    python benchmarks/contact_speed.py --before OLD/src [--after src] [--repeat 3] [--examples DIR]
Writes: benchmarks/results/contact_speed.md
"""

from __future__ import annotations

import argparse
import datetime
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent
sys.path.insert(0, str(HERE))
from _perf_common import RESULTS, load_average, machine, table  # noqa: E402

EXAMPLES = ("bottle_blow_moulding", "cup_thermoforming", "stretch_blow_moulding")
SIZES = (100, 1_000, 10_000, 100_000)

SCALING_CHILD = r"""
import json, sys, time
import numpy as np
from axiform.contact.surfaces import Polyline

def mould(faceted):
    # axis -> bottom -> heel arc -> wall -> shoulder arc -> shoulder -> neck arc -> neck
    pts = [[0.0, 0.0], [0.85, 0.0], [1.0, 0.15], [1.0, 2.2], [0.8, 2.4], [0.45, 2.75],
           [0.35, 2.85], [0.35, 3.2], [0.3, 3.4], [0.0, 3.4]]
    centers = [None, (0.85, 0.15), None, (0.8, 2.2), None, (0.45 - 0.1 * 0.7071, 2.75 + 0.1 * 0.7071),
               None, None, None]
    # the shoulder arc and the neck arc as exact arcs where their ends lie on one circle
    ok = []
    for k, c in enumerate(centers):
        if c is not None:
            ra = np.hypot(*(np.subtract(pts[k], c))); rb = np.hypot(*(np.subtract(pts[k + 1], c)))
            c = c if abs(ra - rb) < 1e-9 * max(ra, 1) else None
        ok.append(c)
    surf = Polyline(points=np.array(pts), centers=ok, ccw=[True] * len(ok))
    if faceted:
        line = surf.polyline()
        s = np.concatenate([[0], np.cumsum(np.linalg.norm(np.diff(line, axis=0), axis=1))])
        q = np.linspace(0, s[-1], 401)
        surf = Polyline(points=np.column_stack([np.interp(q, s, line[:, 0]), np.interp(q, s, line[:, 1])]))
    return surf

def nodes(surf, n, rng):
    line = surf.polyline()
    seg = np.linalg.norm(np.diff(line, axis=0), axis=1)
    s = np.concatenate([[0], np.cumsum(seg)])
    q = np.linspace(0, s[-1], n)
    x = np.column_stack([np.interp(q, s, line[:, 0]), np.interp(q, s, line[:, 1])])
    tan = np.gradient(x, axis=0)
    tan /= np.maximum(np.linalg.norm(tan, axis=1), 1e-300)[:, None]
    nor = np.column_stack([-tan[:, 1], tan[:, 0]])  # towards the body
    h = s[-1] / n
    off = np.where(q < 0.6 * s[-1], rng.uniform(-0.5, 2.0, n) * h, 0.3 * np.sin(np.pi * (q / s[-1] - 0.6) / 0.4))
    x = x + off[:, None] * nor
    return x, x + rng.normal(0, 0.3 * h, (n, 2)), 0.5 * h

sizes, repeat, out = json.loads(sys.argv[1]), int(sys.argv[2]), sys.argv[3]
res = {}
saved = {}
for faceted in (False, True):
    surf = mould(faceted)
    for n in sizes:
        rng = np.random.default_rng(n)
        x, x_prev, depth = nodes(surf, n, rng)
        p = surf.local(x, x_prev, depth)
        calls = max(3, int(2e4 // n))
        # three different last converged positions in turn: every call a new step
        steps = [x_prev + rng.normal(0, 1e-3 * depth, x.shape) for _ in range(3)]
        times, times_new = [], []
        for _ in range(repeat):
            t = time.perf_counter()
            for _ in range(calls):
                surf.local(x, x_prev, depth)
            times.append((time.perf_counter() - t) / calls)
            t = time.perf_counter()
            for c in range(calls):
                surf.local(x, steps[c % 3], depth)
            times_new.append((time.perf_counter() - t) / calls)
        key = f"{len(surf.a)}/{n}"
        res[key] = {"median": float(np.median(times)), "min": float(np.min(times)),
                    "median_new": float(np.median(times_new)), "min_new": float(np.min(times_new)),
                    "active": int(p.active.sum()), "pieces": len(surf.a)}
        for f in ("active", "g", "n", "t", "s", "kappa", "m", "point", "s_prev", "kind"):
            saved[f"{key}:{f}"] = getattr(p, f)
np.savez(out, **saved)
print(json.dumps(res))
"""

PROFILE_CHILD = r"""
import cProfile, importlib, json, pstats, sys
from axiform.cli import main
case, out = sys.argv[1], sys.argv[2]
# each function by its module and qualified name: its code object names the profile's entry
# (file, first line, name); a function this tree does not have is reported as missing, not as 0
WANT = {"total": "axiform.cli:main", "solver": "axiform.solve.solver:solve",
        "contact term (ContactTerm.evaluate)": "axiform.model.terms:ContactTerm.evaluate",
        "pair.evaluate": "axiform.contact.pair:ContactPair.evaluate",
        "pair.guard": "axiform.contact.pair:ContactPair.guard",
        "pair._traction": "axiform.contact.pair:ContactPair._traction",
        "Polyline.local": "axiform.contact.surfaces:Polyline.local",
        "Polyline._project": "axiform.contact.surfaces:Polyline._project",
        "search.buckets": "axiform.contact.search:buckets",
        "ring_areas": "axiform.contact.rings:ring_areas",
        "solid (MixedAssembly.evaluate)": "axiform.fem.mixed:MixedAssembly.evaluate",
        "linear solves (factorize)": "axiform.solve.linsolve:factorize"}
def code_key(path):
    module, name = path.split(":")
    try:
        obj = importlib.import_module(module)
        for part in name.split("."):
            obj = getattr(obj, part)
    except (ImportError, AttributeError):
        return None
    code = obj.__code__
    return (code.co_filename, code.co_firstlineno, code.co_name)
keys = {label: code_key(path) for label, path in WANT.items()}
pr = cProfile.Profile(); pr.enable()
main(["run", case, "--out", out, "-q", "--set", "output.plots=false"])
pr.disable()
st = pstats.Stats(pr).stats
res = {label: None if key is None else [st[key][1], st[key][3]] if key in st else [0, 0.0]
       for label, key in keys.items()}
print("PROFILE " + json.dumps(res))
"""


SHARE_CHILD = r"""
import json, sys, time
from axiform.model import terms
from axiform.solve import paths
acc = {"contact": 0.0, "solve": 0.0}
calls = {"contact": 0, "solve": 0}
def timed(f, key):
    def wrapper(*a, **k):
        calls[key] += 1
        t = time.perf_counter()
        try:
            return f(*a, **k)
        finally:
            acc[key] += time.perf_counter() - t
    return wrapper
terms.ContactTerm.evaluate = timed(terms.ContactTerm.evaluate, "contact")
for cls in (paths.LoadPath, paths.DisplacementPath):
    for name in ("attempt", "accept"):
        setattr(cls, name, timed(getattr(cls, name), "solve"))
from axiform.cli import main
case, out, sets = sys.argv[1], sys.argv[2], json.loads(sys.argv[3])
main(["run", case, "--out", out, "-q", "--set", "output.plots=false"] + [a for v in sets for a in ("--set", v)])
if 0 in calls.values():  # the tree no longer calls a wrapped function: its share would read 0
    sys.exit(f"no call of the wrapped {[k for k, n in calls.items() if n == 0]}: update SHARE_CHILD")
print("SHARE " + json.dumps(acc))
"""
# the share's cases: (example, --set overrides, label)
SHARE_CASES = (
    ("cup_thermoforming", [], "cup (100 x 2, 101 slaves a tool)"),
    ("cup_thermoforming", ["mesh.divisions=[200,2]"], "cup 200 x 2"),
    ("cup_thermoforming", ["mesh.divisions=[400,4]"], "cup 400 x 4"),
    ("die_drawing", [], "die drawing"),
    ("bottle_blow_moulding", [], "bottle"),
    ("stretch_blow_moulding", [], "stretch blow moulding"),
)


def env_for(src: Path) -> dict:
    env = dict(os.environ, PYTHONPATH=str(src))
    env.pop("PYTHONDONTWRITEBYTECODE", None)
    return env


def fmt(t: float) -> str:
    return f"{t * 1e6:.0f} µs" if t < 1e-3 else (f"{t * 1e3:.2f} ms" if t < 1 else f"{t:.2f} s")


def section_scaling(trees: dict[str, Path], repeat: int, tmp: Path) -> str:
    runs: dict[str, list[dict]] = {name: [] for name in trees}
    npz = {}
    for _r in range(repeat):  # child processes in turn: before, after, before, ...
        for name, src in trees.items():
            out = tmp / f"scaling_{name}.npz"
            proc = subprocess.run(
                [sys.executable, "-c", SCALING_CHILD, json.dumps(SIZES), "3", str(out)],
                env=env_for(src),
                capture_output=True,
                text=True,
                check=True,
            )
            runs[name].append(json.loads(proc.stdout.strip().splitlines()[-1]))
            npz[name] = out
    a, b = (np.load(npz[n]) for n in trees)
    rows = []
    names = list(trees)
    for key in runs[names[0]][0]:
        diff = max(
            float(np.max(np.abs(a[f"{key}:{f}"].astype(float) - b[f"{key}:{f}"].astype(float)), initial=0.0))
            for f in ("active", "g", "n", "t", "s", "kappa", "m", "point", "s_prev", "kind")
        )
        row = []
        for suffix in ("", "_new"):
            med = [statistics.median(run[key]["median" + suffix] for run in runs[n]) for n in names]
            mins = [min(run[key]["min" + suffix] for run in runs[n]) for n in names]
            row += [f"{fmt(mins[0])} / {fmt(med[0])}", f"{fmt(mins[1])} / {fmt(med[1])}", f"{med[0] / med[1]:.1f}"]
        info = runs[names[0]][0][key]
        rows.append([info["pieces"], key.split("/")[1], info["active"], *row, f"{diff:.1e}"])
    return (
        "### `Polyline.local` against the number of slave nodes\n\n"
        f"Per call, min / median over {repeat} child processes per tree in turn (3 timings each).  "
        "*iteration*: the same last converged positions at every call (the iterations of a "
        "step); *new step*: different ones at every call.\n\n"
        + table(
            [
                "pieces",
                "N",
                "in contact",
                f"iteration {names[0]}",
                f"iteration {names[1]}",
                "speed-up",
                f"new step {names[0]}",
                f"new step {names[1]}",
                "speed-up",
                "max |diff|",
            ],
            rows,
        )
    )


def section_share(trees: dict[str, Path], repeat: int, tmp: Path, examples: Path) -> str:
    got: dict[tuple[str, str], list[dict]] = {}
    for _ in range(repeat):
        for example, sets, label in SHARE_CASES:
            for name, src in trees.items():
                proc = subprocess.run(
                    [
                        sys.executable,
                        "-c",
                        SHARE_CHILD,
                        str(examples / f"{example}.toml"),
                        str(tmp / f"share_{name}"),
                        json.dumps(sets),
                    ],
                    env=env_for(src),
                    capture_output=True,
                    text=True,
                    cwd=ROOT,
                    check=True,
                )
                line = next(s for s in proc.stdout.splitlines() if s.startswith("SHARE "))
                got.setdefault((label, name), []).append(json.loads(line[len("SHARE ") :]))
    names = list(trees)
    rows = []
    for _, _, label in SHARE_CASES:
        row = [label]
        for n in names:
            best = min(got[(label, n)], key=lambda a: a["solve"])
            row.append(f"{best['contact']:.2f} / {best['solve']:.2f} s = {best['contact'] / best['solve']:.0%}")
        rows.append(row)
    return (
        "### The share of contact in the solver's time\n\n"
        f"Contact evaluations / the load path's steps, wall time, the run with the shortest solve of {repeat}, "
        "plots off, the trees in turn.\n\n" + table(["case"] + names, rows)
    )


def section_process(trees: dict[str, Path], repeat: int, tmp: Path, examples: Path) -> str:
    times: dict[tuple[str, str], list[float]] = {}
    steps = {}
    for _r in range(repeat):
        for ex in EXAMPLES:
            for name, src in trees.items():
                out = tmp / f"{ex}_{name}"
                t = time.perf_counter()
                proc = subprocess.run(
                    [sys.executable, "-m", "axiform.cli", "run", str(examples / f"{ex}.toml"), "--out", str(out), "-q"],
                    env=env_for(src),
                    capture_output=True,
                    text=True,
                    cwd=ROOT,
                )
                wall = time.perf_counter() - t
                if proc.returncode:
                    raise RuntimeError(proc.stdout[-2000:] + proc.stderr[-2000:])
                times.setdefault((ex, name), []).append(wall)
                status = [s for s in (proc.stdout + proc.stderr).splitlines() if s.startswith("axiform:")]
                steps[(ex, name)] = status[-1].split(",")[0:2]
    names = list(trees)
    rows = []
    for ex in EXAMPLES:
        row = [
            ex,
            " → ".join(
                ", ".join(s.strip() for s in steps[(ex, n)]).replace("axiform: finished after ", "") for n in names
            ),
        ]
        for n in names:
            row.append(f"{min(times[(ex, n)]):.1f} / {statistics.median(times[(ex, n)]):.1f} s")
        row.append(f"{statistics.median(times[(ex, names[0])]) / statistics.median(times[(ex, names[1])]):.2f}")
        rows.append(row)
    return (
        "### Whole process, the three process examples\n\n"
        f"`axiform run {examples}/NAME.toml --out DIR -q` (outputs as in the case files, plots included), "
        f"wall time min / median of {repeat} runs, the trees in turn.\n\n"
        + table(["example", "steps, iterations", names[0], names[1], "speed-up (median)"], rows)
    )


def section_profile(trees: dict[str, Path], tmp: Path) -> str:
    res = {}
    for name, src in trees.items():
        proc = subprocess.run(
            [
                sys.executable,
                "-c",
                PROFILE_CHILD,
                str(ROOT / "examples" / "cup_thermoforming.toml"),
                str(tmp / f"prof_{name}"),
            ],
            env=env_for(src),
            capture_output=True,
            text=True,
            cwd=ROOT,
            check=True,
        )
        line = next(s for s in (proc.stdout + proc.stderr).splitlines() if s.startswith("PROFILE "))
        res[name] = json.loads(line[len("PROFILE ") :])
    names = list(trees)
    rows = [
        [label]
        + [f"{res[n][label][1]:.2f} s ({res[n][label][0]})" if res[n][label] else "not in the tree" for n in names]
        for label in res[names[0]]
    ]
    return (
        "### Profile of the cup example (cProfile, cumulative seconds and calls)\n\n"
        "cProfile adds a cost to every Python call: the many small calls of contact weigh more "
        "than they do unprofiled.\n\n" + table(["function"] + names, rows)
    )


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--before", type=Path, required=True, help="src/ of the tree before (e.g. the branch point)")
    ap.add_argument("--after", type=Path, default=ROOT / "src", help="src/ of the tree after (default: this tree)")
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--only", choices=["scaling", "process", "profile", "share"], action="append")
    ap.add_argument(
        "--examples",
        type=Path,
        default=ROOT / "examples",
        help="the folder of the case files run by 'process' and 'share' (default: this tree's)",
    )
    args = ap.parse_args()
    trees = {"before": args.before.resolve(), "after": args.after.resolve()}
    only = args.only or ["scaling", "process", "profile", "share"]
    examples = args.examples.resolve()
    parts = [
        f"## Contact speed, before / after ({datetime.datetime.now(datetime.UTC):%Y-%m-%d %H:%M} UTC)\n",
        f"Machine: {machine()}; load average at the start {load_average()}.\n",
        f"before: `{trees['before']}`, after: `{trees['after']}`.\n",
    ]
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        if "scaling" in only:
            parts.append(section_scaling(trees, args.repeat, tmp))
        if "process" in only:
            parts.append(section_process(trees, args.repeat, tmp, examples))
        if "share" in only:
            parts.append(section_share(trees, args.repeat, tmp, examples))
        if "profile" in only:
            parts.append(section_profile(trees, tmp))
    parts.append(f"Load average at the end: {load_average()}.\n")
    text = "\n".join(parts)
    RESULTS.mkdir(exist_ok=True)
    name = "contact_speed" + ("" if len(only) == 4 else "_" + "_".join(only))
    (RESULTS / f"{name}.md").write_text(text)
    print(text)


if __name__ == "__main__":
    main()
