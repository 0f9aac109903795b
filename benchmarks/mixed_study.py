"""Mixed against displacement elements: accuracy against kappa/mu and cost per iteration.

1. The thick sphere of tests/test_mixed.py (A = 1, B = 1.5, Mooney-Rivlin C1 = 0.4, C2 = 0.1,
   internal follower pressure 0.35, layered 16 x 4 along the mid-surface arc): the bore
   displacement of every element and formulation against the 1D solution of the same law
   (tests/oracles.py), kappa/mu from 10 to 1e5; SFR with both pressure spaces (P0 and P1).
2. The paper's plate (C1 = 80, C2 = 20 psi, 2 x 20 and 8 x 80): the pressure at a
   mid-thickness centre deflection of 6 in, against a mixed Q8 16 x 160 reference, at
   kappa/mu = 50 (the paper's kappa) and 1e3.
3. Cost of one residual + tangent evaluation, mixed over displacement, for 1e4 elements.

    .venv/bin/python benchmarks/mixed_study.py        # writes benchmarks/results/mixed_study.md
"""

from __future__ import annotations

import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))

from oracles import SphereBVP  # noqa: E402

from axiform import (
    DisplacementControl,
    LoadControl,
    Model,
    MooneyRivlin,
    rectangle,  # noqa: E402
    select_edges,
    select_nodes,
    solve,
)
from axiform.fem.mesh import layered  # noqa: E402
from axiform.fem.profile import Arc, Profile  # noqa: E402

OUT = Path(__file__).parent / "results" / "mixed_study.md"
A, B, C1, C2, P = 1.0, 1.5, 0.4, 0.1, 0.35
VARIANTS = [
    ("q4", "displacement", None),
    ("q4", "mixed", "p0"),
    ("q8", "displacement", None),
    ("q8", "mixed", "p1"),
    ("sfr", "displacement", None),
    ("sfr", "mixed", "p0"),
    ("sfr", "mixed", "p1"),
]


def sphere(element, kappa, formulation, space):
    profile = Profile(((A + B) / 2, 0.0), (Arc((0.0, 0.0), (0.0, (A + B) / 2), 16, True),))
    mesh = layered(profile, B - A, 4, element)
    model = Model(mesh, MooneyRivlin(C1, C2, kappa), formulation=formulation, pressure_space=space)
    model.fix(select_nodes(mesh, {"set": "start"}), ["uz"])
    model.fix(select_nodes(mesh, {"set": "end"}), ["ur"])
    model.pressure(select_edges(mesh, {"set": "inner"}), P)
    model = model.finalize()
    res = solve(model, LoadControl(1.0, 10))
    if res.status != "finished":
        return np.nan
    return float(res.last.u[model.dof(select_nodes(mesh, {"set": "inner", "z": 0.0}), "ur")][0])


def plate(element, divisions, kappa, formulation, w=6.0, space=None):
    mesh = rectangle((0.0, 7.5), (0.0, 0.5), divisions, element)
    model = Model(mesh, MooneyRivlin(80.0, 20.0, kappa), formulation=formulation, pressure_space=space)
    model.fix(select_nodes(mesh, {"r": 7.5}), ["ur", "uz", "rot"])
    model.fix(select_nodes(mesh, {"r": 0.0}), ["ur"])
    model.pressure(select_edges(mesh, {"z": 0.0}), 1.0)
    model = model.finalize()
    c = int(model.dof(select_nodes(mesh, {"r": 0.0, "z": 0.25})[0], "uz"))
    res = solve(model, DisplacementControl(c, w, 12))
    return res.last.lam if res.status == "finished" else np.nan


def evaluate_cost(element, formulation, n=100):
    mesh = rectangle((0.0, 10.0), (0.0, 1.0), (n, n), element)
    model = Model(mesh, MooneyRivlin(80.0, 20.0, 1e4), formulation=formulation).finalize()
    u = 1e-5 * np.random.default_rng(0).standard_normal(model.n_full)
    best = np.inf
    for _ in range(5):
        t = time.perf_counter()
        model.solid.evaluate(u, tangent=True)
        best = min(best, time.perf_counter() - t)
    return best


def zero_modes(element, divisions, formulation, space):
    mesh = rectangle((1.0, 2.0), (0.0, 1.0), divisions, element)
    model = Model(mesh, MooneyRivlin(0.4, 0.1, 1e3), formulation=formulation, pressure_space=space).finalize()
    _, Ke = model.solid.evaluate(np.zeros(model.n_full))
    K = np.zeros((model.n_full, model.n_full))
    for dofs, k in zip(model.solid.dofs, Ke, strict=False):
        K[np.ix_(dofs, dofs)] += k
    w = np.linalg.eigvalsh(0.5 * (K + K.T))
    return int((np.abs(w) < 1e-8 * np.abs(w).max()).sum())


def main():
    lines = [
        "# Mixed (u–p–J̄) against displacement elements",
        "",
        "Regenerate: `.venv/bin/python benchmarks/mixed_study.py` (about a minute).",
        "",
        "## 1. Thick sphere, bore displacement error against the 1D solution (16 × 4 layered mesh)",
        "",
        "| kappa/mu | " + " | ".join(f"{e} {f}{' ' + s if s else ''}" for e, f, s in VARIANTS) + " |",
        "|---|" + "---|" * len(VARIANTS),
    ]
    mu = 2 * (C1 + C2)
    for km in (10.0, 1e2, 1e3, 1e4, 1e5):
        exact = SphereBVP(MooneyRivlin(C1, C2, km * mu), A, B).bore_displacement(P, 0.18)
        errs = [sphere(e, km * mu, f, s) / exact - 1 for e, f, s in VARIANTS]
        lines.append(f"| {km:g} | " + " | ".join(f"{100 * v:+.3f} %" for v in errs) + " |")
        print(lines[-1], flush=True)
    lines += [
        "",
        "## 2. Paper's plate: pressure at w = 6 in (mid-thickness centre) against mixed Q8 16 × 160",
        "",
        "| kappa/mu | mesh | "
        + " | ".join(f"{e} {f}" for e in ("q4", "q8", "sfr") for f in ("displacement", "mixed"))
        + " | sfr mixed p1 |",
        "|---|---|" + "---|" * 7,
    ]
    for km in (50.0, 1e3):
        ref = plate("q8", (160, 16), km * 200.0, "mixed")
        for div in ((20, 2), (80, 8)):
            vals = [
                plate(e, div, km * 200.0, f) / ref - 1 for e in ("q4", "q8", "sfr") for f in ("displacement", "mixed")
            ]
            vals.append(plate("sfr", div, km * 200.0, "mixed", space="p1") / ref - 1)
            lines.append(f"| {km:g} | {div[1]}x{div[0]} | " + " | ".join(f"{100 * v:+.2f} %" for v in vals) + " |")
            print(lines[-1], flush=True)
        lines.append(f"| {km:g} | reference | p = {ref:.4f} psi |" + " |" * 6)
    lines += [
        "",
        "## 3. One residual + tangent evaluation, 100 × 100 elements (best of 5, this machine)",
        "",
        "| element | displacement (s) | mixed (s) | mixed / displacement |",
        "|---|---|---|---|",
    ]
    for e in ("q4", "q8", "sfr"):
        d, m = evaluate_cost(e, "displacement"), evaluate_cost(e, "mixed")
        lines.append(f"| {e} | {d:.3f} | {m:.3f} | {m / d:.2f} |")
        print(lines[-1], flush=True)
    lines += [
        "",
        "## 4. Zero-energy modes of the assembled tangent at u = 0 (eigenvalues below 1e-8 of the largest)",
        "",
        "kappa/mu = 1e3.  Rigid axial translation: 1; SFR adds the uniform fibre rotation (and, on one",
        "element, one more mode, DESIGN 3).  A pressure space that added spurious modes would show here.",
        "",
        "| element | mesh | displacement | mixed p0 | mixed p1 |",
        "|---|---|---|---|---|",
    ]
    for e in ("q4", "q8", "sfr"):
        for div in ((1, 1), (2, 2), (4, 1)):
            lines.append(
                f"| {e} | {div[1]}x{div[0]} | "
                + " | ".join(
                    str(zero_modes(e, div, f, sp))
                    for f, sp in (("displacement", None), ("mixed", "p0"), ("mixed", "p1"))
                )
                + " |"
            )
    OUT.write_text("\n".join(lines) + "\n")
    print("wrote", OUT)


if __name__ == "__main__":
    main()
