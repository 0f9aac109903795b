#!/usr/bin/env python
"""The frictionless die drawing against CalculiX CAX4 on the same mesh, whole processes side by
side (the goal: axiform at most 0.1 x CalculiX, the punch force within 2 %).

    .venv/bin/python benchmarks/die_drawing_speed.py [--repeat 3] [--before OLD/src]

axiform: `axiform run examples/die_drawing.toml` with both frictions 0, the displacement
formulation (CAX4 has no mixed or B-bar form), the penalty K = 10 E / h of
validation/die_drawing_ccx.py on both tools, VTU and plots off (history.csv, contact.csv,
thickness.csv, summary.json and the checkpoint are written), a fresh Python each time.
CalculiX: `ccx -i die` on the deck of validation/die_drawing_ccx.py for the same case (Q4 40 x 2
as CAX4, the tools as prescribed strips, node-to-surface penalty contact, increments of at most
1 % of the travel), one thread.  Interleaved repeats; the minimum CPU time (user + system of
the child) and wall time of each; the punch force at the travel of 3 (ccx's scaled to the
whole ring by the measured ring factor).  Writes benchmarks/results/die_drawing_speed.md.
"""

from __future__ import annotations

import argparse
import csv
import json
import os
import shutil
import sys
import tempfile
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent
sys.path.insert(0, str(HERE))
sys.path.insert(0, str(ROOT / "validation"))
from speed import env_for, machine, md_table, timed  # noqa: E402

CASE = ROOT / "examples" / "die_drawing.toml"


def axiform_sets(penalty: float) -> list[str]:
    sets = [f"contact[{k}].{key}" for k in range(2) for key in (f"penalty={penalty!r}", "friction=0.0")]
    return sets + ['mesh.formulation="displacement"', "output.vtu=false", "output.plots=false"]


def run_axiform(src: Path, penalty: float, out: Path) -> dict:
    cmd = [sys.executable, "-m", "axiform.cli", "run", str(CASE), "-q", "--out", str(out)]
    for s in axiform_sets(penalty):
        cmd += ["--set", s]
    wall, cpu, _ = timed(cmd, env_for(src))
    summary = json.loads((out / "summary.json").read_text())
    with open(out / "history.csv") as f:
        last = [r for r in csv.DictReader(f) if not r["step"].startswith("#")][-1]
    return {
        "wall": wall,
        "cpu": cpu,
        "solve": float(summary["wall_time_s"]),
        "steps": int(summary["steps"]),
        "iterations": int(summary["newton_iterations"]),
        "force": -float(last["punch_force"]),
        "travel": -float(last["punch_travel"]),
    }


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--before", type=Path, help="another source tree of axiform, run side by side")
    ap.add_argument("--after", type=Path, default=ROOT / "src", help="the source tree timed (default: this one)")
    ap.add_argument("--out", default="die_drawing_speed", help="results file name (default die_drawing_speed)")
    args = ap.parse_args(argv)
    if shutil.which("ccx") is None:
        print("die_drawing_speed.py: CalculiX (ccx) is not installed: nothing to compare")
        return 0
    import die_drawing_ccx as dd  # the deck, the ring factor and the reading of ccx's forces

    base = dd.build(dd.load(CASE, ["mesh.element=q4"]), CASE.parent)
    penalty = 10.0 * dd.youngs_modulus(base.model.material) / 0.15
    factor = dd.ring_factor(penalty)
    built = dd.build(dd.load(CASE, axiform_sets(penalty)[:-2]), CASE.parent)
    deck = dd.ccx_deck(built, False, penalty, 0.01)
    trees = {"this tree": args.after.resolve()} | ({"before": args.before.resolve()} if args.before else {})
    tmp = Path(tempfile.mkdtemp(prefix="die_speed_"))
    runs: dict[str, list[dict]] = {}
    for k in range(args.repeat):
        for name, src in trees.items():
            runs.setdefault(f"axiform ({name})", []).append(run_axiform(src, penalty, tmp / f"{name}-{k}"))
        c0, t0 = os.times(), time.perf_counter()
        cc = dd.run_ccx(deck, "die_speed")
        c1, wall = os.times(), time.perf_counter() - t0
        cpu = (c1.children_user - c0.children_user) + (c1.children_system - c0.children_system)
        if not cc["ok"]:
            raise RuntimeError(f"ccx did not finish: {cc['message']}")
        force = -factor * float(cc["fz"][-1])
        runs.setdefault("CalculiX CAX4", []).append({"wall": wall, "cpu": cpu, "force": force, "steps": len(cc["t"])})
        print(f"run {k + 1}: " + ", ".join(f"{c} {r[-1]['cpu']:.2f} s CPU" for c, r in runs.items()), flush=True)
    best = {c: min(r, key=lambda x: x["cpu"]) | {"wall": min(x["wall"] for x in r)} for c, r in runs.items()}
    ccx = best["CalculiX CAX4"]
    rows = []
    for code, r in best.items():
        its = f"{r['steps']}, {r['iterations']}" if "iterations" in r else f"{r['steps']} increments"
        rows.append(
            [
                code,
                its,
                f"{r['cpu']:.2f} / {r['wall']:.2f}",
                f"{r['solve']:.2f}" if "solve" in r else "–",
                f"**{r['cpu'] / ccx['cpu']:.3f}** / {r['wall'] / ccx['wall']:.3f}",
                f"{r['force']:.4f} ({100 * (r['force'] / ccx['force'] - 1):+.2f} %)",
            ]
        )
    header = ["process", "steps, iterations", "CPU / wall s", "solve wall s", "/ CalculiX, CPU / wall", "punch force"]
    text = [
        "# The die drawing against CalculiX CAX4, whole processes",
        "",
        f"Written by `benchmarks/die_drawing_speed.py {' '.join(argv if argv is not None else sys.argv[1:])}` on "
        f"{time.strftime('%Y-%m-%d %H:%M')}; {machine()}. Frictionless, Q4 40 x 2, displacement formulation, "
        f"penalty K = {penalty:.6g}; minimum of {args.repeat} interleaved runs.",
        "",
        md_table(header, rows),
    ]
    path = HERE / "results" / f"{args.out}.md"
    path.write_text("\n".join(text) + "\n")
    print("\n".join(text))
    print(f"wrote {path}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
