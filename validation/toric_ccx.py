#!/usr/bin/env python
"""The toric plate (examples/toric_plate.toml, paper 4.2) with Q8 4x40 against CalculiX CAX8
with node-to-surface contact, which uses every node of the contact face: the pressure p at
equal centre deflection w (mid-side nodes are slaves in both).

    python validation/toric_ccx.py        (a few minutes; skipped without ccx)

Writes validation/results/toric_ccx.md and the deck under validation/work/toric_ccx/.
Asserts: ccx reaches w = 5 (it stops on its own increment control after that) and axiform's
pressure is within 0.5 % of ccx's at w = 1 ... 5 (0.2 % measured).

Same problem: the plate R = 7.5, h = 0.5, Q8 / CAX8 4 x 40, Mooney-Rivlin C1 = 80, C2 = 20,
kappa = 1e4 (D1 = 2 / kappa), rim clamped, follower pressure on z = 0; the torus a rigid
strip of CAX4 elements under its lower half circle (1-degree facets), all nodes fixed;
contact penalty K = 10 E / h (h = 0.125) per unit area in both codes (axiform: `penalty`),
Coulomb friction mu = 1 with stick slope K in both (instead of the example's sticky
contact, which ccx does not have).  axiform drives w to 6 by displacement control; ccx is
loaded by pressure along axiform's p(w) (*STATIC, an amplitude with one knot per axiform
step, increments of at most one knot, cut back by ccx as needed) and prints w.
"""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent
sys.path.insert(0, str(HERE))
from checks import RESULTS, Checks, have_ccx  # noqa: E402
from checks import WORK as WORKS  # noqa: E402

WORK = WORKS / "toric_ccx"
CASE = ROOT / "examples" / "toric_plate.toml"
E = 9 * 1e4 * 200 / (3e4 + 200)
K = 10 * E / 0.125
SETS = [
    "mesh.element=q8",
    "mesh.divisions=[40,4]",
    "contact[0].sticky=false",
    "contact[0].friction=1.0",
    f"contact[0].penalty={K!r}",
    f"contact[0].tangential_penalty={K!r}",
]


def run_axiform(src: Path) -> dict:
    """Run the case with the axiform found in src (a child process: two versions side by
    side); returns w and p per step."""
    code = f"""
import json, sys
sys.path.insert(0, {str(src)!r})
from axiform.case.schema import build, load
from axiform.solve.solver import solve
b = build(load({str(CASE)!r}, {SETS!r}), {str(CASE.parent)!r})
w, p = [], []
dof = int(b.model.dof(int(__import__('numpy').flatnonzero((abs(b.model.mesh.points[:, 0]) < 1e-9)
      & (abs(b.model.mesh.points[:, 1] - 0.5) < 1e-9))[0]), 'uz'))
res = solve(b.model, b.control, b.options, on_step=lambda s: (w.append(float(s.u[dof])), p.append(float(s.lam))))
print(json.dumps({{"w": w, "p": p, "status": res.status, "slaves": int(len(b.model.contacts[0].nodes))}}))
"""
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout
    import json

    return json.loads(out.strip().splitlines()[-1])


def deck(p_steps: np.ndarray) -> str:
    sys.path.insert(0, str(ROOT / "src"))
    sys.path.insert(0, str(HERE))
    from die_drawing_ccx import _lines, tool_strip

    from axiform import rectangle

    mesh = rectangle((0.0, 7.5), (0.0, 0.5), (40, 4), "q8")
    P, C = mesh.points, mesh.cells
    tol = 1e-9
    out = ["*HEADING", "toric plate", "*NODE"] + [f"{i + 1}, {x:.15g}, {y:.15g}" for i, (x, y) in enumerate(P)]
    out += ["*ELEMENT, TYPE=CAX8, ELSET=PLATE"] + [
        f"{e + 1}, " + ", ".join(str(k + 1) for k in c) for e, c in enumerate(C)
    ]
    phi = np.radians(np.arange(0.0, -180.0 - 1e-9, -1.0))  # clockwise: the body to the left, outside
    ring = np.column_stack([4.5 + 1.5 * np.cos(phi), 3.0 + 1.5 * np.sin(phi)])
    nodes, cells = tool_strip(ring, 0.2)
    n0, e0 = len(P), len(C)
    out += ["*NODE, NSET=TORUS"] + [f"{n0 + i + 1}, {x:.15g}, {y:.15g}" for i, (x, y) in enumerate(nodes)]
    out += ["*ELEMENT, TYPE=CAX4, ELSET=ETORUS"] + [
        f"{e0 + e + 1}, " + ", ".join(str(n0 + k + 1) for k in c) for e, c in enumerate(cells)
    ]
    out += ["*SURFACE, NAME=MTORUS"] + [f"{e0 + e + 1}, S3" for e in range(len(cells))]
    ends = np.array([[0, 1], [1, 2], [2, 3], [3, 0]])
    on = np.abs(P[C[:, :4][:, ends], 1] - 0.5).max(axis=2) < tol
    on &= P[C[:, :4][:, ends], 0].min(axis=2) > tol
    out += ["*SURFACE, NAME=STOP"] + [f"{e + 1}, S{f + 1}" for e, f in zip(*np.nonzero(on), strict=False)]
    bottom = [e + 1 for e, c in enumerate(C) if abs(P[c[0], 1]) < tol and abs(P[c[1], 1]) < tol]
    rim = np.flatnonzero(np.abs(P[:, 0] - 7.5) < tol) + 1
    axis = np.flatnonzero(np.abs(P[:, 0]) < tol) + 1
    centre = np.flatnonzero((np.abs(P[:, 0]) < tol) & (np.abs(P[:, 1] - 0.5) < tol)) + 1
    out += (
        ["*NSET, NSET=RIM"]
        + _lines(rim)
        + ["*NSET, NSET=AXIS"]
        + _lines(axis)
        + ["*NSET, NSET=CENTRE"]
        + _lines(centre)
    )
    out += [
        "*MATERIAL, NAME=MR",
        "*HYPERELASTIC, MOONEY-RIVLIN",
        f"80, 20, {2.0 / 1e4:.15g}",
        "*SOLID SECTION, ELSET=PLATE, MATERIAL=MR",
        "*MATERIAL, NAME=STEEL",
        "*ELASTIC",
        "1e8, 0.3",
        "*SOLID SECTION, ELSET=ETORUS, MATERIAL=STEEL",
        "*CONTACT PAIR, INTERACTION=I, TYPE=NODE TO SURFACE",
        "STOP, MTORUS",
        "*SURFACE INTERACTION, NAME=I",
        "*SURFACE BEHAVIOR, PRESSURE-OVERCLOSURE=LINEAR",
        f"{K:.15g}, 1e-3, 1e-3",
        "*FRICTION",
        f"1.0, {K:.15g}",
    ]
    n = len(p_steps)
    pmax = float(p_steps[-1])
    amp = [f"{t:.15g}, {a:.15g}" for t, a in zip(np.arange(n + 1) / n, np.r_[0.0, p_steps / pmax], strict=False)]
    out += ["*AMPLITUDE, NAME=RAMP"] + [", ".join(amp[k : k + 4]) for k in range(0, len(amp), 4)]
    out += [
        "*BOUNDARY",
        "RIM, 1, 2",
        "AXIS, 1, 1",
        "TORUS, 1, 2",
        "*STEP, NLGEOM, INC=100000",
        "*STATIC",
        f"{1.0 / n:.15g}, 1.0, 1e-7, {1.0 / n:.15g}",
        "*CONTROLS, PARAMETERS=FIELD, FIELD=DISPLACEMENT",
        "1.e-7, 1.e-6, , , 1.e-7, 1.e-5, 1.e-3, 1.e-8",
        "*DLOAD, AMPLITUDE=RAMP",
    ]
    out += [f"{e}, P1, {pmax:.15g}" for e in bottom]
    out += ["*NODE PRINT, NSET=CENTRE", "U", "*END STEP", ""]
    return "\n".join(out)


def run_ccx(p_steps: np.ndarray) -> dict:
    sys.path.insert(0, str(HERE))
    from die_drawing_ccx import _BLOCK

    WORK.mkdir(parents=True, exist_ok=True)
    (WORK / "toric_cax8.inp").write_text(deck(p_steps))
    env = dict(os.environ, OMP_NUM_THREADS="1")
    proc = subprocess.run(["ccx", "-i", "toric_cax8"], cwd=WORK, capture_output=True, text=True, env=env, check=False)
    (WORK / "toric_cax8.log").write_text(proc.stdout[-20000:] + proc.stderr[-3000:])
    dat = (WORK / "toric_cax8.dat").read_text()
    t, w = [], []
    for m in _BLOCK.finditer(dat):
        t.append(float(m.group(3)))
        w.append(float(m.group(4).split()[2]))
    n = len(p_steps)
    p = np.interp(t, np.arange(n + 1) / n, np.r_[0.0, p_steps])
    for ext in (".frd", ".12d", ".cvg"):
        (WORK / f"toric_cax8{ext}").unlink(missing_ok=True)
    return {"w": np.array(w), "p": p, "ok": "Job finished" in proc.stdout}


def main() -> int:
    if not have_ccx("toric_ccx.py"):
        return 0
    now = run_axiform(ROOT / "src")
    ccx = run_ccx(np.array(now["p"]))
    checks = Checks()
    L = [
        "# Toric plate Q8 4x40 against CalculiX CAX8, node-to-surface",
        "",
        "Written by `validation/toric_ccx.py`. "
        f"Penalty K = {K:.5g} per unit area, friction mu = 1 (stick slope K) in both codes; "
        f"ccx {'finished' if ccx['ok'] else 'stopped'} after {len(ccx['w'])} increments.",
        "",
        "| w | p CalculiX | p axiform | diff |",
        "|---:|---:|---:|---:|",
    ]
    reached = float(ccx["w"].max()) if len(ccx["w"]) else 0.0
    checks.above("largest centre deflection w ccx reaches", reached, 5.0)
    for w in (1.0, 2.0, 3.0, 4.0, 5.0, 6.0):
        if reached < w:
            continue
        pc = np.interp(w, ccx["w"], ccx["p"])
        pa = np.interp(w, now["w"], now["p"])
        L.append(f"| {w:g} | {pc:.4g} | {pa:.4g} | {100 * (pa / pc - 1):+.2f} % |")
        checks.below(f"w = {w:g}: p axiform / p CalculiX - 1, %", 100 * (pa / pc - 1), 0.5)
    L += ["", f"Slave nodes: {now['slaves']}.", ""] + checks.table()
    RESULTS.mkdir(exist_ok=True)
    (RESULTS / "toric_ccx.md").write_text("\n".join(L) + "\n")
    print("\n".join(L))
    return checks.finish()


if __name__ == "__main__":
    sys.exit(main())
