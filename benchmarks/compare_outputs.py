#!/usr/bin/env python
"""Run examples with two source trees and compare their CSV outputs number by number.

    python benchmarks/compare_outputs.py --before /work/main/src [--after src] [--out DIR]
        [EXAMPLE ...]   (default: die_drawing cup_thermoforming stretch_blow_moulding
                         bottle_blow_moulding toric_plate dxf_cup_mould)

For every example and output file (history.csv, contact.csv, thickness.csv, where written)
it prints the largest relative difference |a - b| / max(|a|, |b|, floor) over the numeric
cells of the columns both files have (matched by their header's names; a column only one
has is named, e.g. history.csv's `time` against a tree from before it), floor = 1e-12 times
the column's largest magnitude (cells near zero compared to the column's scale), and whether
the non-numeric cells (status, ...) and the shapes agree.
Plots off (they do not change the CSVs).  Existing output folders are reused with --reuse.
"""

from __future__ import annotations

import argparse
import csv
import os
import subprocess
import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
EXAMPLES = (
    "die_drawing",
    "cup_thermoforming",
    "stretch_blow_moulding",
    "bottle_blow_moulding",
    "toric_plate",
    "dxf_cup_mould",
)
FILES = ("history.csv", "contact.csv", "thickness.csv")


def run(src: Path, example: str, out: Path) -> None:
    env = dict(os.environ, PYTHONPATH=str(src))
    subprocess.run(
        [
            sys.executable,
            "-m",
            "axiform.cli",
            "run",
            str(ROOT / "examples" / f"{example}.toml"),
            "--out",
            str(out),
            "-q",
            "--set",
            "output.plots=false",
        ],
        env=env,
        cwd=ROOT,
        check=True,
        capture_output=True,
    )


def read(path: Path) -> list[list[str]]:
    with open(path, newline="") as f:
        return [row for row in csv.reader(f) if row and not row[0].startswith("#")]


def number(cell: str) -> float | None:
    try:
        return float(cell) if cell != "" else None
    except ValueError:
        return None


def common_columns(ra: list[list[str]], rb: list[list[str]]) -> tuple[list[list[str]], list[list[str]], list[str]]:
    """The rows of both tables on the columns both headers name (in a's order), and the
    names only one of them has."""
    if not ra or not rb or ra[0] == rb[0]:
        return ra, rb, []
    names = [c for c in ra[0] if c in rb[0]]

    def pick(rows: list[list[str]]) -> list[list[str]]:
        where = [rows[0].index(c) for c in names]
        return [[r[k] if k < len(r) else "" for k in where] for r in rows]

    return pick(ra), pick(rb), sorted(set(ra[0]) ^ set(rb[0]))


def common_times(ra: list[list[str]], rb: list[list[str]]) -> tuple[list, list, str]:
    """The rows of two history.csv files (header first) at the load factors both reached
    (other steps: knots, the end, and steps of equal size), without the step and iteration
    columns; and a note on how many."""
    head = ra[0]
    keep = [j for j, name in enumerate(head) if name not in ("step", "iterations")]
    tb = {round(float(r[1]), 12): r for r in rb[1:]}
    pa, pb = [[head[j] for j in keep]], [[rb[0][j] for j in keep]]
    for r in ra[1:]:
        match = tb.get(round(float(r[1]), 12))
        if match is not None:
            pa.append([r[j] for j in keep])
            pb.append([match[j] for j in keep])
    return pa, pb, f" at the {len(pa) - 1} load factors of both ({len(ra) - 1} vs {len(rb) - 1} steps)"


def compare(a: Path, b: Path) -> str:
    ra, rb, only = common_columns(read(a), read(b))
    extra = f"; columns in one file only: {', '.join(only)}" if only else ""
    note = ""
    if len(ra) != len(rb) and a.name == "history.csv" and ra and ra[0][:2] == ["step", "load_factor"]:
        ra, rb, note = common_times(ra, rb)
    if len(ra) != len(rb) or any(len(x) != len(y) for x, y in zip(ra, rb, strict=False)):
        return f"shapes differ ({len(ra)} vs {len(rb)} rows){extra}"
    ncol = max((len(r) for r in ra), default=0)
    scale = np.zeros(ncol)
    for r in ra + rb:
        for j, c in enumerate(r):
            v = number(c)
            if v is not None and np.isfinite(v):
                scale[j] = max(scale[j], abs(v))
    worst, cells, text_diff = 0.0, 0, 0
    for x, y in zip(ra, rb, strict=False):
        for j, (c, d) in enumerate(zip(x, y, strict=False)):
            u, v = number(c), number(d)
            if u is None or v is None:
                text_diff += c != d
                continue
            cells += 1
            if np.isnan(u) and np.isnan(v) or u == v:
                continue
            worst = max(worst, abs(u - v) / max(abs(u), abs(v), 1e-12 * scale[j], 1e-300))
    return f"{worst:.1e} over {cells} numbers{note}" + (f"; {text_diff} text cells differ" if text_diff else "") + extra


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--before", type=Path, required=True)
    ap.add_argument("--after", type=Path, default=ROOT / "src")
    ap.add_argument("--out", type=Path, default=Path("/tmp/axiform_compare"))
    ap.add_argument("--reuse", action="store_true", help="compare existing outputs under --out")
    ap.add_argument("examples", nargs="*", default=list(EXAMPLES))
    args = ap.parse_args()
    print("| example | file | largest relative difference |\n|---|---|---|")
    for ex in args.examples:
        dirs = {name: args.out / name / ex for name in ("before", "after")}
        if not args.reuse:
            for name, src in (("before", args.before), ("after", args.after)):
                run(src.resolve(), ex, dirs[name])
        for f in FILES:
            if (dirs["before"] / f).exists() or (dirs["after"] / f).exists():
                print(f"| {ex} | {f} | {compare(dirs['before'] / f, dirs['after'] / f)} |")


if __name__ == "__main__":
    main()
