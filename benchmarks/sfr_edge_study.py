#!/usr/bin/env python
"""Which rule for the fibre rotations of SFR edges whose normal displacement is held at both
nodes (clamped rim, axis r = 0, plane-strain faces): Model(sfr_edges="tie" | "fix" | "free").

A mesh-convergence study against fine Q8 (DESIGN.md 3, "Things to know about SFR"):

1. Hughes-Carnoy clamped plate (paper 4.1): R = 7.5, h = 0.5, Mooney-Rivlin C1 = 80, C2 = 20,
   kappa = 1e4; ur = uz = 0 at r = 7.5, ur = 0 on the axis; unit follower pressure on z = 0;
   the centre node (0, 0.5) is driven by displacement control to w = 8 (32 steps of 0.25,
   so every reported w is a converged step unless a step was cut back, in which case p is
   interpolated linearly and the table says so).  Two rim variants: "rim rule", where rot is
   not fixed at the rim so the rule acts there too, and "rim rot=0" (rot fixed at r = 7.5 as
   the case-file example of DESIGN.md 7 does), where the rule acts on the axis only.
   SFR meshes 2x20, 4x40, 8x80 (through-thickness x radial), plus 16x160 for the three rules
   to see the trend; reference Q8 16x160 (its error estimated by Richardson from Q8 4x40,
   8x80, 16x160); Q4 on the same meshes for context.  Reported: p and the centre thickness
   at w = 0.5, 1, 2, 4, 6, 8, and how far the held edges bow between their nodes.
2. Thick cylinder in plane strain (r in [1.5, 3], slice height 0.2, two element rows, uz = 0
   on both faces: edges along r with uz held), internal follower pressure, inner radius
   driven to a = 1.125 A ... 1.5 A; same material.  Reference: Q8 nr = 64 and the 1D radial
   boundary-value problem of the law as implemented (tests/oracles.py, solve_bvp at 1e-8).
3. Volumetric locking: one small step on the plate at kappa/mu = 1, 5, 50, to show what the
   large errors at small w are made of.

Run:  python benchmarks/sfr_edge_study.py            (full, writes results/sfr_edge_study.md)
      python benchmarks/sfr_edge_study.py --quick    (smoke run: coarser meshes and reference)

Linear solver: axiform.solve.linsolve factorizes with SuperLU, permc_spec="MMD_AT_PLUS_A" and the
default partial pivoting (diag_pivot_thresh = 1), which discards the symmetric ordering and
fills L+U 15x more than needed on these meshes (8x80 SFR: 2.2e6 vs 1.4e5 nonzeros, 0.37 s vs
0.01 s per factorization).  So that the study runs in minutes, this script replaces the
factorization by the same SuperLU with threshold pivoting in symmetric mode
(diag_pivot_thresh = 0.01, SymmetricMode); the solutions are the same to round-off, which the
script checks side by side on one case (and reports the speed ratio).  --stock-linsolve
keeps the library's factorization.
"""

from __future__ import annotations

import argparse
import datetime
import platform
import sys
import time
from pathlib import Path

import numpy as np
from scipy.sparse.linalg import splu

import axiform.solve.newton
from axiform import DisplacementControl, Model, MooneyRivlin, rectangle, select_edges, select_nodes, solve
from axiform.solve.linsolve import SingularTangentError

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parent / "tests"))

C1, C2, KAPPA = 80.0, 20.0, 1.0e4
MATERIAL = MooneyRivlin(C1, C2, KAPPA)
# plate
RADIUS, THICK, W_END, W_STEPS = 7.5, 0.5, 8.0, 32
W_REPORT = np.array([0.5, 1.0, 2.0, 4.0, 6.0, 8.0])
# cylinder
A, B, H, NZ = 1.5, 3.0, 0.2, 2
A_REPORT = A * np.array([1.125, 1.25, 1.375, 1.5])
CYL_STEPS = 8  # inner-radius increments of A/16: every reported a is a step

RULES = ("tie", "fix", "free")


# ------------------------------------------------------------------------ linear solver
_stock_factorize = axiform.solve.newton.factorize


def symmetric_mode_factorize(K):
    """SuperLU with the minimum-degree ordering on K^T + K kept (threshold pivoting)."""
    try:
        lu = splu(K.tocsc(), permc_spec="MMD_AT_PLUS_A", diag_pivot_thresh=0.01, options=dict(SymmetricMode=True))
    except RuntimeError as exc:
        raise SingularTangentError(str(exc)) from exc

    def solve_(b):
        x = lu.solve(b)
        if not np.all(np.isfinite(x)):
            raise SingularTangentError("the tangent is singular")
        return x

    return solve_


def use_factorization(fast: bool) -> None:
    axiform.solve.newton.factorize = symmetric_mode_factorize if fast else _stock_factorize


# ------------------------------------------------------------------------------ helpers
def edge_bow(mesh, u: np.ndarray, edges: np.ndarray) -> float:
    """Largest normal bow between the nodes of the given boundary edges: the SFR enrichment on
    an edge i-j is the bubble s (L - s) / L (theta_i - theta_j) normal to it, L/4 |dtheta| at
    mid-edge (0 for Q4/Q8, whose held edges are held everywhere)."""
    if mesh.element.dofs_per_node != 3:
        return 0.0
    nodes = mesh.boundary_edges[edges][:, :2]
    length = np.linalg.norm(mesh.points[nodes[:, 1]] - mesh.points[nodes[:, 0]], axis=1)
    th = u[3 * nodes + 2]
    return float(np.max(length / 4 * np.abs(th[:, 0] - th[:, 1])))


# ---------------------------------------------------------------------------- the plate
def plate(element: str, nt: int, nr: int, rule: str = "tie", rim_rot: bool = False) -> dict:
    """Solve the clamped plate on an nt x nr mesh; p, w and the centre thickness per step."""
    mesh = rectangle((0.0, RADIUS), (0.0, THICK), (nr, nt), element)
    model = Model(mesh, MATERIAL, formulation="displacement", sfr_edges=rule)
    rim = select_nodes(mesh, {"r": RADIUS})
    model.fix(rim, ["ur", "uz", "rot"] if rim_rot else ["ur", "uz"])
    model.fix(select_nodes(mesh, {"r": 0.0}), ["ur"])
    model.pressure(select_edges(mesh, {"z": 0.0}), 1.0)
    model = model.finalize()
    top = select_nodes(mesh, {"r": 0.0, "z": THICK})[0]
    bottom = select_nodes(mesh, {"r": 0.0, "z": 0.0})[0]
    c = int(model.dof(top, "uz"))
    b = int(model.dof(bottom, "uz"))
    held = np.concatenate([select_edges(mesh, {"r": 0.0}), select_edges(mesh, {"r": RADIUS})])
    t0 = time.perf_counter()
    res = solve(model, DisplacementControl(c, W_END, W_STEPS))
    wall = time.perf_counter() - t0
    bow = max((edge_bow(mesh, s.u, held) / s.u[c] for s in res.steps), default=np.nan)
    w = np.array([0.0] + [s.u[c] for s in res.steps])
    p = np.array([0.0] + [s.lam for s in res.steps])
    t = np.array([THICK] + [THICK + s.u[c] - s.u[b] for s in res.steps])
    exact = all(np.isclose(w, x, rtol=0, atol=1e-9).any() for x in W_REPORT)
    return dict(
        element=element,
        mesh=f"{nt}x{nr}",
        rule=rule,
        rim_rot=rim_rot,
        status=res.status,
        message=res.message,
        steps=len(res.steps),
        iterations=res.newton_iterations,
        dofs=model.n_free,
        wall=wall,
        w=w,
        p=p,
        t=t,
        exact=exact,
        bow=bow,
        p_at=np.interp(W_REPORT, w, p) if w[-1] >= W_END - 1e-9 else None,
        t_at=np.interp(W_REPORT, w, t) if w[-1] >= W_END - 1e-9 else None,
    )


def small_deflection(element: str, nt: int, nr: int, kappa: float, w: float = 0.05) -> float:
    """Pressure of the plate at centre deflection w (one step), rule tie."""
    mesh = rectangle((0.0, RADIUS), (0.0, THICK), (nr, nt), element)
    model = Model(mesh, MooneyRivlin(C1, C2, kappa), formulation="displacement")
    model.fix(select_nodes(mesh, {"r": RADIUS}), ["ur", "uz"])
    model.fix(select_nodes(mesh, {"r": 0.0}), ["ur"])
    model.pressure(select_edges(mesh, {"z": 0.0}), 1.0)
    model = model.finalize()
    c = int(model.dof(select_nodes(mesh, {"r": 0.0, "z": THICK})[0], "uz"))
    res = solve(model, DisplacementControl(c, w, 1))
    assert res.status == "finished", res.message
    return res.last.lam


# ------------------------------------------------------------------------- the cylinder
def cylinder(element: str, nr: int, rule: str = "tie") -> dict:
    mesh = rectangle((A, B), (0.0, H), (nr, NZ), element)
    model = Model(mesh, MATERIAL, formulation="displacement", sfr_edges=rule)
    model.fix(select_nodes(mesh, {"z": 0.0}), ["uz"])
    model.fix(select_nodes(mesh, {"z": H}), ["uz"])
    model.pressure(select_edges(mesh, {"r": A}), 1.0)
    model = model.finalize()
    c = int(model.dof(select_nodes(mesh, {"r": A, "z": 0.0})[0], "ur"))
    held = np.concatenate([select_edges(mesh, {"z": 0.0}), select_edges(mesh, {"z": H})])
    t0 = time.perf_counter()
    res = solve(model, DisplacementControl(c, A_REPORT[-1] - A, CYL_STEPS))
    wall = time.perf_counter() - t0
    bow = max(edge_bow(mesh, s.u, held) / s.u[c] for s in res.steps)
    a = np.array([A] + [A + s.u[c] for s in res.steps])
    p = np.array([0.0] + [s.lam for s in res.steps])
    dpn = model.dpn
    # how much the fibre rotations move, as a displacement over the wall (B - A), relative to ur
    theta = max((np.abs(s.u[2::3]).max() * (B - A) / np.abs(s.u[0::dpn]).max() if dpn == 3 else 0.0) for s in res.steps)
    uz = max(np.abs(s.u[1::dpn]).max() / np.abs(s.u[0::dpn]).max() for s in res.steps)
    exact = all(np.isclose(a, x, rtol=0, atol=1e-9).any() for x in A_REPORT)
    return dict(
        element=element,
        nr=nr,
        rule=rule,
        status=res.status,
        steps=len(res.steps),
        iterations=res.newton_iterations,
        dofs=model.n_free,
        wall=wall,
        exact=exact,
        p_at=np.interp(A_REPORT, a, p) if res.status == "finished" else None,
        theta=theta,
        uz=uz,
        bow=bow,
    )


# ------------------------------------------------------------------------------ output
def pct(x: float) -> str:
    return f"{100 * x:+.2f}"


def table(header: list[str], rows: list[list[str]]) -> str:
    out = ["| " + " | ".join(header) + " |", "|" + "|".join("---" for _ in header) + "|"]
    out += ["| " + " | ".join(r) + " |" for r in rows]
    return "\n".join(out)


def label(run: dict) -> str:
    if run["element"] != "sfr":
        return run["element"].upper()
    return f"SFR {run['rule']}" + (" + rim rot=0" if run["rim_rot"] else "")


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--quick", action="store_true", help="smoke run: coarse meshes and reference")
    ap.add_argument(
        "--stock-linsolve", action="store_true", help="keep axiform's own factorization (slow on these meshes)"
    )
    ap.add_argument("--out", type=Path, default=HERE / "results" / "sfr_edge_study.md")
    args = ap.parse_args()
    t_start = time.perf_counter()
    lines: list[str] = []

    def emit(s: str = "") -> None:
        print(s, flush=True)
        lines.append(s)

    quick = args.quick
    plate_meshes = [(2, 20), (4, 40)] if quick else [(2, 20), (4, 40), (8, 80)]
    extra_mesh = None if quick else (16, 160)  # SFR tie/fix/free only, to see the trend
    q8_meshes = [(2, 20), (4, 40), (8, 80)] if quick else [(4, 40), (8, 80), (16, 160)]
    cyl_meshes = [4, 8] if quick else [4, 8, 16, 32]
    cyl_ref = 32 if quick else 64

    emit("# SFR edge rule: mesh-convergence study" + (" (--quick smoke run)" if quick else ""))
    emit()
    emit(
        f"Written by `benchmarks/sfr_edge_study.py{' --quick' if quick else ''}` on "
        f"{datetime.date.today()} ({platform.machine()}, Python {platform.python_version()}, "
        f"numpy {np.__version__}; wall times on a shared, loaded 2-core machine)."
    )
    emit()
    emit(
        "Rules (`Model(sfr_edges=...)`) for the fibre rotations of an SFR edge whose normal "
        "displacement is held at both nodes: **tie** (one shared theta per chain of such "
        "edges), **fix** (theta = 0), **free** (nothing; one theta is then fixed somewhere "
        "against the uniform-theta mode).  Under tie and fix the held edge is held everywhere "
        "(the theta bubble s (L - s)/L (theta_i - theta_j) vanishes), under free it bows "
        "between its nodes by up to L/4 |theta_i - theta_j|: the column *bow* reports that, "
        "relative to the controlled displacement."
    )
    emit()

    # ---- linear solver check, side by side
    emit("## Linear solver used by this study")
    emit()
    if args.stock_linsolve:
        use_factorization(False)
        emit("axiform's own factorization (`--stock-linsolve`).")
    else:
        use_factorization(False)
        slow = plate("sfr", 4, 40, "tie")
        use_factorization(True)
        fast = plate("sfr", 4, 40, "tie")
        dp = np.abs(fast["p"] - slow["p"]).max() / np.abs(slow["p"]).max()
        emit(
            "axiform.solve.linsolve (SuperLU, MMD_AT_PLUS_A, default partial pivoting) replaced by "
            "SuperLU, MMD_AT_PLUS_A, diag_pivot_thresh = 0.01, SymmetricMode (see the module "
            "docstring).  Same run (SFR tie 4x40 plate, to w = 8), side by side:"
        )
        emit()
        emit(
            table(
                ["factorization", "Newton its", "wall [s]"],
                [
                    ["axiform.solve.linsolve (stock)", str(slow["iterations"]), f"{slow['wall']:.2f}"],
                    ["symmetric mode", str(fast["iterations"]), f"{fast['wall']:.2f}"],
                ],
            )
        )
        emit()
        emit(
            f"Speed-up {slow['wall'] / fast['wall']:.1f}x; max |p difference| over the path "
            f"{dp:.1e} of max p (same solution to round-off)."
        )
    emit()

    # ---- plate
    emit("## 1. Clamped plate (Hughes & Carnoy), pressure p at centre deflection w")
    emit()
    q8 = [plate("q8", nt, nr) for nt, nr in q8_meshes]
    for run in q8:
        assert run["p_at"] is not None, run["message"]
    ref = q8[-1]
    p_ref, t_ref = ref["p_at"], ref["t_at"]
    p1, p2, p3 = (r["p_at"] for r in q8)
    with np.errstate(divide="ignore", invalid="ignore"):
        order = np.log2((p1 - p2) / (p2 - p3))
        p_rich = p3 + (p3 - p2) / (2.0**order - 1)
    emit(
        f"Reference: Q8 {ref['mesh']} ({ref['dofs']} unknowns, {ref['wall']:.0f} s).  Its own "
        f"error is estimated by Richardson from the three Q8 meshes (observed order and "
        f"extrapolated p below).  The convergence is slow (observed order 1-1.7, consistent "
        f"with the stress singularities at the clamped rim corners), so the reference itself "
        f"is off by the last row of that table, a fraction of a per cent.  The SFR errors below are relative to Q8 "
        f"{ref['mesh']}, not to the extrapolation."
    )
    emit()
    rows = [[f"p Q8 {r['mesh']}"] + [f"{x:.5g}" for x in r["p_at"]] for r in q8]
    rows.append(["observed order (Q8)"] + [f"{o:.2f}" for o in order])
    rows.append(["p Richardson"] + [f"{x:.5g}" for x in p_rich])
    rows.append([f"Q8 {ref['mesh']} vs Richardson, %"] + [pct(x) for x in p_ref / p_rich - 1])
    rows.append([f"thickness at r = 0, Q8 {ref['mesh']}"] + [f"{x:.4f}" for x in t_ref])
    emit(table(["w"] + [f"{w:g}" for w in W_REPORT], rows))
    emit()

    configs = [("tie", False), ("fix", False), ("free", False), ("tie", True), ("free", True)]
    runs: dict[tuple, dict] = {}
    for nt, nr in plate_meshes:
        for rule, rim_rot in configs:
            runs[("sfr", nt, rule, rim_rot)] = plate("sfr", nt, nr, rule, rim_rot)
        runs[("q4", nt, "-", False)] = plate("q4", nt, nr)
    all_meshes = list(plate_meshes)
    if extra_mesh:
        for rule in RULES:
            runs[("sfr", extra_mesh[0], rule, False)] = plate("sfr", *extra_mesh, rule)
        all_meshes.append(extra_mesh)

    def keys(nt):
        if extra_mesh and nt == extra_mesh[0]:
            return [("sfr", nt, r, False) for r in RULES]
        return [("sfr", nt, r, rr) for r, rr in configs] + [("q4", nt, "-", False)]

    emit(
        'Relative error of p, in %, (p - p_ref) / p_ref.  Without "+ rim rot=0": rot not '
        'fixed at r = 7.5, the rule acts on the rim and on the axis; "+ rim rot=0": rot fixed '
        "at the rim explicitly (as in DESIGN.md's case-file example), the rule acts on the axis "
        "only (fix + rim rot=0 is fix).  bow: max over the path of the largest bow of the rim "
        "and axis edges / w."
    )
    emit()
    header = ["mesh", "element / rule"] + [f"w={w:g}" for w in W_REPORT] + ["bow", "its", "s"]
    rows = []
    for nt, nr in all_meshes:
        for key in keys(nt):
            run = runs[key]
            if run["p_at"] is None:
                rows.append(
                    [run["mesh"], label(run), f"stopped at w = {run['w'][-1]:.3g}: {run['message']}"] + [""] * 8
                )
                continue
            e = run["p_at"] / p_ref - 1
            rows.append(
                [run["mesh"], label(run) + ("" if run["exact"] else " (interp.)")]
                + [pct(x) for x in e]
                + [f"{run['bow']:.1e}", str(run["iterations"]), f"{run['wall']:.1f}"]
            )
    emit(table(header, rows))
    emit()
    same = 0.0
    for nt, _ in plate_meshes:
        pa, pb = runs[("sfr", nt, "tie", True)]["p"][1:], runs[("sfr", nt, "tie", False)]["p"][1:]
        same = max(same, np.abs(pa / pb - 1).max() if len(pa) == len(pb) else np.inf)
    emit(
        f"tie and tie + rim rot=0 agree to {same:.1e} (relative, every step, every mesh): under "
        "tie the rim and the axis are two tied groups, and the uniform-theta mode shifts one "
        "group's value to zero at no cost, so fixing the rim's theta changes nothing."
    )
    emit()

    emit("Thickness at the centre (r = 0), relative error in % vs the reference:")
    emit()
    rows = []
    for nt, nr in all_meshes:
        for key in keys(nt):
            run = runs[key]
            if run["t_at"] is None:
                continue
            rows.append([run["mesh"], label(run)] + [pct(x) for x in run["t_at"] / t_ref - 1])
    emit(table(["mesh", "element / rule"] + [f"w={w:g}" for w in W_REPORT], rows))
    emit()

    emit(
        "Difference between the rules, p(fix) / p(tie) - 1 and p(free) / p(tie) - 1 in %: "
        "how fast the choice stops mattering."
    )
    emit()
    rows = []
    for nt, nr in all_meshes:
        tie = runs[("sfr", nt, "tie", False)]["p_at"]
        for rule in ("fix", "free"):
            rows.append([f"{nt}x{nr}", rule] + [pct(x) for x in runs[("sfr", nt, rule, False)]["p_at"] / tie - 1])
    emit(table(["mesh", "rule"] + [f"w={w:g}" for w in W_REPORT], rows))
    emit()

    # ---- cylinder
    emit("## 2. Thick cylinder, plane strain (uz = 0 on both faces), pressure p at inner radius a")
    emit()
    cref = cylinder("q8", cyl_ref)
    try:
        from oracles import RadialBVP

        p_bvp = RadialBVP(MATERIAL, A, B, tol=1e-8).pressures(A_REPORT)
    except Exception as exc:  # the oracle is a bonus; the Q8 reference is the study's
        p_bvp = None
        emit(f"(1D oracle unavailable: {exc})")
    emit(
        f"A = {A}, B = {B}, slice height {H}, {NZ} element rows; reference Q8 nr = {cyl_ref} ({cref['dofs']} unknowns)."
    )
    emit()
    rows = [[f"p Q8 nr={cyl_ref}"] + [f"{x:.7g}" for x in cref["p_at"]]]
    if p_bvp is not None:
        rows.append(["p 1D BVP (exact for this law)"] + [f"{x:.7g}" for x in p_bvp])
        rows.append(["Q8 vs BVP, %"] + [f"{100 * x:+.1e}" for x in cref["p_at"] / p_bvp - 1])
    emit(table(["a/A"] + [f"{x / A:g}" for x in A_REPORT], rows))
    emit()
    p_cref = cref["p_at"]
    crun = {}
    for nr in cyl_meshes:
        for rule in RULES:
            crun[(nr, rule)] = cylinder("sfr", nr, rule)
        crun[(nr, "q4")] = cylinder("q4", nr)
        crun[(nr, "q8")] = cylinder("q8", nr)
    emit(
        f"Relative error of p in % vs Q8 nr = {cyl_ref}.  theta: max |theta| (B - A) / max |ur| "
        "over the path (0: the rotations stay at rest); bow: largest bow of the faces z = 0, H "
        "between nodes / (a - A), max over the path (the faces of a plane-strain slice must "
        "stay flat)."
    )
    emit()
    rows = []
    for nr in cyl_meshes:
        for key in [(nr, r) for r in RULES] + [(nr, "q4"), (nr, "q8")]:
            run = crun[key]
            name = f"SFR {run['rule']}" if run["element"] == "sfr" else run["element"].upper()
            if run["p_at"] is None:
                rows.append([str(nr), name, "stopped"] + [""] * 6)
                continue
            e = run["p_at"] / p_cref - 1
            rows.append(
                [f"{nr}x{NZ}", name]
                + [pct(x) for x in e]
                + [f"{run['theta']:.1e}", f"{run['bow']:.1e}", str(run["iterations"])]
            )
    emit(
        table(["mesh (r x z)", "element / rule"] + [f"a/A={x / A:g}" for x in A_REPORT] + ["theta", "bow", "its"], rows)
    )
    emit()

    # ---- locking: why the small-w errors are large
    emit("## 3. Why the errors at small w are large: volumetric locking, not the edge rule")
    emit()
    emit(
        "Same plate, one step to w = 0.05 (linear range), p relative to Q8 8x80 at the same "
        "kappa, in %, for three kappa / mu (mu = 2 (C1 + C2) = 200; the study uses 50):"
    )
    emit()
    rows = []
    lock_meshes = [("sfr", 2, 20), ("sfr", 4, 40), ("sfr", 2, 80), ("q4", 2, 20), ("q8", 2, 20)]
    for ratio in (1.0, 5.0, 50.0):
        kappa = ratio * 2.0 * (C1 + C2)
        pr = small_deflection("q8", 8, 80, kappa)
        rows.append([f"{ratio:g}"] + [pct(small_deflection(el, nt, nr, kappa) / pr - 1) for el, nt, nr in lock_meshes])
    emit(table(["kappa/mu"] + [f"{el.upper()} {nt}x{nr}" for el, nt, nr in lock_meshes], rows))
    emit()
    emit(
        "At kappa/mu = 1 SFR is within 1 % of Q8 on 2x20 where Q4 is 15 % too stiff (the shear "
        "locking that the fibre rotations cure); at kappa/mu = 50 every fully integrated "
        "element locks volumetrically, SFR about as much as Q4, and refining in r alone (2x80) "
        "does not help.  The edge rules differ in p by at most 1.5 % on any mesh."
    )
    emit()

    # ---- verdict, computed
    emit("## Summary (computed)")
    emit()
    rows = []
    for rule in RULES:
        rows.append(
            [rule]
            + [f"{np.abs(runs[('sfr', nt, rule, False)]['p_at'] / p_ref - 1).max() * 100:.2f}" for nt, _ in all_meshes]
        )
    rows.append(
        ["Q4"]
        + [f"{np.abs(runs[('q4', nt, '-', False)]['p_at'] / p_ref - 1).max() * 100:.2f}" for nt, _ in plate_meshes]
        + ([""] if extra_mesh else [])
    )
    emit(
        "Plate, max |error of p| in % over w = 0.5 ... 8 (dominated by w = 0.5: bending, where "
        "all fully integrated elements lock at kappa/mu = 50):"
    )
    emit()
    emit(table(["rule"] + [f"{nt}x{nr}" for nt, nr in all_meshes], rows))
    emit()
    for what, idx in (("p, w >= 2 (membrane range)", slice(2, None)),):
        rows = []
        for rule in RULES:
            rows.append(
                [rule]
                + [
                    f"{np.abs(runs[('sfr', nt, rule, False)]['p_at'][idx] / p_ref[idx] - 1).max() * 100:.2f}"
                    for nt, _ in all_meshes
                ]
            )
        emit(f"Plate, max |error| in % of {what}:")
        emit()
        emit(table(["rule"] + [f"{nt}x{nr}" for nt, nr in all_meshes], rows))
        emit()
    spread = []
    for nt, _ in all_meshes:
        ps = np.array([runs[("sfr", nt, rule, False)]["p_at"] for rule in RULES])
        spread.append(f"{100 * ((ps.max(axis=0) - ps.min(axis=0)) / p_ref).max():.2f}")
    emit("Plate, spread of p between the three rules, max over w of (max - min) / p_ref, in %:")
    emit()
    emit(table(["mesh"] + [f"{nt}x{nr}" for nt, nr in all_meshes], [["spread"] + spread]))
    emit()
    rows = []
    for rule in RULES:
        rows.append(
            [rule]
            + [f"{np.abs(runs[('sfr', nt, rule, False)]['t_at'] / t_ref - 1).max() * 100:.2f}" for nt, _ in all_meshes]
        )
    emit("Plate, max |error| in % of the centre thickness over w = 0.5 ... 8:")
    emit()
    emit(table(["rule"] + [f"{nt}x{nr}" for nt, nr in all_meshes], rows))
    emit()
    rows = []
    for rule in RULES + ("q4",):
        rows.append(
            [rule if rule != "q4" else "Q4"]
            + [f"{np.abs(crun[(nr, rule)]['p_at'] / p_cref - 1).max() * 100:.3f}" for nr in cyl_meshes]
        )
    emit("Cylinder, max |error of p| in % over a/A = 1.125 ... 1.5:")
    emit()
    emit(table(["rule"] + [f"{nr}x{NZ}" for nr in cyl_meshes], rows))
    emit()
    emit(CONCLUSION.strip() if not quick else "(--quick: no conclusion drawn from a smoke run)")
    emit()
    total = time.perf_counter() - t_start
    emit(f"Total runtime {total:.0f} s.")
    args.out.parent.mkdir(parents=True, exist_ok=True)
    args.out.write_text("\n".join(lines) + "\n")
    print(f"wrote {args.out}")
    return 0


CONCLUSION = """
## Conclusion: keep "tie" as the default

Numbers from the full run above (references: Q8 16x160 for the plate, within 0.05-0.19 % of its
Richardson extrapolation; Q8 nr = 64 for the cylinder, equal to the exact 1D solution to 1e-8).

1. The rule is a second-order effect on the plate's load curve.  The spread of p between the
   three rules is 1.5 / 0.43 / 0.23 / 0.12 % on 2x20 / 4x40 / 8x80 / 16x160 (first order in
   h), while SFR's own error is 133 / 38 / 11 / 3.2 % at w = 0.5 (volumetric locking, section
   3) and 0.2-3.2 % at w >= 2.  No rule changes the ranking against Q4 or Q8.
2. tie and fix are conforming: the held edges stay held between the nodes (bow = 0).  free is
   not: the clamped rim and the axis bow by up to 0.7 % of w (2x20; 0.09 % on 16x160), and the
   faces of the plane-strain slice, which must stay flat, by 0.15-1.5 % of the radial
   displacement.  That leak is what makes free look good on the cylinder (max p error 5.0 /
   1.1 / 0.20 / 0.04 % against 12.4 / 3.1 / 0.79 / 0.20 % for tie and fix): the bulging faces
   relax the volumetric locking, and free undershoots the exact pressure (-0.85 % on 4x2,
   -0.04 % on 32x2), which a conforming displacement model cannot do.  It also makes the
   answer depend on whether the user fixes rot at the rim (free vs free + rim rot=0 differ by
   up to 1.6 % in p on 2x20), and on a symmetry plane or the axis it moves material across it.
   On the plate free has the best centre thickness on the finer meshes (0.14 % on 16x160
   against 0.38 % for tie) and about the same p as tie (within 0.03 % on 16x160); it stays
   available for who wants node-only boundary conditions, not as the default.
3. Between the two conforming rules, tie is the weaker constraint (fix = tie plus "all the
   tied groups share theta = 0"), and the extra constraint of fix shows where forming cares
   most: the centre thickness.  fix's thickness error converges at about half the rate
   (max over w: 3.93 / 2.16 / 1.40 / 0.92 % against tie's 3.40 / 1.56 / 0.76 / 0.38 %; at
   w = 8 on 16x160, 0.92 % against 0.33 %; observed order about 0.6 against 1.0).  Presumably
   because fix makes the fibre rotations at the clamped rim, where the plate turns, equal to
   those on the axis, where symmetry forbids any rotation; tie only keeps each held edge
   straight.  fix is closer in p for w >= 2 by 0.04-0.8 percentage points (0.61 against
   0.65 % on 16x160), a gap that halves with each refinement like the rule difference itself.
4. tie does not care whether the user also fixes rot on one held edge (tie and tie + rim
   rot=0 agree to 4e-14: the uniform-theta mode shifts a tied group to zero for free), so the
   case-file example of DESIGN.md 7 (rot fixed at the rim) and the bare clamp give the same
   answer.
5. On the cylinder tie, fix and Q4 are identical (theta stays 0 to 1e-14): for a field that
   does not depend on z the enrichment has nothing to add once the faces are held flat.

Recommendation: keep sfr_edges = "tie" as the default (conforming, the least constrained
conforming choice, best centre thickness of the two, invariant to an explicit rim rot fix);
document "fix" (slightly closer p at large deflection, worse thickness) and "free" (node-only
boundary conditions: held edges bow) as options.
"""

if __name__ == "__main__":
    sys.exit(main())
