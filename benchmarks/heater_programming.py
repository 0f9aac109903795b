#!/usr/bin/env python
"""Temperature programming of a thermoformed cup (issue 20): the heater profile of
examples/cup_heater_programming.toml (five knots of the sheet's initial temperature along its
radius, from a uniform 150 C) programmed by `axiform optimize --vary temperature` for the
wall a known profile leaves (examples/cup_heater_target.csv, rewritten here from that
profile), by the gradient method and by the fixed-point rule, at most 15 iterations each.

Writes results/heater_programming.md (forward solves, the max deviation after them, the
profile found) and results/heater_programming.png (the gradient method's optimize.png).

Run:  python benchmarks/heater_programming.py        (about 3 minutes)
"""

from __future__ import annotations

import copy
import csv
import json
import shutil
import tempfile
from pathlib import Path

import tomli_w

from axiform.case.schema import read
from axiform.cli import main

HERE = Path(__file__).resolve().parent
EXAMPLES = HERE.parent / "examples"
CASE = EXAMPLES / "cup_heater_programming.toml"
TARGET = EXAMPLES / "cup_heater_target.csv"
RESULTS = HERE / "results"
KNOWN = [146.0, 153.0, 149.0, 147.0, 152.0]


def write_target(folder: Path) -> None:
    """The final wall of the case at the known profile, stations with 1 <= s <= 48."""
    tree = copy.deepcopy(read(CASE))
    tree["temperature"]["initial"]["table"] = [
        [row[0], v] for row, v in zip(tree["temperature"]["initial"]["table"], KNOWN, strict=False)
    ]
    for table in tree["contact"]:
        table["surface"]["dxf"] = str(EXAMPLES / table["surface"]["dxf"])
    case = folder / "known.toml"
    case.write_text(tomli_w.dumps(tree))
    out = folder / "known"
    assert main(["run", str(case), "--out", str(out), "-q", "--set", "output.plots=false"]) == 0
    with open(out / "thickness.csv", newline="") as fh:
        rows = [r for r in csv.DictReader(fh) if 1.0 <= float(r["s"]) <= 48.0]
    head = TARGET.read_text().splitlines()[:2]  # its two comment lines
    TARGET.write_text("\n".join(head + ["s,thickness"] + [f"{r['s']},{r['thickness']}" for r in rows]) + "\n")


def study() -> None:
    RESULTS.mkdir(exist_ok=True)
    lines = [
        "| method | forward solves | max deviation after 3 solves | best max deviation | optimized profile (C) |",
        "|---|---:|---:|---:|---|",
    ]
    with tempfile.TemporaryDirectory() as tmp:
        write_target(Path(tmp))
        for method in ("gradient", "fixed-point"):
            out = Path(tmp) / method
            main(
                [
                    "optimize",
                    str(CASE),
                    "--target",
                    str(TARGET),
                    "--out",
                    str(out),
                    "--vary",
                    "temperature",
                    "--method",
                    method,
                    "--max-iter",
                    "15",
                    "-q",
                ]
            )
            summary = json.loads((out / "optimize.json").read_text())
            with open(out / "optimize.csv", newline="") as fh:
                rows = list(csv.DictReader(fh))
            at3 = min(float(r["max_rel_deviation"]) for r in rows if int(r["forward_solves"]) <= 3)
            profile = ", ".join(f"{v:.1f}" for v in summary["optimized_temperature"])
            lines.append(
                f"| {method} | {summary['forward_solves']} | {100 * at3:.2f} % | "
                f"{100 * summary['max_rel_deviation']:.2f} % | {profile} |"
            )
            if method == "gradient":
                shutil.copy(out / "optimize.png", RESULTS / "heater_programming.png")
    lines.append(f"| (the known profile) | | | | {', '.join(f'{v:.1f}' for v in KNOWN)} |")
    (RESULTS / "heater_programming.md").write_text("\n".join(lines) + "\n")
    print("\n".join(lines))


if __name__ == "__main__":
    study()
