#!/usr/bin/env python
"""The paper's plate against FElupe at every size from 1e3 to 2e4 dofs, whole processes side
by side (the goal: axiform at most 0.15 x FElupe, its solve growing no faster than n^1.2).

    .venv/bin/python benchmarks/plate_scaling.py                       # 5 meshes, about 15 min
    .venv/bin/python benchmarks/plate_scaling.py --meshes 4x40 --repeat 1   # smoke run
    .venv/bin/python benchmarks/plate_scaling.py --before OLD/src      # also another source tree

Each mesh NZxNR (Q8, NZ elements through the thickness, NR along the radius, as
validation/plate_peers.py): `axiform run examples/hughes_carnoy_plate.toml` with Q8, the mesh,
VTU and plots off (40 displacement steps to w = 8 in; its history.csv, summary.json,
thickness.csv and checkpoint are written), a fresh Python each time; then FElupe (a fresh
Python: import, the same mesh, Q8 axisymmetric, the same Mooney-Rivlin and follower pressure,
Newton to 1e-8) loaded through axiform's 40 converged pressures, so that both give the same
40 points of the load curve: the largest |w_FElupe - w_axiform| over them is printed
("matched"). FElupe's solve is its load loop; axiform's solve is also timed alone, in a
process of its own on the same case (the solve's CPU time: the machine is shared, and the
CPU time of a single-threaded computation is steadier than its wall time). All on one
thread (OMP/MKL/OpenBLAS_NUM_THREADS=1). axiform runs `--repeat` times and FElupe
`--felupe-repeat` times, interleaved; the minimum CPU and wall time of each is reported, the
ratios and exponents of the CPU times first.  `--felupe-from RESULTS.json` takes FElupe's
runs from an earlier run's results instead of running it again.  `--inside` times the parts
of axiform's solve instead (a fresh Python per tree, mesh and repeat, interleaved): the CPU
time of its factorizations (with the symmetry check), of its solves with them and of its
evaluations (a deferred tangent counted with the evaluation that reads it), and how many
evaluations and tangents it made (the least of the repeats).
Growth: the exponent a of t ~ n^a from one mesh to the next and over all of them (a
least-squares line through log t against log n).

Writes benchmarks/results/plate_scaling.md (`--out NAME` for another name).
"""

from __future__ import annotations

import argparse
import csv
import json
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent
sys.path.insert(0, str(HERE))
from speed import FELUPE_PLATE, env_for, machine, md_table, timed  # noqa: E402

PLATE = ROOT / "examples" / "hughes_carnoy_plate.toml"

FELUPE_SCRIPT = (
    r"""
import sys, time, warnings
t_start = time.perf_counter()
import numpy as np
import felupe as fem
warnings.filterwarnings("ignore")
R, H = 7.5, 0.5
nr, nz = int(sys.argv[1]), int(sys.argv[2])
pressures = np.loadtxt(sys.argv[3], ndmin=1)
"""
    + FELUPE_PLATE
    + r"""
its, w = 0, []
t_solve, c_solve = time.perf_counter(), time.process_time()
for p in pressures:
    pressure.update(float(p))
    res = newton(items=[solid, pressure], x0=field, dof1=dof1, dof0=dof0, ext0=ext0, tol=1e-8, verbose=0)
    field.link(res.x)
    its += int(res.iterations)
    w.append(float(field[0].values[centre, 0]))
t_end, c_end = time.perf_counter(), time.process_time()
import json
print("FELUPE " + json.dumps({"dofs": int(len(dof1)), "iterations": its, "w": w, "solve_s": t_end - t_solve,
                              "solve_cpu": c_end - c_solve}))
"""
)


SOLVE_SCRIPT = r"""
import json, sys, time
from pathlib import Path
sys.path.insert(0, sys.argv[1])
from axiform.case.schema import build, load
from axiform.solve.solver import solve
case = Path(sys.argv[2])
built = build(load(case, json.loads(sys.argv[3])), case.parent)
c, t = time.process_time(), time.perf_counter()
result = solve(built.model, built.control, built.options)
print("SOLVE " + json.dumps({"cpu": time.process_time() - c, "wall": time.perf_counter() - t}))
"""


INSIDE_SCRIPT = r"""
import json, sys, time
from pathlib import Path
sys.path.insert(0, sys.argv[1])
import axiform.solve.linsolve as ls
from axiform.case.schema import build, load
from axiform.model.system import System
from axiform.solve.solver import solve
cpu = {"factorize": 0.0, "solve": 0.0, "evaluate": 0.0, "factorizations": 0, "evaluations": 0, "tangents": 0}
factorize, evaluate, depth = ls.LinearSolver.factorize, System.evaluate, [0]
def timed_factorize(self, K):
    c = time.process_time()
    f = factorize(self, K)
    cpu["factorize"] += time.process_time() - c
    cpu["factorizations"] += 1
    def timed_solve(b):
        c = time.process_time()
        x = f(b)
        cpu["solve"] += time.process_time() - c
        return x
    return timed_solve
def timed_evaluate(self, *args, **kw):
    depth[0] += 1
    c = time.process_time()
    try:
        ev = evaluate(self, *args, **kw)
    finally:
        depth[0] -= 1
    if depth[0] == 0:
        cpu["evaluate"] += time.process_time() - c
        cpu["evaluations"] += 1
    tangent = kw.get("tangent", args[3] if len(args) > 3 else True)
    cpu["tangents"] += bool(tangent and not kw.get("deferred"))
    return ev
ls.LinearSolver.factorize, System.evaluate = timed_factorize, timed_evaluate
case = Path(sys.argv[2])
built = build(load(case, json.loads(sys.argv[3])), case.parent)
c = time.process_time()
solve(built.model, built.control, built.options)
print("INSIDE " + json.dumps(cpu | {"total": time.process_time() - c}))
"""


def inside(meshes: list[str], trees: dict, repeat: int, tmp: Path) -> str:
    """The table of `--inside`: per mesh and tree the least CPU time of the whole solve, of its
    factorizations, solves and evaluations over the repeats, and its counts."""
    script = tmp / "inside.py"
    script.write_text(INSIDE_SCRIPT)
    best: dict[tuple[str, str], dict] = {}
    for mesh in meshes:
        nr, nz = parse_mesh(mesh)
        sets = [f"mesh.element={json.dumps('q8')}", f"mesh.divisions=[{nr},{nz}]"]
        for _ in range(repeat):
            for name, src in trees.items():
                _, _, out = timed([sys.executable, str(script), str(src), str(PLATE), json.dumps(sets)], env_for(src))
                run = json.loads(out[out.index("INSIDE ") + 7 :].split("\n")[0])
                held = best.setdefault((mesh, name), run)
                best[mesh, name] = {k: min(v, held[k]) for k, v in run.items()}
            print(f"{mesh}: " + ", ".join(f"{n} {best[mesh, n]['total']:.2f} s" for n in trees), flush=True)
    parts = ("total", "factorize", "solve", "evaluate")
    header = ["mesh", "tree"] + [f"{k} s (CPU)" for k in parts] + ["factorizations", "evaluations", "tangents"]
    rows = [
        [m, n] + [f"{best[m, n][k]:.3f}" for k in parts] + [best[m, n][k] for k in header[6:]]
        for m in meshes
        for n in trees
    ]
    return md_table(header, rows)


def parse_mesh(name: str) -> tuple[int, int]:
    """'4x40' (through the thickness x along the radius) -> (nr, nz) = (40, 4)."""
    nz, nr = (int(v) for v in name.lower().split("x"))
    return nr, nz


def run_axiform(src: Path, nr: int, nz: int, out: Path, script: Path) -> dict:
    """One `axiform run` of the plate on src (wall and CPU time of the process, its steps,
    iterations, dofs and load curve (w, load factor)), then the same case's solve alone in
    another process (`script`: SOLVE_SCRIPT), its CPU and wall time."""
    sets = [f"mesh.element={json.dumps('q8')}", f"mesh.divisions=[{nr},{nz}]", "output.vtu=false"]
    sets += ["output.plots=false"]
    cmd = [sys.executable, "-m", "axiform.cli", "run", str(PLATE), "-q", "--out", str(out)]
    for s in sets:
        cmd += ["--set", s]
    wall, cpu, _ = timed(cmd, env_for(src))
    summary = json.loads((out / "summary.json").read_text())
    with open(out / "history.csv") as f:
        rows = [r for r in csv.DictReader(f) if not r["step"].startswith("#")]
    _, _, printed = timed([sys.executable, str(script), str(src), str(PLATE), json.dumps(sets)], env_for(src))
    solve = json.loads(printed[printed.index("SOLVE ") + 6 :].split("\n")[0])
    return {
        "wall": wall,
        "cpu": cpu,
        "solve": solve["cpu"],
        "solve_wall": solve["wall"],
        "steps": int(summary["steps"]),
        "iterations": int(summary["newton_iterations"]),
        "dofs": int(summary["free_dofs"]),
        "w": [float(r["w_center"]) for r in rows[1:]],
        "p": [float(r["load_factor"]) for r in rows[1:]],
    }


def run_felupe(script: Path, nr: int, nz: int, pressures: Path) -> dict:
    wall, cpu, out = timed([sys.executable, str(script), str(nr), str(nz), str(pressures)], env_for(ROOT / "src"))
    result = json.loads(out[out.index("FELUPE ") + 7 :].split("\n")[0])
    return result | {"wall": wall, "cpu": cpu, "solve": result["solve_cpu"], "solve_wall": result["solve_s"]}


def exponents(n: list[int], t: list[float]) -> tuple[list[str], str]:
    """The exponents a of t ~ n^a from each size to the next, and of a least-squares line
    through all of them (log t against log n)."""
    steps = ["–"] + [f"{np.log(t[k] / t[k - 1]) / np.log(n[k] / n[k - 1]):.2f}" for k in range(1, len(n))]
    overall = f"{np.polyfit(np.log(n), np.log(t), 1)[0]:.2f}" if len(n) > 1 else "–"
    return steps, overall


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--meshes", default="4x40,8x80,12x120,16x160,18x180", help="NZxNR, comma-separated")
    ap.add_argument("--repeat", type=int, default=3, help="axiform runs per mesh (default 3)")
    ap.add_argument("--felupe-repeat", type=int, default=1, help="FElupe runs per mesh (default 1)")
    ap.add_argument("--before", type=Path, help="another source tree of axiform, run side by side")
    ap.add_argument("--after", type=Path, default=ROOT / "src", help="the source tree timed (default: this one)")
    ap.add_argument("--felupe-from", type=Path, help="FElupe's results of an earlier run (its .json): not run again")
    ap.add_argument("--no-felupe", action="store_true")
    ap.add_argument("--inside", action="store_true", help="time the parts of axiform's solve (no FElupe)")
    ap.add_argument("--out", default="plate_scaling", help="results file name (default plate_scaling)")
    args = ap.parse_args(argv)
    trees = {"this tree": args.after.resolve()} | ({"before": args.before.resolve()} if args.before else {})
    meshes = [m.strip() for m in args.meshes.split(",") if m.strip()]
    felupe = None
    if not args.no_felupe:
        try:
            import felupe  # noqa: F401

            felupe = felupe.__version__
        except ImportError:
            print("FElupe is not installed (pip install -e '.[bench]'): axiform alone")
    t_start = time.perf_counter()
    tmp = Path(tempfile.mkdtemp(prefix="plate_scaling_"))
    if args.inside:
        report = inside(meshes, trees, args.repeat, tmp)
        path = HERE / "results" / f"{args.out}.md"
        command = " ".join(argv or sys.argv[1:])
        head = f"# Where the plate's solve goes\n\nWritten by `benchmarks/plate_scaling.py {command}`"
        path.write_text(f"{head} on {time.strftime('%Y-%m-%d %H:%M')}; {machine()}.\n\n{report}\n")
        print(report)
        return 0
    script, solve_script = tmp / "felupe_plate.py", tmp / "solve.py"
    script.write_text(FELUPE_SCRIPT)
    solve_script.write_text(SOLVE_SCRIPT)
    runs: dict[tuple[str, str], list[dict]] = {}
    if args.felupe_from:  # {mesh: [runs]} of FElupe
        runs |= {(m, "FElupe"): r for m, r in json.loads(args.felupe_from.read_text())["FElupe"].items()}
    for mesh in meshes:
        nr, nz = parse_mesh(mesh)
        for k in range(max(args.repeat, args.felupe_repeat if felupe else 0)):
            for name, src in trees.items():
                if k < args.repeat:
                    out = tmp / f"ax-{mesh}-{name.replace(' ', '-')}-{k}"
                    runs.setdefault((mesh, f"axiform ({name})"), []).append(run_axiform(src, nr, nz, out, solve_script))
            if felupe and k < args.felupe_repeat and not args.felupe_from:
                pressures = tmp / f"pressures-{mesh}.txt"
                np.savetxt(pressures, runs[mesh, "axiform (this tree)"][0]["p"])
                runs.setdefault((mesh, "FElupe"), []).append(run_felupe(script, nr, nz, pressures))
            print(
                f"{mesh} run {k + 1}: "
                + ", ".join(f"{c} {r[-1]['wall']:.2f} s" for (m, c), r in runs.items() if m == mesh)
            )
    # the fastest process of each, with the fastest solve of its repeats
    best = {
        key: min(r, key=lambda x: x["cpu"]) | {k: min(x[k] for x in r) for k in ("solve", "solve_wall", "wall", "cpu")}
        for key, r in runs.items()
    }
    report = table(meshes, trees, best, felupe)
    text = [
        f"# The plate against FElupe, 1e3 to 2e4 dofs{'' if len(meshes) > 1 else ' (one mesh)'}",
        "",
        f"Written by `benchmarks/plate_scaling.py {' '.join(argv or sys.argv[1:])}` on "
        f"{time.strftime('%Y-%m-%d %H:%M')};"
        f" {machine()}. FElupe {felupe or 'not run'}. Total {time.perf_counter() - t_start:.0f} s.",
        "",
        report,
    ]
    path = HERE / "results" / f"{args.out}.md"
    path.write_text("\n".join(text) + "\n")
    saved = {code: {m: r for (m, c), r in runs.items() if c == code} for code in {c for _, c in runs}}
    path.with_suffix(".json").write_text(json.dumps(saved))
    print("\n".join(text))
    print(f"wrote {path}")
    return 0


def table(meshes: list[str], trees: dict, best: dict, felupe: str | None) -> str:
    """The markdown table: per mesh and code its dofs, steps and iterations, solve and process
    (CPU and wall, the minimum of the repeats), the ratios to FElupe, the growth exponents
    of the CPU times and the match of w."""
    rows = []
    codes = [f"axiform ({name})" for name in trees] + (["FElupe"] if felupe else [])
    growth = {}
    for code in codes:
        n = [best[m, code]["dofs"] for m in meshes]
        growth[code] = [exponents(n, [best[m, code][k] for m in meshes]) for k in ("solve", "cpu")]
    for i, m in enumerate(meshes):
        fe = best.get((m, "FElupe"))
        ref = best[m, "axiform (this tree)"]
        for code in codes:
            r = best[m, code]
            its = f"{r['steps']}, {r['iterations']}" if "steps" in r else f"40, {r['iterations']}"
            match = "–"
            if code == "FElupe":
                match = f"{np.abs(np.asarray(r['w']) - np.asarray(ref['w'])).max():.1e}"
            ratio = fe and code != "FElupe"
            rows.append(
                [
                    m,
                    code,
                    f"{r['dofs']:,}",
                    its,
                    f"{r['solve']:.2f} / {r['solve_wall']:.2f}",
                    f"{r['cpu']:.2f} / {r['wall']:.2f}",
                    f"{r['solve'] / fe['solve']:.3f}" if ratio else "–",
                    f"**{r['cpu'] / fe['cpu']:.3f}** / {r['wall'] / fe['wall']:.3f}" if ratio else "–",
                    growth[code][0][0][i],
                    growth[code][1][0][i],
                    match,
                ]
            )
    header = [
        "mesh",
        "code",
        "dofs",
        "steps, iterations",
        "solve s, CPU / wall",
        "process s, CPU / wall",
        "solve / FElupe's (CPU)",
        "process / FElupe's, CPU / wall",
        "solve growth a (CPU)",
        "process growth a (CPU)",
        "max abs w - w_axiform (in)",
    ]
    lines = [md_table(header, rows), ""]
    for code in codes:
        lines.append(
            f"- {code}: t ~ n^a fitted over all meshes: solve a = {growth[code][0][1]}, "
            f"process a = {growth[code][1][1]} (CPU times)"
        )
    return "\n".join(lines)


if __name__ == "__main__":
    sys.exit(main())
