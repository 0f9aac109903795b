#!/usr/bin/env python
"""The sheet's temperature profile against the wall it gives: examples/cup_thermoforming.toml
(a HIPS sheet at 150 C, Prony series of terminal time 2 s) with a [temperature] table, the WLF
shift of polystyrene moved to 150 C (C1 = 13.7, C2 = 50 K at Tg = 100 C give C1 = 6.85,
C2 = 100 K at 150 C) and the plateau modulus a table of T (stiffer as the sheet is colder:
C1 = 0.10 MPa at 150 C, 0.13 at 145 C, 0.18 at 140 C, 0.40 at 130 C; an estimate of the
approach to the glass transition, not a measured curve), run with

- the uniform 150 C of the example,
- a profile hotter at the centre of the sheet (155 C at r = 0 down to 145 C at the rim),
- a profile colder at the centre (145 C at r = 0 up to 155 C at the rim),

the same process and steps otherwise (no heat equation: each point keeps its temperature).
Writes results/temperature_study.png (the wall against the reference arc length, and the
profiles) and results/temperature_study.md (the thinnest wall and where, the wall at the
centre of the bottom, the bottom corner and mid-height of the side, steps, Newton iterations).

Run:  python benchmarks/temperature_study.py        (about a minute on one core)
"""

from __future__ import annotations

import copy
import csv
import json
import tempfile
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import tomli_w  # noqa: E402

from axiform.case.schema import read  # noqa: E402
from axiform.cli import main  # noqa: E402

HERE = Path(__file__).resolve().parent
EXAMPLES = HERE.parent / "examples"
CASE = EXAMPLES / "cup_thermoforming.toml"
RESULTS = HERE / "results"
QUIET = ["-q", "--set", "output.plots=false", "--set", "output.vtu=false"]
S_REPORT = {"bottom centre": 0.0, "bottom corner": 9.5, "side, mid-height": 25.0}
PLATEAU = [[130.0, 0.40], [140.0, 0.18], [145.0, 0.13], [150.0, 0.10]]
PROFILES = {
    "uniform 150 C": 150.0,
    "hot centre 155 -> 145 C": {"along": "r", "table": [[0.0, 155.0], [50.0, 145.0]]},
    "cold centre 145 -> 155 C": {"along": "r", "table": [[0.0, 145.0], [50.0, 155.0]]},
}


def with_profile(data: dict, initial) -> dict:
    """The case tree with a [temperature] table of the given initial field, the WLF shift at
    150 C and the plateau modulus as a table of T."""
    case = copy.deepcopy(data)
    for table in case.get("contact", []):
        table["surface"]["dxf"] = str(EXAMPLES / table["surface"]["dxf"])
    case["material"]["C1"] = PLATEAU
    case["temperature"] = {"initial": initial, "reference": 150.0, "shift": {"wlf": {"C1": 6.85, "C2": 100.0}}}
    return case


def run(case: dict, folder: Path) -> tuple[dict[str, np.ndarray], dict]:
    path = folder / "case.toml"
    path.write_text(tomli_w.dumps(case))
    out = folder / "out"
    code = main(["run", str(path), "--out", str(out)] + QUIET)
    summary = json.loads((out / "summary.json").read_text())
    if code != 0:
        raise SystemExit(f"{path}: exit {code}: {summary.get('message')}")
    with open(out / "thickness.csv") as fh:
        rows = list(csv.DictReader(fh))
    table = {k: np.array([float(r[k]) if r[k] else np.nan for r in rows]) for k in ("s", "thickness", "temperature")}
    return table, summary


def main_study() -> None:
    data = read(CASE)
    results = {}
    with tempfile.TemporaryDirectory() as tmp:
        for k, (name, initial) in enumerate(PROFILES.items()):
            folder = Path(tmp) / f"p{k}"
            folder.mkdir()
            results[name] = run(with_profile(data, initial), folder)
    RESULTS.mkdir(exist_ok=True)
    fig, (ax, ax_T) = plt.subplots(1, 2, figsize=(12, 4.5), gridspec_kw={"width_ratios": [2, 1]})
    for k, (name, (t, _)) in enumerate(results.items()):
        ax.plot(t["s"], t["thickness"], "o-", ms=2, color=f"C{k}", label=name)
        ax_T.plot(t["s"], t["temperature"], "-", color=f"C{k}", label=name)
    ax.set_xlabel("reference arc length s (mm): 0 at the centre of the sheet, 50 at the clamp")
    ax.set_ylabel("final wall thickness (mm)")
    ax.set_ylim(0.0, None)
    ax.legend(fontsize=8)
    ax.grid(True, alpha=0.3)
    ax_T.set_xlabel("reference arc length s (mm)")
    ax_T.set_ylabel("sheet temperature (C)")
    ax_T.grid(True, alpha=0.3)
    fig.suptitle("Plug-assisted thermoforming of a HIPS cup: the sheet's temperature profile and its wall")
    fig.tight_layout()
    fig.savefig(RESULTS / "temperature_study.png", dpi=110)
    lines = [
        "| profile | thinnest wall (mm) at s | "
        + " | ".join(f"wall at {k} (s = {s:g})" for k, s in S_REPORT.items())
        + " | steps | Newton iterations |",
        "|---" * (4 + len(S_REPORT)) + "|",
    ]
    for name, (t, summary) in results.items():
        i = int(np.nanargmin(t["thickness"]))
        walls = " | ".join(f"{np.interp(s, t['s'], t['thickness']):.3f}" for s in S_REPORT.values())
        lines.append(
            f"| {name} | {t['thickness'][i]:.3f} at {t['s'][i]:.1f} | {walls} | {summary['steps']} | "
            f"{summary['newton_iterations']} |"
        )
    (RESULTS / "temperature_study.md").write_text("\n".join(lines) + "\n")
    print("\n".join(lines))


if __name__ == "__main__":
    main_study()
