#!/usr/bin/env python
"""The forming rate against the relaxation times: examples/cup_thermoforming.toml (a HIPS
sheet, Prony series of terminal time tau_d = 2 s) run at 0.1x, 1x and 10x its nominal rate,
every curve's time axis (and the end time) divided by the factor, the same number of steps;
and the same case with the elastic law at its instantaneous modulus, the limit of a very
fast process.  (The other limit, the law at its long-term modulus, 2 % of the instantaneous
one, 4 kPa, does not carry the 0.09 MPa of the vacuum: its elements invert.)

Writes results/rate_study.png (the wall against the reference arc length; the plug force
against the process time over its duration) and results/rate_study.md (a table: the
thinnest wall and where, the wall at the centre of the bottom, at the bottom corner and at
mid-height of the side, the largest plug force, steps, Newton iterations).

Run:  python benchmarks/rate_study.py        (about a minute on one core)
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
from axiform.post.results_folder import read_history  # noqa: E402

HERE = Path(__file__).resolve().parent
EXAMPLES = HERE.parent / "examples"
CASE = EXAMPLES / "cup_thermoforming.toml"
RESULTS = HERE / "results"
QUIET = ["-q", "--set", "output.plots=false", "--set", "output.vtu=false"]
# the reference arc lengths reported in the table (the sheet's initial radius): the centre of
# the bottom, the bottom corner (the thinnest point at the nominal rate), mid-height of the side
S_REPORT = {"bottom centre": 0.0, "bottom corner": 9.5, "side, mid-height": 25.0}


def scaled(data: dict, factor: float) -> dict:
    """The case tree with every curve's time axis and the end time divided by `factor` (the
    process run `factor` times faster)."""
    case = copy.deepcopy(data)
    for table in case.get("contact", []):
        table["surface"]["dxf"] = str(EXAMPLES / table["surface"]["dxf"])
        if "motion" in table:
            table["motion"]["curve"] = [[t / factor, f] for t, f in table["motion"]["curve"]]
    for table in case.get("pressure", []):
        table["curve"] = [[t / factor, f] for t, f in table["curve"]]
    case["solver"]["target"] = case["solver"]["target"] / factor
    return case


def elastic(data: dict) -> dict:
    """The case tree without the Prony series: the law at its instantaneous modulus."""
    case = scaled(data, 1.0)
    del case["material"]["viscoelastic"]
    return case


def run(case: dict, folder: Path) -> dict:
    """Run a case tree with `axiform run`; its thickness table, plug-force history and summary."""
    folder.mkdir(parents=True, exist_ok=True)
    path = folder / "case.toml"
    path.write_bytes(tomli_w.dumps(case).encode())
    code = main(["run", str(path), "--out", str(folder / "out"), *QUIET])
    summary = json.loads((folder / "out" / "summary.json").read_text())
    if code != 0:
        raise RuntimeError(f"{folder.name}: {summary['status']}: {summary.get('message')}")
    with open(folder / "out" / "thickness.csv", newline="") as stream:
        wall = list(csv.DictReader(line for line in stream if not line.startswith("#")))
    history = read_history(folder / "out" / "history.csv")
    return {
        "s": np.array([float(r["s"]) for r in wall]),
        "ratio": np.array([float(r["ratio"]) for r in wall]),
        "t": history["load_factor"],
        "plug_force": history["plug_force"],
        "steps": summary["steps"],
        "iterations": summary["newton_iterations"],
    }


def table(runs: dict[str, dict], thickness: float) -> str:
    """The markdown table of the runs."""
    head = [
        "run",
        "process time (s)",
        "thinnest wall (mm)",
        "at s (mm)",
        *[f"{name} (mm)" for name in S_REPORT],
        "largest plug force (N)",
        "steps",
        "Newton iterations",
    ]
    lines = ["| " + " | ".join(head) + " |", "|" + "---|" * len(head)]
    for name, res in runs.items():
        wall = res["ratio"] * thickness
        at = [np.interp(s, res["s"], wall) for s in S_REPORT.values()]
        lines.append(
            f"| {name} | {res['t'][-1]:g} | {wall.min():.3f} | {res['s'][np.argmin(wall)]:.1f} | "
            + " | ".join(f"{w:.3f}" for w in at)
            + f" | {-res['plug_force'].min():.1f} | {res['steps']} | {res['iterations']} |"
        )
    return "\n".join(lines) + "\n"


def figure(runs: dict[str, dict], thickness: float, path: Path) -> None:
    """The wall along the sheet and the plug force over the process, one curve per run."""
    fig, (left, right) = plt.subplots(1, 2, figsize=(12, 4.8))
    styles = {"elastic, instantaneous modulus": ("k", "--")}
    for name, res in runs.items():
        colour, line = styles.get(name, (None, "-"))
        left.plot(res["s"], res["ratio"] * thickness, color=colour, linestyle=line, label=name)
        right.plot(res["t"] / res["t"][-1], -res["plug_force"], color=colour, linestyle=line, label=name)
    left.set(
        xlabel="reference arc length s (mm), from the centre of the sheet",
        ylabel="wall thickness (mm)",
        title="final wall",
        ylim=(0, None),
    )
    right.set(xlabel="t / process time (plug down to 2/3, vacuum after)", ylabel="plug force (N)", title="plug force")
    for ax in (left, right):
        ax.grid(alpha=0.3)
        ax.legend(fontsize=8)
    fig.suptitle("Plug-assisted thermoforming of a HIPS cup at three rates (tau_d = 2 s)")
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def study() -> None:
    """Run the four cases, write the figure and the table."""
    data = read(CASE)
    cases = {
        "10x faster (0.15 s)": scaled(data, 10.0),
        "nominal (1.5 s)": scaled(data, 1.0),
        "10x slower (15 s)": scaled(data, 0.1),
        "elastic, instantaneous modulus": elastic(data),
    }
    thickness = data["mesh"]["z"][1] - data["mesh"]["z"][0]
    with tempfile.TemporaryDirectory() as tmp:
        runs = {name: run(case, Path(tmp) / f"run{k}") for k, (name, case) in enumerate(cases.items())}
    RESULTS.mkdir(exist_ok=True)
    figure(runs, thickness, RESULTS / "rate_study.png")
    text = table(runs, thickness)
    (RESULTS / "rate_study.md").write_text(
        "# Rate study: the cup at 0.1x, 1x and 10x its rate\n\nWritten by `benchmarks/rate_study.py`.\n\n" + text
    )
    print(text)


if __name__ == "__main__":
    study()
