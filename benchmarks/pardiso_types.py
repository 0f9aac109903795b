#!/usr/bin/env python
"""PARDISO's matrix types and orderings on the tangents of the plate and the ring: the
factorization (phase 22) and the solve with two right-hand sides (phase 33), CPU ms, the
least of `--repeat` interleaved calls, one thread (benchmarks/README.md § 8.1).

    .venv/bin/python benchmarks/pardiso_types.py [--quick] [--repeat 9]

Tangents: the plate (Q8, NZ x 10 NZ, after 5 displacement steps to w = 2 in: symmetric to
round-off), the ring of _perf_common.py with its follower pressure ending at a free node
(non-symmetric) and without it (symmetric, indefinite at the perturbed state).  Variants:
mtype -2 (symmetric indefinite, upper triangle), 1 (structurally symmetric), 11 (with
scaling and weighted matching, and without), each with nested dissection (METIS) and
minimum degree.  Prints a markdown table; the residual |K x - b| / |b| of each answer and the
fill (iparm[17]) are given with it.
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np
import scipy.sparse as sp

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))
sys.path.insert(0, str(HERE.parent / "validation"))
from _perf_common import build_model, deformed_state, divisions_for_dofs, table  # noqa: E402

import axiform as af  # noqa: E402
import axiform.solve.pardiso as pd  # noqa: E402

# name: (mtype, scaling and matching, ordering: 2 nested dissection, 0 minimum degree)
VARIANTS = {
    "-2 ND": (-2, 0, 2),
    "-2 MD": (-2, 0, 0),
    "1 ND": (1, 0, 2),
    "11 sm ND": (11, 1, 2),
    "11 sm MD": (11, 1, 0),
    "11 ND": (11, 0, 2),
}


def plate_tangent(nz: int):
    from plate_peers import plate_model

    model, centre = plate_model("q8", 10 * nz, nz)
    step = af.solve(model, af.DisplacementControl(centre, target=2.0, steps=5)).steps[-1]
    ev = model.evaluate(step.u_f, step.lam)
    return ev.K.tocsr(), np.column_stack([-ev.r, -ev.dr_dlam])


def ring_tangent(element: str, dofs: int, pressure: float):
    model = build_model(element, divisions_for_dofs(element, dofs), pressure=pressure)
    ev = model.evaluate(*deformed_state(model))
    return ev.K.tocsr(), np.column_stack([-ev.r, -ev.dr_dlam])


def handle(K: sp.csr_matrix, mtype: int, matching: int, ordering: int):
    """A PARDISO handle analysed for K in the given type and ordering, on one thread."""
    A = sp.triu(K, format="csr") if mtype == -2 else K.copy()
    A.sort_indices()
    s = pd.Pardiso(pd.mkl())
    s.iparm[17] = -1  # report the fill
    s.analyse(
        pd.int32(A.indptr, "indptr"),
        pd.int32(A.indices, "indices"),
        A.data,
        mtype == -2,
        A,
        (mtype, matching, ordering),
    )
    s.threads = 1
    return s, A


def measure(K: sp.csr_matrix, B: np.ndarray, repeat: int) -> dict:
    made = {name: handle(K, *v) for name, v in VARIANTS.items()}
    best = {name: [np.inf, np.inf] for name in VARIANTS}
    for _ in range(repeat):
        for name, (s, A) in made.items():
            c0 = time.process_time()
            s.factor(A.data)
            c1 = time.process_time()
            x = s.solve(A.data, B)
            c2 = time.process_time()
            best[name] = [min(best[name][0], c1 - c0), min(best[name][1], c2 - c1)]
    out = {}
    for name, (s, A) in made.items():
        x = s.solve(A.data, B)
        res = np.linalg.norm(K @ x - B) / np.linalg.norm(B)
        out[name] = (1e3 * best[name][0], 1e3 * best[name][1], int(s.iparm[17]), res)
    return out


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="the smallest tangents only")
    ap.add_argument("--repeat", type=int, default=9)
    args = ap.parse_args(argv)
    if pd.mkl() is None:
        print("pardiso_types.py: MKL (pypardiso) is not installed")
        return 0
    cases = [
        (f"plate {nz}x{10 * nz}", lambda nz=nz: plate_tangent(nz)) for nz in ((4,) if args.quick else (4, 8, 16, 18))
    ]
    for dofs in (1000,) if args.quick else (1000, 4000, 16000):
        cases.append((f"ring q8 {dofs}, pressure", lambda d=dofs: ring_tangent("q8", d, 5.0)))
        cases.append((f"ring q4 {dofs}, no pressure", lambda d=dofs: ring_tangent("q4", d, 0.0)))
    rows = []
    for label, make in cases:
        K, B = make()
        asym = abs(K - K.T).max() / abs(K).max()
        for name, (f, s, fill, res) in measure(K, B, args.repeat).items():
            rows.append(
                [label, f"{K.shape[0]:,}", f"{asym:.0e}", name, f"{f:.2f}", f"{s:.2f}", f"{fill:,}", f"{res:.0e}"]
            )
        print(f"{label} done", flush=True)
    header = ["tangent", "n", "asymmetry", "variant", "factor CPU ms", "solve CPU ms", "fill", "residual"]
    print(table(header, rows))
    return 0


if __name__ == "__main__":
    sys.exit(main())
