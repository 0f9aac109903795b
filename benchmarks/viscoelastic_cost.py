#!/usr/bin/env python
"""The cost of a Newton iteration's evaluation with and without a Prony series.

1. `Model.evaluate(u, t, state, tangent=True)` (residual and tangent, the part of a Newton
   iteration that the series changes) on the ring of `_perf_common.py` (r 1..2, z 0..1, a
   60 x 60 mesh: 3600 elements) for Q4 displacement, Q4 mixed, Q8 mixed and SFR mixed, with
   the elastic Mooney-Rivlin law of the other benchmarks and the same law with a 1- and a
   3-term Prony series, and the 3 terms shifted by a temperature per point (WLF: one set of
   the step's factors per point), side by side in one run: the median of interleaved repeats of the
   process CPU time (single-threaded) and the ratio to the elastic law.  The viscoelastic
   evaluation starts from a committed state with history (h_i != 0), a step dt later.  The
   same for `tangent=False` (a residual alone, as a line search or a sensitivity's shadow).
2. Where the time of the series goes: the pieces of the displacement assembly's memory
   branch (fem.assembly; the mixed one calls the same prony_step) on one chunk of
   elements, timed apart (same points, same calls as the assembly makes).

    python benchmarks/viscoelastic_cost.py            # about a minute
    python benchmarks/viscoelastic_cost.py --quick    # smoke run

The tables go to stdout and to benchmarks/results/viscoelastic_cost.md (…_quick.md with
--quick, NAME.md with --out NAME).  Run it again with glibc's malloc told to keep freed
memory (GLIBC_TUNABLES=glibc.malloc.mmap_threshold=33554432:glibc.malloc.trim_threshold=536870912,
--out viscoelastic_cost_malloc_keeps): the series' temporaries are otherwise mapped and
faulted in afresh on every call.
"""

from __future__ import annotations

import argparse
import os
import sys
import time

if __name__ == "__main__":  # thread counts must be set before NumPy is imported
    for _var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
        os.environ.setdefault(_var, "1")

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from _perf_common import MATERIAL, deformed_state, load_average, machine, table, write_result  # noqa: E402

from axiform import Model, rectangle  # noqa: E402
from axiform.fem.mesh import edges_on_nodes  # noqa: E402
from axiform.materials.base import add_volumetric  # noqa: E402
from axiform.materials.kinematics import from_rows, to_rows  # noqa: E402
from axiform.materials.prony import Prony, prony_step, second_piola_rows, viscous_rows  # noqa: E402
from axiform.materials.temperature import WLF  # noqa: E402
from axiform.materials.viscoelastic import Viscoelastic  # noqa: E402

SERIES = {"1 term": Prony((0.5,), (0.1,)), "3 terms": Prony((0.3, 0.2, 0.1), (0.01, 0.1, 1.0))}
# the 3 terms again with their relaxation times shifted per point: 150 on the inner face to
# 120 on the outer (r = 1 to 2), WLF about 150 (one set of the step's factors per point)
SHIFTED = "3 terms, WLF"
WLF_SHIFT = WLF(2.0, 100.0, 150.0)
LAWS = ["elastic", *SERIES, SHIFTED]
CASES = [("q4", "displacement"), ("q4", "mixed"), ("q8", "mixed"), ("sfr", "mixed")]
T_COMMITTED, T_TRIAL = 0.05, 0.1  # the committed state's time and the evaluation's


def ring(element: str, formulation: str, material, n: int) -> Model:
    """The benchmark ring (_perf_common.build_model) with any law and formulation: roller at
    z = 0, the top face moved down, a follower pressure on the lower half of the inner face."""
    mesh = rectangle((1.0, 2.0), (0.0, 1.0), (n, n), element)
    model = Model(mesh, material, formulation=formulation)
    model.fix(mesh.node_sets["bottom"], ["uz"])
    model.prescribe(mesh.node_sets["top"], ["uz"], -0.05)
    left = mesh.node_sets["left"]
    model.pressure(edges_on_nodes(mesh, left[mesh.points[left, 1] <= 0.5 + 1e-12]), 5.0)
    return model


def committed_state(model: Model):
    """A committed state with history: the initial one carried to T_COMMITTED at half the
    deformation (an elastic law: its state, with no history)."""
    start = model.initial_state()
    if not model.solid_state(start):
        return start
    u_half, _ = deformed_state(model, seed=1, lam=0.25)
    state = model.evaluate(u_half, T_COMMITTED, start, tangent=False).trial
    assert np.abs(model.solid_state(state)["h"]).max() > 0
    return state


def time_evaluations(n: int, repeats: int) -> dict:
    """{(element, formulation, law, tangent): [CPU s per call, ...]} over interleaved repeats."""
    models = {}
    for element, formulation in CASES:
        laws = {"elastic": MATERIAL} | {name: Viscoelastic(MATERIAL, p) for name, p in SERIES.items()}
        laws[SHIFTED] = laws["3 terms"]
        for name, law in laws.items():
            built = ring(element, formulation, law, n)
            if name == SHIFTED:
                built.heat(150.0 - 30.0 * (built.mesh.points[:, 0] - 1.0), WLF_SHIFT)
            model = built.finalize()
            u_f, _ = deformed_state(model, lam=0.5)
            models[element, formulation, name] = (model, u_f, committed_state(model))
    times: dict = {}
    for _ in range(repeats):
        for (element, formulation, name), (model, u_f, state) in models.items():
            for tangent in (True, False):
                model.evaluate(u_f, T_TRIAL, state, tangent)  # warm: buffers, caches
                t0 = time.process_time()
                model.evaluate(u_f, T_TRIAL, state, tangent)
                times.setdefault((element, formulation, name, tangent), []).append(time.process_time() - t0)
    n_elements = {key[:2]: model.mesh.n_cells for key, (model, _, _) in models.items()}
    return times, n_elements


def evaluation_table(times: dict, n_elements: dict) -> str:
    rows = []
    for element, formulation in CASES:
        row = [f"{element} {formulation} ({n_elements[element, formulation]} el.)"]
        for tangent in (True, False):
            base = np.median(times[element, formulation, "elastic", tangent])
            row.append(f"{1e3 * base:.1f}")
            for name in LAWS[1:]:
                t = np.median(times[element, formulation, name, tangent])
                row.append(f"{1e3 * t:.1f} ({t / base:.2f}x)")
        rows.append(row)
    header = ["element"] + [f"{what} {law} ms" for what in ("R + K:", "R:") for law in LAWS]
    return table(header, rows)


def best(f, repeats: int) -> float:
    """Minimum over repeats of the CPU time of f() (s)."""
    out = np.inf
    for _ in range(repeats):
        t0 = time.process_time()
        f()
        out = min(out, time.process_time() - t0)
    return out


def pieces(n_points: int, repeats: int) -> list[list[str]]:
    """The memory branch's pieces on n_points quadrature points (one chunk of the displacement
    assembly: 2048 Q4 elements x 4 points), 3 terms, as the displacement assembly calls them
    (fem.assembly): rows (piece, us, x the elastic law)."""
    rng = np.random.default_rng(0)
    x = np.array([1.0, 0.0, 0.0, 1.0, 1.0]) + 0.05 * rng.uniform(-1, 1, (n_points // 4, 4, 5))
    law = MATERIAL
    history = {"h": rng.standard_normal(x.shape[:2] + (3, 4)), "S": rng.standard_normal(x.shape[:2] + (4,))}
    factors = SERIES["3 terms"].factors(T_TRIAL - T_COMMITTED)
    xt, shape = to_rows(x)
    P, A = law.stress_rows(xt, 0.0, True)
    n, m = xt.shape[1], len(factors[0])
    h_rows = history["h"].reshape(n, m, 4).transpose(1, 2, 0)  # (m, 4, n), as prony_step views it
    S_rows = history["S"].reshape(n, 4).T
    column = tuple(f[:, None] for f in factors)
    e, a, b = column
    S = second_piola_rows(xt, P)
    trial, _ = viscous_rows(xt, P.copy(), A.copy(), h_rows, S_rows, column)
    branch = {  # the displacement assembly's memory branch, call by call
        "`stress_rows(xt, 0.0, True)` (the law's isochoric part)": lambda: law.stress_rows(xt, 0.0, True),
        "`prony_step` (`viscous_rows`, the history to rows and back)": lambda: prony_step(
            xt, P.copy(), A.copy(), history, factors
        ),
        "`add_volumetric` (kappa's part, a second pass over A)": lambda: add_volumetric(
            xt, law.kappa, P.copy(), A.copy()
        ),
        "`from_rows` of P, A": lambda: from_rows(P, A, shape),
    }
    inside = {  # what prony_step spends it on (the copies of P and A it is handed, apart)
        "· copies of P, A (this benchmark's, to keep them unchanged)": lambda: (P.copy(), A.copy()),
        "· `second_piola_rows` (S_iso)": lambda: second_piola_rows(xt, P),
        "· H0 = sum(e h) + sum(a) S_n, h a (m, 4, n) view of (n, m, 4)": lambda: (
            (e[:, None] * h_rows).sum(0) + a.sum(0) * S_rows
        ),
        "· trial h_i = e h + a S_n + b S, the same view": lambda: (
            e[:, None] * h_rows + a[:, None] * S_rows + b[:, None] * S
        ),
        "· the same two on a contiguous (m, 4, n) h": lambda: (
            (e[:, None] * h_contiguous).sum(0) + a.sum(0) * S_rows,
            e[:, None] * h_contiguous + a[:, None] * S_rows + b[:, None] * S,
        ),
        "· the trial brought back to (e, q, m, 4)": lambda: np.ascontiguousarray(
            trial.transpose(2, 0, 1).reshape(history["h"].shape)
        ),
        "· `viscous_rows` as a whole": lambda: viscous_rows(xt, P.copy(), A.copy(), h_rows, S_rows, column),
    }
    h_contiguous = np.ascontiguousarray(h_rows)
    elastic = best(lambda: law.stress_tangent(x), repeats)
    times = {name: best(f, repeats) for name, f in (branch | inside).items()}
    copies = times["· copies of P, A (this benchmark's, to keep them unchanged)"]
    for name in (
        "`prony_step` (`viscous_rows`, the history to rows and back)",
        "`add_volumetric` (kappa's part, a second pass over A)",
        "· `viscous_rows` as a whole",
    ):
        times[name] -= copies
    total = sum(times[name] for name in branch)
    rows = [
        ["the elastic law: `stress_tangent` (`stress_rows` with kappa, `from_rows`)", f"{1e6 * elastic:.0f}", "1.00"]
    ]
    rows += [[name, f"{1e6 * t:.0f}", f"{t / elastic:.2f}"] for name, t in times.items()]
    rows.insert(
        len(branch) + 1,
        [
            "**the displacement form's memory branch** (the four above)",
            f"**{1e6 * total:.0f}**",
            f"**{total / elastic:.2f}**",
        ],
    )
    return rows


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="smoke run: a 20 x 20 mesh, few repeats")
    parser.add_argument("--out", help="the results file's name (default viscoelastic_cost[_quick])")
    args = parser.parse_args()
    n, repeats = (20, 3) if args.quick else (60, 15)
    print(f"evaluate: {n} x {n} mesh, {repeats} interleaved repeats", file=sys.stderr)
    times, n_elements = time_evaluations(n, repeats)
    part1 = evaluation_table(times, n_elements)
    n_points = 8192
    part2 = table(["piece (3 terms, 8192 points)", "CPU us", "x the elastic law's P, A"], pieces(n_points, repeats))
    series = "; ".join(f"{k}: g = {p.g}, tau = {p.tau}" for k, p in SERIES.items()) + (
        f"; {SHIFTED}: the 3 terms with a temperature from 150 (inner face) to 120 (outer), WLF C1 = "
        f"{WLF_SHIFT.C1:g}, C2 = {WLF_SHIFT.C2:g} about {WLF_SHIFT.reference:g}"
    )
    text = (
        f"# The cost of a Prony series in a Newton iteration\n\n"
        f"`python benchmarks/viscoelastic_cost.py{' --quick' if args.quick else ''}`; {machine()}; load "
        f"average {load_average()}; GLIBC_TUNABLES {os.environ.get('GLIBC_TUNABLES', 'unset')}.\n\n"
        f"## 1. `Model.evaluate` with and without the series\n\nThe ring of `_perf_common.py` on a {n} x {n} "
        f"mesh, Mooney-Rivlin (80, 20, 1e4), the state a homogeneous stretch plus 1 % noise; the series "
        f"({series}) from a committed state with history at t = {T_COMMITTED} to t = {T_TRIAL}.  Median of "
        f"{repeats} interleaved repeats of the process CPU time, one thread; in brackets the ratio to the "
        f"elastic law in the same run.  R + K: `tangent=True` (a Newton iteration's evaluation); R: the "
        f"residual alone.\n\n{part1}\n"
        f"## 2. The pieces of the memory branch\n\n{n_points} points (F = I + 5 % random), the displacement "
        f"assembly's calls on component rows, 3 terms; minimum of {repeats} repeats of the CPU time (less the "
        f"copies of P and A that keep them unchanged from call to call); the ratio to the elastic law's one "
        f"call `stress_tangent` on the same points.\n\n{part2}"
    )
    print(text)
    path = write_result(args.out or ("viscoelastic_cost_quick" if args.quick else "viscoelastic_cost"), text)
    print(f"wrote {path}", file=sys.stderr)


if __name__ == "__main__":
    main()
