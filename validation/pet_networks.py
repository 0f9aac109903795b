#!/usr/bin/env python
"""Stretch blow moulding of a PET preform with a Prony series and with networks in parallel:
`examples/stretch_blow_moulding.toml` (Mooney–Rivlin with a Prony
series, linear viscoelastic) beside `examples/pet_stretch_blow.toml` (an Arruda–Boyce
equilibrium network and a Bergström–Boyce viscous network: hardening whose onset moves with
the rate), the same preform, rod, mould and air.

    python validation/pet_networks.py        (about 3 minutes on 2 cores)

Writes validation/results/pet_networks.md and pet_networks.png: the law's equibiaxial nominal
stress at 1, 5 and 20 /s (homogeneous, incompressible to 1e-3: the lateral stress solved to
zero at each step with the update's tangent), and the two bottles' final walls.  Asserts: the
network bottle finishes with the default settings; the law hardens (its slope at a stretch of
3.25 at least twice that at 2) and stiffens with the rate at every stretch; the network
bottle's body wall (current z from 40 to 150 mm) is more even than the Prony bottle's
(a smaller coefficient of variation).
"""

from __future__ import annotations

import json
import sys
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent
sys.path[:0] = [str(ROOT / "src"), str(HERE)]

from checks import RESULTS, WORK, Checks  # noqa: E402

from axiform.case.schema import parse, read  # noqa: E402
from axiform.cli import main as axiform  # noqa: E402

EXAMPLES = ROOT / "examples"
WORK_HERE = WORK / "pet_networks"
RATES = (1.0, 5.0, 20.0)  # 1/s
LAM_END, STEPS = 3.5, 250
BODY = (40.0, 150.0)  # current z of the bottle's body (mm)


def equibiaxial(law, rate: float) -> tuple[np.ndarray, np.ndarray]:
    """Stretches (STEPS,) along r and theta from 1 to LAM_END at dlam/dt = rate, and the nominal
    stress P_rR, the free stretch along z solved so that P_zZ = 0 (Newton, the update's tangent)."""
    dt = (LAM_END - 1.0) / rate / STEPS
    state, a = law.initial_state(()), 1.0
    lams = 1.0 + rate * dt * np.arange(1, STEPS + 1)
    out = []
    for lam in lams:
        for _ in range(40):
            P, A, _ = law.update(np.array([lam, 0.0, 0.0, a, lam]), state, dt, None)
            da = -P[3] / A[3, 3]
            a += da
            if abs(da) < 1e-13:
                break
        P, _, state = law.update(np.array([lam, 0.0, 0.0, a, lam]), state, dt, None)
        out.append(P[0])
    return lams, np.array(out)


def wall(out: Path) -> dict[str, np.ndarray]:
    d = np.genfromtxt(out / "thickness.csv", delimiter=",", names=True)
    return {k: d[k] for k in ("s", "z", "thickness")}


def spread(w: dict[str, np.ndarray]) -> float:
    """The coefficient of variation of the body's wall thickness."""
    t = w["thickness"][(w["z"] > BODY[0]) & (w["z"] < BODY[1])]
    return float(t.std() / t.mean())


def main() -> int:
    WORK_HERE.mkdir(parents=True, exist_ok=True)
    law = parse(read(EXAMPLES / "pet_stretch_blow.toml")).material.build()
    curves = {rate: equibiaxial(law, rate) for rate in RATES}
    runs = {}
    for name, case in (("prony", "stretch_blow_moulding.toml"), ("networks", "pet_stretch_blow.toml")):
        runs[name] = WORK_HERE / name
        code = axiform(["run", str(EXAMPLES / case), "--out", str(runs[name]), "-q", "--set", "output.plots=false"])
        print(f"{name}: exit {code}")
    summary = {k: json.loads((v / "summary.json").read_text()) for k, v in runs.items()}
    walls = {k: wall(v) for k, v in runs.items()}
    checks = Checks()
    checks.above("networks: finished (1 = yes)", float(summary["networks"]["status"] == "finished"), 1.0)
    lams, P = curves[RATES[0]]
    slope = np.gradient(P, lams)
    checks.above("law: slope at 3.25 / slope at 2", np.interp(3.25, lams, slope) / np.interp(2.0, lams, slope), 2.0)
    faster = min(float((curves[b][1] - curves[a][1]).min()) for a, b in zip(RATES, RATES[1:], strict=False))
    checks.above("law: least rise of the stress from one rate to the next (MPa)", faster, 1e-3)
    evener = spread(walls["prony"]) - spread(walls["networks"])
    checks.above("body wall's coefficient of variation, prony - networks", evener, 0.0)
    draw(curves, walls)
    lines = [
        "# PET stretch blow moulding: a Prony series and networks in parallel",
        "",
        "Written by `validation/pet_networks.py`.",
        "",
    ]
    lines += [
        "| material | status | steps | Newton iterations | thinnest wall (mm) | body wall (mm) "
        "| body's coefficient of variation |"
    ]
    lines += ["|---|---|---:|---:|---:|---|---:|"]
    for k, v in summary.items():
        w = walls[k]
        body = w["thickness"][(w["z"] > BODY[0]) & (w["z"] < BODY[1])]
        lines.append(
            f"| {k} | {v['status']} | {v['steps']} | {v['newton_iterations']} | {v['thickness']['min']:.3f} "
            f"| {body.min():.3f} to {body.max():.3f} | {spread(w):.3f} |"
        )
    lines += [
        "",
        "The law's equibiaxial nominal stress (MPa):",
        "",
        "| stretch | " + " | ".join(f"{r:g} /s" for r in RATES) + " |",
    ]
    lines += ["|---:|" + "---:|" * len(RATES)]
    for lam in (1.5, 2.0, 2.5, 3.0, 3.5):
        lines.append(f"| {lam:g} | " + " | ".join(f"{np.interp(lam, *curves[r]):.2f}" for r in RATES) + " |")
    lines += ["", *checks.table(), ""]
    RESULTS.mkdir(exist_ok=True)
    (RESULTS / "pet_networks.md").write_text("\n".join(lines) + "\n")
    print("\n".join(lines))
    return checks.finish()


def draw(curves, walls) -> None:
    fig, (a, b) = plt.subplots(1, 2, figsize=(11, 4.2), layout="constrained")
    for rate, (lams, P) in curves.items():
        a.plot(lams, P, label=f"{rate:g} /s")
    a.set(xlabel="equibiaxial stretch", ylabel="nominal stress (MPa)", title="the network law, equibiaxial")
    a.legend(title="stretch rate")
    for k, style in (("prony", "--"), ("networks", "-")):
        w = walls[k]
        b.plot(w["z"], w["thickness"], style, label={"prony": "Prony series", "networks": "networks in parallel"}[k])
    b.axvspan(*BODY, color="0.92", zorder=0)
    b.set(xlabel="current height z (mm)", ylabel="wall thickness (mm)", title="the bottle's final wall (body shaded)")
    b.legend()
    fig.savefig(RESULTS / "pet_networks.png", dpi=110)


if __name__ == "__main__":
    sys.exit(main())
