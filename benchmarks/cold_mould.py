#!/usr/bin/env python
"""A cold mould that freezes the wall through temperature, beside the sticky mould:
examples/cup_thermoforming.toml (the sheet sticks where it touches, no heat) and
examples/cup_cold_mould.toml (heat flows into the 60 C mould, the colder sheet is stiffer and
relaxes more slowly, it slides with friction 0.5), the same sheet, plug and vacuum.

Writes results/cold_mould.png (the final wall, the time each point first touched the mould,
the mid-wall temperature, all against the reference arc length) and results/cold_mould.md
(the thinnest wall and where, the wall at the bottom centre, the bottom corner and mid-height
of the side, the coldest and hottest mid-wall temperature, steps, Newton iterations).

Run:  python benchmarks/cold_mould.py        (about 30 s)
"""

from __future__ import annotations

import csv
import json
import tempfile
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from axiform.cli import main  # noqa: E402

HERE = Path(__file__).resolve().parent
EXAMPLES = HERE.parent / "examples"
RESULTS = HERE / "results"
QUIET = ["-q", "--set", "output.plots=false", "--set", "output.vtu=false"]
S_REPORT = {"bottom centre": 0.0, "bottom corner": 11.0, "side, mid-height": 25.0}
CASES = {"sticky mould (no heat)": "cup_thermoforming", "cold mould (60 C, heat, friction 0.5)": "cup_cold_mould"}


def run(name: str, folder: Path) -> tuple[dict[str, np.ndarray], dict]:
    """Run an example; its thickness table (columns as arrays, NaN where empty) and summary."""
    out = folder / name
    code = main(["run", str(EXAMPLES / f"{name}.toml"), "--out", str(out)] + QUIET)
    summary = json.loads((out / "summary.json").read_text())
    if code != 0:
        raise SystemExit(f"{name}: exit {code}: {summary.get('message')}")
    with open(out / "thickness.csv", newline="") as fh:
        rows = list(csv.DictReader(fh))
    return {k: np.array([float(r[k]) if r[k] else np.nan for r in rows]) for k in rows[0]}, summary


def study() -> None:
    with tempfile.TemporaryDirectory() as tmp:
        runs = {label: run(name, Path(tmp)) for label, name in CASES.items()}
    RESULTS.mkdir(exist_ok=True)
    fig, (a_t, a_c, a_T) = plt.subplots(1, 3, figsize=(15, 4.5))
    for k, (label, (t, _)) in enumerate(runs.items()):
        a_t.plot(t["s"], t["thickness"], "o-", ms=2, color=f"C{k}", label=label)
        a_c.plot(t["s"], t["first_contact_1"], "o", ms=3, color=f"C{k}", label=label)
        if "temperature" in t:
            a_T.plot(t["s"], t["temperature"], "-", color=f"C{k}", label=label)
    a_t.set(
        xlabel="reference arc length s (mm), from the centre of the sheet",
        ylabel="final wall thickness (mm)",
        ylim=(0, None),
        title="final wall",
    )
    a_c.set(
        xlabel="reference arc length s (mm)",
        ylabel="time of first contact with the mould (s)",
        title="when each point reached the mould",
    )
    a_T.set(
        xlabel="reference arc length s (mm)",
        ylabel="mid-wall temperature at the end (C)",
        title="temperature (the cold mould's case)",
    )
    for ax in (a_t, a_c, a_T):
        ax.grid(True, alpha=0.3)
        ax.legend(fontsize=8)
    fig.suptitle("Plug-assisted thermoforming of a HIPS cup: a sticky mould against a cold one")
    fig.tight_layout()
    fig.savefig(RESULTS / "cold_mould.png", dpi=110)
    head = [
        "mould",
        "thinnest wall (mm) at s",
        *[f"wall at {k} (s = {s:g})" for k, s in S_REPORT.items()],
        "mid-wall T min / max (C)",
        "steps",
        "Newton iterations",
    ]
    lines = ["| " + " | ".join(head) + " |", "|" + "---|" * len(head)]
    for label, (t, summary) in runs.items():
        i = int(np.nanargmin(t["thickness"]))
        walls = " | ".join(f"{np.interp(s, t['s'], t['thickness']):.3f}" for s in S_REPORT.values())
        temps = f"{np.nanmin(t['temperature']):.0f} / {np.nanmax(t['temperature']):.0f}" if "temperature" in t else "-"
        lines.append(
            f"| {label} | {t['thickness'][i]:.3f} at {t['s'][i]:.1f} | {walls} | {temps} | "
            f"{summary['steps']} | {summary['newton_iterations']} |"
        )
    (RESULTS / "cold_mould.md").write_text("\n".join(lines) + "\n")
    print("\n".join(lines))


if __name__ == "__main__":
    study()
