#!/usr/bin/env python
"""The die drawing of examples/die_drawing.toml in axiform and in CalculiX (ccx, node-to-surface
contact), on the same mesh: punch force and the gap between the sheet's centre and the punch
face against the punch travel, with and without friction, and the final shapes.

    python validation/die_drawing_ccx.py [--quick]        (a few minutes; skipped without ccx)
    python validation/die_drawing_ccx.py --timing [--src OLD/src] [--repeat 3]

Writes validation/results/die_drawing_ccx.md (_q8 with --q8), its picture and the CalculiX
decks under validation/work/die_drawing_ccx/ (apt-get install calculix-ccx).  Asserts: both
codes finish; at every travel from 0.5 to 3 the punch forces within 1 % (0.5 % measured)
and the gaps between the sheet's centre and the punch face within 0.005 (0.003 measured).

Same problem in both codes:
- the sheet r in [0, 6], z in [0, 0.3], 40 x 2 elements (Q4 / CAX4, or Q8 / CAX8 with --q8),
  Mooney-Rivlin C1 = 0.4, C2 = 0.1, kappa = 100 (ccx: C10, C01, D1 = 2 / kappa); ur = 0 on
  the axis, uz = 0 on the top face for r >= 4.8 (the blank holder);
- the punch and the die of the case, as rigid tools: in ccx a strip of CAX4 elements along
  each tool's outline (arcs cut into 2-degree facets, lines into pieces of 0.025) whose
  nodes are all prescribed, the punch moving down by 3; the punch face is cut at the axis;
- contact: node-to-surface, the slave nodes on the sheet's faces (z = 0.3 on the punch,
  z = 0 on the die), linear penalty K = 10 E / h per unit area (E the small-strain modulus,
  h = 0.15 the element edge: the same constant value in axiform, `penalty = K`), Coulomb
  friction mu = 0.1 (punch) and 0.3 (die) with stick slope K, or none;
- ccx: *STATIC with increments of at most 1 % of the travel; axiform: the case's load
  control (30 nominal steps, cut back as needed), in the displacement formulation as CalculiX's
  CAX4 / CAX8 (the case's default mixed Q4 is softer in bending at kappa / mu = 100: the punch
  force at a travel of 0.5 is a third of CAX4's).
ccx prints the forces of axisymmetric models for a segment of the ring: the factor to the whole
ring is measured on a pressurised annulus resting on a rigid tool (`ring_factor`).

--timing: the frictionless case only, axiform in the displacement formulation with no outputs
(the solve through the API) against ccx on one thread, each run `--repeat` times in turn; wall
times min / median, their ratio and the punch forces at a travel of 3.  --src: the source tree
of axiform to time (another checkout's src/, for a before / after comparison).
"""

from __future__ import annotations

import argparse
import os
import re
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent
SRC = Path(sys.argv[sys.argv.index("--src") + 1]) if "--src" in sys.argv[:-1] else ROOT / "src"
sys.path.insert(0, str(SRC.resolve()))

from axiform.case.contact import youngs_modulus  # noqa: E402 (after the sys.path line)
from axiform.case.schema import build, load  # noqa: E402
from axiform.solve.solver import solve  # noqa: E402

sys.path.insert(0, str(HERE))
from checks import RESULTS, Checks, have_ccx  # noqa: E402
from checks import WORK as WORKS  # noqa: E402

WORK = WORKS / "die_drawing_ccx"
CASE = ROOT / "examples" / "die_drawing.toml"
TRAVEL = 3.0


def _lines(ids, per=12):
    ids = [str(int(i)) for i in ids]
    return [", ".join(ids[k : k + per]) for k in range(0, len(ids), per)]


def sample(surface, h: float, arc_deg: float = 2.0, r_min: float = 0.0) -> np.ndarray:
    """Points along a Polyline surface: lines cut into pieces of at most h, arcs into facets
    of at most arc_deg; points at r < r_min are cut off (a tool face crossing the axis)."""
    pts = [surface.a[0]]
    for k in range(len(surface.a)):
        if surface.is_arc[k]:
            n = max(1, int(np.ceil(np.degrees(surface.sweep[k]) / arc_deg)))
            phi = surface.phi0[k] + surface.dir[k] * np.linspace(0, surface.sweep[k], n + 1)[1:]
            pts += list(surface.c[k] + surface.R[k] * np.column_stack([np.cos(phi), np.sin(phi)]))
        else:
            n = max(1, int(np.ceil(surface.L[k] / h)))
            f = np.linspace(0, 1, n + 1)[1:, None]
            pts += list(surface.a[k] + f * (surface.b[k] - surface.a[k]))
    P = np.array(pts)
    if (P[:, 0] < r_min).any():
        k = int(np.argmax(P[:, 0] < r_min))  # first point past the axis: cut the segment there
        a, b = P[k - 1], P[k]
        P = P[:k] if a[0] <= r_min + 1e-12 else np.vstack([P[:k], a + (r_min - a[0]) / (b[0] - a[0]) * (b - a)])
    return P


def tool_strip(P: np.ndarray, thickness: float):
    """A strip of quadrilaterals behind the outline P (k, 2), on the side away from the body
    (to the right of the direction of travel): nodes (2k, 2) and cells (k - 1, 4)
    counter-clockwise; face 3 of each cell (its nodes 3-4) lies on the outline."""
    t = np.gradient(P, axis=0)
    t /= np.linalg.norm(t, axis=1)[:, None]
    left = np.column_stack([-t[:, 1], t[:, 0]])
    Q = P - thickness * left
    Q[:, 0] = np.maximum(Q[:, 0], 0.0)
    k = len(P)
    nodes = np.vstack([P, Q])
    i = np.arange(k - 1)
    cells = np.column_stack([k + i, k + i + 1, i + 1, i])
    return nodes, cells


def ccx_deck(built, friction: bool, penalty: float, incr: float) -> str:
    mesh = built.model.mesh
    P, C = mesh.points, mesh.cells
    etype = "CAX8" if mesh.element.nodes == 8 else "CAX4"
    case = built.case
    mat = case.material
    out = ["*HEADING", "die drawing", "*NODE"]
    out += [f"{i + 1}, {x:.15g}, {y:.15g}" for i, (x, y) in enumerate(P)]
    out += [f"*ELEMENT, TYPE={etype}, ELSET=SHEET"]
    out += [f"{e + 1}, " + ", ".join(str(k + 1) for k in c) for e, c in enumerate(C)]
    nn, ne = len(P), len(C)
    tools = []
    for name, pair in zip(("PUNCH", "DIE"), built.model.contacts, strict=False):
        pts = sample(pair.surface, 0.025)
        nodes, cells = tool_strip(pts, 0.2)
        ids = nn + 1 + np.arange(len(nodes))
        eids = ne + 1 + np.arange(len(cells))
        out += ["*NODE, NSET=" + name] + [f"{i}, {x:.15g}, {y:.15g}" for i, (x, y) in zip(ids, nodes, strict=False)]
        out += [f"*ELEMENT, TYPE=CAX4, ELSET=E{name}"]
        out += [f"{e}, " + ", ".join(str(nn + 1 + k) for k in c) for e, c in zip(eids, cells, strict=False)]
        out += [f"*SURFACE, NAME=M{name}"] + [f"{e}, S3" for e in eids]
        tools.append((name, pair))
        nn += len(nodes)
        ne += len(cells)
    tol = 1e-9
    axis = np.flatnonzero(np.abs(P[:, 0]) < tol) + 1
    holder = np.flatnonzero((np.abs(P[:, 1] - 0.3) < tol) & (P[:, 0] >= 4.8 - tol)) + 1
    centre = np.flatnonzero((np.abs(P[:, 0]) < tol) & (np.abs(P[:, 1] - 0.3) < tol)) + 1
    top = np.flatnonzero(np.abs(P[:, 1] - 0.3) < tol) + 1
    bottom = np.flatnonzero(np.abs(P[:, 1]) < tol) + 1
    out += ["*NSET, NSET=AXIS"] + _lines(axis) + ["*NSET, NSET=HOLDER"] + _lines(holder)
    out += ["*NSET, NSET=CENTRE"] + _lines(centre) + ["*NSET, NSET=TOP"] + _lines(top)
    out += ["*NSET, NSET=BOTTOM"] + _lines(bottom)
    # slave surfaces as element faces (node-based ones give ccx a singular system here)
    ends = np.array([[0, 1], [1, 2], [2, 3], [3, 0]])
    for sname, zf in (("STOP", 0.3), ("SBOTTOM", 0.0)):
        on = np.abs(P[C[:, :4][:, ends], 1] - zf).max(axis=2) < tol  # (e, 4) faces on z = zf
        on &= P[C[:, :4][:, ends], 0].min(axis=2) > tol  # a slave node on the axis: singular in ccx
        out += [f"*SURFACE, NAME={sname}"] + [f"{e + 1}, S{f + 1}" for e, f in zip(*np.nonzero(on), strict=False)]
    out += [
        "*MATERIAL, NAME=MR",
        "*HYPERELASTIC, MOONEY-RIVLIN",
        f"{mat.C1:.15g}, {mat.C2:.15g}, {2.0 / mat.kappa:.15g}",
        "*SOLID SECTION, ELSET=SHEET, MATERIAL=MR",
        "*MATERIAL, NAME=STEEL",
        "*ELASTIC",
        "1e6, 0.3",
        "*SOLID SECTION, ELSET=EPUNCH, MATERIAL=STEEL",
        "*SOLID SECTION, ELSET=EDIE, MATERIAL=STEEL",
    ]
    for (name, pair), slave in zip(tools, ("STOP", "SBOTTOM"), strict=False):
        out += [
            f"*CONTACT PAIR, INTERACTION=I{name}, TYPE=NODE TO SURFACE",
            f"{slave}, M{name}",
            f"*SURFACE INTERACTION, NAME=I{name}",
            "*SURFACE BEHAVIOR, PRESSURE-OVERCLOSURE=LINEAR",
            f"{penalty:.15g}, 1e-6, 1e-3",
        ]
        if friction and pair.mu > 0:
            out += ["*FRICTION", f"{pair.mu:.15g}, {penalty:.15g}"]
    out += [
        "*BOUNDARY",
        "AXIS, 1, 1",
        "HOLDER, 2, 2",
        "DIE, 1, 2",
        "PUNCH, 1, 1",
        "*STEP, NLGEOM, INC=100000",
        "*STATIC",
        f"{incr:.6g}, 1.0, 1e-7, {incr:.6g}",
        "*BOUNDARY",
        f"PUNCH, 2, 2, {-TRAVEL:.15g}",
        "*NODE PRINT, NSET=CENTRE",
        "U",
        "*NODE PRINT, NSET=PUNCH, TOTALS=ONLY",
        "RF",
        "*NODE PRINT, NSET=TOP",
        "U",
        "*END STEP",
        "",
    ]
    return "\n".join(out)


_BLOCK = re.compile(
    r"(displacements \(vx,vy,vz\)|total force \(fx,fy,fz\)) for set (\w+) and time\s+([-+0-9.Ee]+)\s*\n\s*\n"
    r"((?:[ \t]*[-+0-9.Ee]+(?:[ \t]+[-+0-9.Ee]+)+[ \t]*\n)+)"
)


def run_ccx(deck: str, name: str) -> dict:
    WORK.mkdir(parents=True, exist_ok=True)
    (WORK / f"{name}.inp").write_text(deck)
    for ext in (".dat", ".sta", ".frd", ".cvg", ".12d"):
        (WORK / f"{name}{ext}").unlink(missing_ok=True)
    env = dict(os.environ, OMP_NUM_THREADS="1", CCX_NPROC_EQUATION_SOLVER="1")
    proc = subprocess.run(["ccx", "-i", name], cwd=WORK, capture_output=True, text=True, env=env, check=False)
    (WORK / f"{name}.log").write_text(proc.stdout[-20000:] + proc.stderr[-5000:])
    dat = (WORK / f"{name}.dat").read_text() if (WORK / f"{name}.dat").exists() else ""
    rows: dict[tuple[str, float], np.ndarray] = {}
    for m in _BLOCK.finditer(dat):
        vals = np.array([[float(v) for v in line.split()] for line in m.group(4).strip().splitlines()])
        rows[(m.group(2), float(m.group(3)))] = vals
    times = sorted({t for (s, t) in rows if s == "CENTRE"})
    t = np.array(times)
    uz = np.array([rows[("CENTRE", ti)][0, 2] for ti in times])
    fz = np.array([rows[("PUNCH", ti)][0, 1] for ti in times]) if times else np.zeros(0)
    top = rows[("TOP", times[-1])] if times else None
    for ext in (".frd", ".12d", ".cvg"):
        (WORK / f"{name}{ext}").unlink(missing_ok=True)
    (WORK / "spooles.out").unlink(missing_ok=True)
    ok = proc.returncode == 0 and "Job finished" in proc.stdout and len(t) and abs(t[-1] - 1.0) < 1e-9
    return {
        "t": t,
        "uz": uz,
        "fz": fz,
        "top": top,
        "ok": bool(ok),
        "message": "" if ok else (proc.stdout[-800:] + proc.stderr[-300:]).strip(),
    }


def ring_factor(penalty: float) -> float:
    """Total ring force over the tool reaction ccx prints for an axisymmetric model, measured
    the way the punch force is read: an annulus r in [1, 2], z in [0, 0.1] under pressure 1
    on its top face, resting through the same node-to-surface contact on a rigid tool strip
    (all nodes prescribed) below it; the tool's total reaction is 3 pi."""
    tool_nodes, tool_cells = tool_strip(sample(_Line((0.5, 0.0), (2.5, 0.0)), 0.05), 0.2)
    P = np.array([[1.0 + 0.1 * i, 0.1 * j] for i in range(11) for j in range(2)])
    cells = [[2 * i, 2 * i + 2, 2 * i + 3, 2 * i + 1] for i in range(10)]
    n = len(P)
    deck = ["*NODE"] + [f"{i + 1}, {x:.15g}, {y:.15g}" for i, (x, y) in enumerate(P)]
    deck += ["*NODE, NSET=TOOL"] + [f"{n + i + 1}, {x:.15g}, {y:.15g}" for i, (x, y) in enumerate(tool_nodes)]
    deck += ["*ELEMENT, TYPE=CAX4, ELSET=E"] + [
        f"{e + 1}, " + ", ".join(str(k + 1) for k in c) for e, c in enumerate(cells)
    ]
    deck += ["*ELEMENT, TYPE=CAX4, ELSET=ET"] + [
        f"{100 + e}, " + ", ".join(str(n + k + 1) for k in c) for e, c in enumerate(tool_cells)
    ]
    deck += ["*SURFACE, NAME=MT"] + [f"{100 + e}, S3" for e in range(len(tool_cells))]
    deck += ["*SURFACE, NAME=SB"] + [f"{e + 1}, S1" for e in range(10)]
    deck += [
        "*NSET, NSET=HOLD",
        "21",
        "*MATERIAL, NAME=M",
        "*ELASTIC",
        "1000, 0.3",
        "*SOLID SECTION, ELSET=E, MATERIAL=M",
        "*SOLID SECTION, ELSET=ET, MATERIAL=M",
        "*CONTACT PAIR, INTERACTION=I, TYPE=NODE TO SURFACE",
        "SB, MT",
        "*SURFACE INTERACTION, NAME=I",
        "*SURFACE BEHAVIOR, PRESSURE-OVERCLOSURE=LINEAR",
        f"{penalty:.15g}, 1e-6, 1e-3",
        "*BOUNDARY",
        "TOOL, 1, 2",
        "HOLD, 1, 1",
        "*STEP, NLGEOM",
        "*STATIC",
        "*DLOAD",
    ]
    deck += [f"{e + 1}, P3, 1.0" for e in range(10)]
    deck += ["*NODE PRINT, NSET=TOOL, TOTALS=ONLY", "RF", "*END STEP", ""]
    WORK.mkdir(parents=True, exist_ok=True)
    (WORK / "ring_factor.inp").write_text("\n".join(deck))
    subprocess.run(["ccx", "-i", "ring_factor"], cwd=WORK, capture_output=True, text=True, check=False)
    dat = (WORK / "ring_factor.dat").read_text()
    fy = float(list(_BLOCK.finditer(dat))[-1].group(4).split()[1])
    for ext in (".frd", ".12d", ".cvg", ".sta", ".dat"):
        (WORK / f"ring_factor{ext}").unlink(missing_ok=True)
    (WORK / "spooles.out").unlink(missing_ok=True)
    return float(3 * np.pi / abs(fy))


class _Line:
    """A straight tool outline from a to b, in the attributes `sample` reads."""

    def __init__(self, a, b):
        self.a, self.b = np.array([a], float), np.array([b], float)
        self.is_arc = np.array([False])
        self.L = np.linalg.norm(self.b - self.a, axis=1)


def run_axiform(friction: bool, penalty: float, element: str, formulation: str | None = None) -> dict:
    sets = [f"contact[{k}].penalty={penalty!r}" for k in range(2)] + [f"mesh.element={element}"]
    if formulation is not None:
        sets.append(f'mesh.formulation="{formulation}"')
    if not friction:
        sets += ["contact[0].friction=0.0", "contact[1].friction=0.0"]
    built = build(load(CASE, sets), CASE.parent)
    punch = built.model.contacts[0]
    centre = int(
        built.model.dof(
            np.flatnonzero(
                (np.abs(built.model.mesh.points[:, 0]) < 1e-9) & (np.abs(built.model.mesh.points[:, 1] - 0.3) < 1e-9)
            )[0],
            "uz",
        )
    )
    t, uz, fz = [0.0], [0.0], [0.0]

    def record(step):
        t.append(step.lam)
        uz.append(step.u[centre])
        fz.append(punch.report(built.model.contact_states(step.state)[0])["force_z"])

    start = time.perf_counter()
    res = solve(built.model, built.control, built.options, on_step=record)
    wall = time.perf_counter() - start
    top = np.flatnonzero(np.abs(built.model.mesh.points[:, 1] - 0.3) < 1e-9)
    x = built.model.mesh.points[top] + res.last.u.reshape(-1, built.model.dpn)[top, :2]
    rep = punch.report(built.model.contact_states(res.last.state)[0])
    return {
        "t": np.array(t),
        "uz": np.array(uz),
        "fz": np.array(fz),
        "x_top": x[np.argsort(x[:, 0])],
        "status": res.status,
        "steps": len(res.steps),
        "iterations": res.newton_iterations,
        "open": int((rep["status"] == 0).sum()),
        "slaves": len(rep["status"]),
        "built": built,
        "wall": wall,
    }


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="only the case with friction, coarser ccx increments")
    ap.add_argument("--q8", action="store_true", help="Q8 / CAX8 instead of Q4 / CAX4")
    ap.add_argument("--timing", action="store_true", help="time the frictionless case in both codes")
    ap.add_argument("--src", type=Path, default=SRC, help="the axiform source tree to time (default: this one)")
    ap.add_argument("--repeat", type=int, default=3)
    args = ap.parse_args(argv)
    if not have_ccx("die_drawing_ccx.py"):
        return 0
    if args.timing:
        return timing(args.repeat)
    element = "q8" if args.q8 else "q4"
    base = build(load(CASE, [f"mesh.element={element}"]), CASE.parent)
    penalty = 10.0 * youngs_modulus(base.model.material) / 0.15
    factor = ring_factor(penalty)
    print(f"ccx ring factor {factor:.6g}; penalty K = {penalty:.6g}")
    runs = []
    for friction in (True,) if args.quick else (True, False):
        ax = run_axiform(friction, penalty, element, "displacement")  # CAX4 / CAX8: no mixed or B-bar form
        deck = ccx_deck(ax["built"], friction, penalty, 0.02 if args.quick else 0.01)
        name = f"die_{element}_{'friction' if friction else 'frictionless'}"
        cc = run_ccx(deck, name)
        cc["fz"] = factor * cc["fz"]  # the punch's reaction: its force on the sheet, whole ring
        runs.append((friction, ax, cc))
        print(
            f"{name}: axiform {ax['status']} {ax['steps']} steps; ccx {'finished' if cc['ok'] else 'stopped'} "
            f"{len(cc['t'])} increments; end gap axiform {-TRAVEL - ax['uz'][-1] * 1 + 0:.4f}"
        )
    return report(runs, element, penalty, factor).finish()


def timing(repeat: int) -> int:
    """Wall times of the frictionless die drawing, Q4 / CAX4: axiform (displacement formulation,
    no outputs) and ccx (one thread), `repeat` runs each in turn; printed as a table."""
    base = build(load(CASE, ["mesh.element=q4"]), CASE.parent)
    penalty = 10.0 * youngs_modulus(base.model.material) / 0.15
    factor = ring_factor(penalty)
    ta, tc = [], []
    for _ in range(repeat):
        ax = run_axiform(False, penalty, "q4", "displacement")
        ta.append(ax["wall"])
        deck = ccx_deck(ax["built"], False, penalty, 0.01)
        start = time.perf_counter()
        cc = run_ccx(deck, "die_q4_frictionless")  # the deck of the comparison run (the same)
        tc.append(time.perf_counter() - start)
    fa, fc = -ax["fz"][-1], -factor * cc["fz"][-1]
    print(f"source: {SRC}")
    print("| | wall min / median | steps, iterations | punch force at travel 3 |\n|---|---:|---:|---:|")
    print(
        f"| axiform Q4, displacement | {min(ta):.2f} / {np.median(ta):.2f} s | {ax['steps']}, {ax['iterations']} | "
        f"{fa:.4f} |"
    )
    print(
        f"| CalculiX CAX4 | {min(tc):.2f} / {np.median(tc):.2f} s | {len(cc['t'])} increments | {fc:.4f} "
        f"({100 * (fa / fc - 1):+.2f} %) |"
    )
    print(f"| ratio axiform / CalculiX | {min(ta) / min(tc):.3f} / {np.median(ta) / np.median(tc):.3f} | | |")
    return 0


def gap(t, uz):
    """Distance from the punch face down to the sheet's centre (top face): -travel - uz."""
    return -uz - TRAVEL * t


def report(runs, element, penalty, factor) -> Checks:
    """The table, the picture and the checks of the runs."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(1, 3, figsize=(15, 4.6))
    L = [
        "# Die drawing: axiform against CalculiX",
        "",
        "Written by `validation/die_drawing_ccx.py`. "
        + (
            f"Element {element.upper()} / {'CAX8' if element == 'q8' else 'CAX4'}; penalty K = {penalty:.4g} per unit "
            f"area (both codes); ccx ring factor {factor:.4g}."
        ),
        "",
        "| friction | travel | punch force axiform | punch force ccx | diff | centre gap axiform | centre gap ccx |",
        "|---|---:|---:|---:|---:|---:|---:|",
    ]
    checks = Checks()
    for friction, a, c in runs:
        tag = "mu 0.1 / 0.3" if friction else "none"
        checks.above(
            f"friction {tag}: both codes finish (1 yes, 0 no)", float(a["status"] == "finished" and c["ok"]), 1
        )
        style = "-" if friction else "--"
        ga, gc = gap(a["t"], a["uz"]), gap(c["t"], c["uz"])
        ax[0].plot(TRAVEL * a["t"], -a["fz"], "C0" + style, label=f"axiform, friction {tag}")
        ax[0].plot(TRAVEL * c["t"], -c["fz"], "C3" + style, label=f"CalculiX, friction {tag}")
        ax[1].plot(TRAVEL * a["t"], ga, "C0" + style, label=f"axiform, friction {tag}")
        ax[1].plot(TRAVEL * c["t"], gc, "C3" + style, label=f"CalculiX, friction {tag}")
        if friction:
            ax[2].plot(a["x_top"][:, 0], a["x_top"][:, 1], "C0.-", ms=3, label="axiform, top face")
            if c["top"] is not None:
                P = a["built"].model.mesh.points
                top = np.flatnonzero(np.abs(P[:, 1] - 0.3) < 1e-9)
                u = {int(row[0]) - 1: row[1:3] for row in c["top"]}
                xc = np.array([P[n] + u[n] for n in top])
                xc = xc[np.argsort(xc[:, 0])]
                ax[2].plot(xc[:, 0], xc[:, 1], "C3x-", ms=3, label="CalculiX, top face")
            pts = a["built"].model.contacts[0].surface.polyline() + np.array([0.0, -TRAVEL])
            ax[2].plot(pts[:, 0], pts[:, 1], "k-", lw=1, label="punch at travel 3")
        for s in (0.5, 1.0, 1.5, 2.0, 2.5, 3.0):
            fa = np.interp(s / TRAVEL, a["t"], a["fz"])
            fc = np.interp(s / TRAVEL, c["t"], c["fz"]) if len(c["t"]) and c["t"][-1] >= s / TRAVEL - 1e-9 else np.nan
            gap_a = np.interp(s / TRAVEL, a["t"], ga)
            gap_c = np.interp(s / TRAVEL, c["t"], gc) if not np.isnan(fc) else np.inf
            checks.below(f"friction {tag}, travel {s:g}: punch force ccx / axiform - 1, %", 100 * (fc / fa - 1), 1.0)
            checks.below(f"friction {tag}, travel {s:g}: centre gap axiform - ccx", gap_a - gap_c, 0.005)
            L.append(
                f"| {tag} | {s:g} | {-fa:.4g} | {-fc:.4g} | {100 * (fc / fa - 1):+.1f} % | "
                f"{np.interp(s / TRAVEL, a['t'], ga):.4f} | "
                f"{np.interp(s / TRAVEL, c['t'], gc) if not np.isnan(fc) else np.nan:.4f} |"
            )
        L.append(
            f"| {tag} | runs | axiform {a['status']}, {a['steps']} steps, {a['iterations']} iterations, "
            f"{a['open']} of {a['slaves']} punch slaves open | "
            f"ccx {'finished' if c['ok'] else 'stopped: ' + c['message'][-200:]}, "
            f"{len(c['t'])} increments | | | |"
        )
    ax[0].set(xlabel="punch travel", ylabel="punch force (whole ring)", title="punch force")
    ax[1].set(xlabel="punch travel", ylabel="gap punch face - sheet centre", title="centre gap")
    ax[2].set(xlabel="r", ylabel="z", title="top face of the sheet at travel 3", xlim=(-0.1, 4.5))
    ax[2].set_aspect("equal")
    for a_ in ax:
        a_.grid(alpha=0.3)
        a_.legend(fontsize=7)
    fig.tight_layout()
    RESULTS.mkdir(exist_ok=True)
    name = "die_drawing_ccx" + ("_q8" if element == "q8" else "")
    fig.savefig(RESULTS / f"{name}.png", dpi=110)
    L += [""] + checks.table()
    (RESULTS / f"{name}.md").write_text("\n".join(L) + "\n")
    print("\n".join(L))
    return checks


if __name__ == "__main__":
    sys.exit(main())
