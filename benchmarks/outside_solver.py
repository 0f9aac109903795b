#!/usr/bin/env python
"""The whole process of the three process examples, before / after: `axiform run EX --out DIR`
timed from outside (the process's wall time), plots as the case files have them and off.

    python benchmarks/outside_solver.py --before /tmp/before/src [--after src] [--repeat 3]
        [--out DIR] [EXAMPLE ...]

The two trees run alternately (before, after, before, ...), `--repeat` times each; the table
gives the least wall time and the least CPU time (user + system of the run and of the
processes it waited for) of each.  Then every file of the two
results folders is compared byte for byte, except summary.json (its timings differ; its other
keys are compared) and the PNG pictures (compared by eye).  The runs write their bytecode
caches (PYTHONDONTWRITEBYTECODE is dropped from their environment), as an installed axiform
has them: without, each run compiles axiform's modules again (about 0.09 s).
"""

from __future__ import annotations

import argparse
import filecmp
import json
import os
import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent
sys.path.insert(0, str(HERE))
from speed import timed  # noqa: E402  (wall, CPU of the child, its output)

EXAMPLES = ("bottle_blow_moulding", "cup_thermoforming", "stretch_blow_moulding")
TIMINGS = ("wall_time_s",)


def run(src: Path, example: str, out: Path, plots: bool) -> tuple[float, float]:
    """The wall time and the CPU time (user + system, its own processes included) in s of one
    `axiform run` of the example with the tree src."""
    env = dict(os.environ, PYTHONPATH=str(src))
    env.pop("PYTHONDONTWRITEBYTECODE", None)
    args = [
        sys.executable,
        "-m",
        "axiform.cli",
        "run",
        str(ROOT / "examples" / f"{example}.toml"),
        "--out",
        str(out),
        "-q",
    ] + ([] if plots else ["--set", "output.plots=false"])
    wall, cpu, _ = timed(args, env, ROOT)
    return wall, cpu


def differences(a: Path, b: Path) -> list[str]:
    """The files of two results folders that differ (or that only one has), PNGs left out."""
    names = {p.relative_to(a) for p in a.rglob("*") if p.is_file()} | {
        p.relative_to(b) for p in b.rglob("*") if p.is_file()
    }
    out = []
    for name in sorted(names):
        fa, fb = a / name, b / name
        if not (fa.is_file() and fb.is_file()):
            out.append(f"{name} (only in {'before' if fa.is_file() else 'after'})")
        elif name.suffix == ".png":
            continue
        elif name.name == "summary.json":
            ja, jb = (json.loads(f.read_text()) for f in (fa, fb))
            for key in TIMINGS:
                ja.pop(key, None), jb.pop(key, None)
            if ja != jb:
                out.append(f"{name} ({sorted(k for k in ja.keys() | jb.keys() if ja.get(k) != jb.get(k))})")
        elif not filecmp.cmp(fa, fb, shallow=False):
            out.append(str(name))
    return out


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--before", type=Path, required=True)
    parser.add_argument("--after", type=Path, default=ROOT / "src")
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--out", type=Path, default=Path("/tmp/axiform-outside-solver"))
    parser.add_argument("examples", nargs="*", default=EXAMPLES)
    args = parser.parse_args()
    print(f"load average at start: {os.getloadavg()[0]:.2f}", flush=True)
    rows = []
    for example in args.examples:
        for plots in (True, False):
            best = {label: [float("inf"), float("inf")] for label in ("before", "after")}
            for _ in range(args.repeat):
                for label, src in (("before", args.before), ("after", args.after)):
                    wall, cpu = run(src.resolve(), example, args.out / label / f"{example}-{plots}", plots)
                    best[label] = [min(best[label][0], wall), min(best[label][1], cpu)]
            diff = differences(*(args.out / label / f"{example}-{plots}" for label in ("before", "after")))
            rows.append((example, "on" if plots else "off", *best["before"], *best["after"], diff))
            print(
                f"{example} plots {rows[-1][1]}: wall {best['before'][0]:.2f} -> {best['after'][0]:.2f} s, "
                f"CPU {best['before'][1]:.2f} -> {best['after'][1]:.2f} s; differ: {', '.join(diff) or 'none'}",
                flush=True,
            )
    print(f"load average at end: {os.getloadavg()[0]:.2f}\n")
    print(
        "| example | plots | wall before (s) | wall after (s) | saved | CPU before (s) | CPU after (s) | saved | "
        "files that differ (PNGs aside) |"
    )
    print("|---|---|---:|---:|---:|---:|---:|---:|---|")
    for example, plots, wall0, cpu0, wall1, cpu1, diff in rows:
        print(
            f"| {example} | {plots} | {wall0:.2f} | {wall1:.2f} | {wall0 - wall1:.2f} | {cpu0:.2f} | {cpu1:.2f} | "
            f"{cpu0 - cpu1:.2f} | {', '.join(diff) or 'none'} |"
        )


if __name__ == "__main__":
    main()
