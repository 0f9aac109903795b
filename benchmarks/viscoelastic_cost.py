#!/usr/bin/env python
"""The cost of a Newton iteration's evaluation with and without a Prony series (DESIGN § 11.2).

1. `Model.evaluate(u, t, state, tangent=True)` (residual and tangent, the part of a Newton
   iteration that the series changes) on the ring of `_perf_common.py` (r 1..2, z 0..1, a
   60 x 60 mesh: 3600 elements) for Q4 displacement, Q4 mixed, Q8 mixed and SFR mixed, with
   the elastic Mooney-Rivlin law of the other benchmarks and the same law with a 1- and a
   3-term Prony series, side by side in one run: the median of interleaved repeats of the
   process CPU time (single-threaded) and the ratio to the elastic law.  The viscoelastic
   evaluation starts from a committed state with history (h_i != 0), a step dt later.  The
   same for `tangent=False` (a residual alone, as a line search or a sensitivity's shadow).
2. Where the time of the series goes: the pieces of the memory branch of the assemblies
   (fem.assembly, fem.mixed) on one chunk of elements, timed apart (same points, same
   calls as the assembly makes).

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
from axiform.materials.kinematics import from_rows, to_rows  # noqa: E402
from axiform.materials.viscoelastic import (Memory, Prony, Viscoelastic, d_f_times, f_times,  # noqa: E402
                                            second_piola)

SERIES = {"1 term": Prony((0.5,), (0.1,)), "3 terms": Prony((0.3, 0.2, 0.1), (0.01, 0.1, 1.0))}
CASES = [("q4", "displacement"), ("q4", "mixed"), ("q8", "mixed"), ("sfr", "mixed")]
T_COMMITTED, T_TRIAL = 0.05, 0.1  # the committed state's time and the evaluation's


def ring(element: str, formulation: str, material, n: int) -> Model:
    """The benchmark ring (_perf_common.build_model) with any law and formulation: roller at
    z = 0, the top face moved down, a follower pressure on the lower half of the inner face."""
    mesh = rectangle((1.0, 2.0), (0.0, 1.0), (n, n), element)
    model = Model(mesh, material, formulation=formulation)
    model.fix(mesh.node_sets["bottom"], ["uz"])
    model.prescribe(mesh.node_sets["top"], ["uz"], -0.05)
    model.bench_top_displacement = -0.05
    left = mesh.node_sets["left"]
    model.pressure(edges_on_nodes(mesh, left[mesh.points[left, 1] <= 0.5 + 1e-12]), 5.0)
    return model.finalize()


def committed_state(model: Model):
    """A committed state with history: the initial one carried to T_COMMITTED at half the
    deformation (an elastic law: its state, with no history)."""
    start = model.initial_state()
    if not start.solid:
        return start
    u_half, _ = deformed_state(model, seed=1, lam=0.25)
    state = model.evaluate(u_half, T_COMMITTED, start, tangent=False).trial
    assert np.abs(state.solid["h"]).max() > 0
    return state


def time_evaluations(n: int, repeats: int) -> dict:
    """{(element, formulation, law, tangent): [CPU s per call, ...]} over interleaved repeats."""
    models = {}
    for element, formulation in CASES:
        laws = {"elastic": MATERIAL} | {name: Viscoelastic(MATERIAL, p) for name, p in SERIES.items()}
        for name, law in laws.items():
            model = ring(element, formulation, law, n)
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
            for name in SERIES:
                t = np.median(times[element, formulation, name, tangent])
                row.append(f"{1e3 * t:.1f} ({t / base:.2f}x)")
        rows.append(row)
    header = ["element"] + [f"{what} {law} ms" for what in ("R + K:", "R:") for law in ["elastic", *SERIES]]
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
    assembly: 2048 Q4 elements x 4 points), 3 terms: rows (piece, us, x the elastic law)."""
    rng = np.random.default_rng(0)
    x = np.array([1.0, 0.0, 0.0, 1.0, 1.0]) + 0.05 * rng.uniform(-1, 1, (n_points // 4, 4, 5))
    law = MATERIAL
    history = {"h": rng.standard_normal(x.shape[:2] + (3, 4)), "S": rng.standard_normal(x.shape[:2] + (4,))}
    factors = SERIES["3 terms"].factors(T_TRIAL - T_COMMITTED)
    e, a, b = factors
    P, A = law.iso_stress_tangent(x)
    P_vol, A_vol = law.volumetric_stress_tangent(x)
    S = second_piola(x, P)
    H0 = np.einsum("m,...mk->...k", e, history["h"]) + a.sum() * history["S"]
    dP, dA = Memory(history, factors).add(slice(None), x, P, A)
    xt, shape = to_rows(x)
    P_rows, A_rows = law.stress_rows(xt, 0.0, True)
    branch = {  # the displacement assembly's memory branch, call by call
        "`iso_stress_tangent`": lambda: law.iso_stress_tangent(x),
        "`volumetric_stress_tangent`": lambda: law.volumetric_stress_tangent(x),
        "`Memory.add` (`viscous_part`, its slices, the trial written)": lambda: Memory(history, factors).add(
            slice(None), x, P, A),
        "P + P_vol + dP, A + A_vol + dA": lambda: (P + P_vol + dP, A + A_vol + dA),
    }
    inside = {  # what Memory.add and the calls above spend it on
        "· the law's rows to points (`from_rows` of P, A), once per call": lambda: from_rows(P_rows, A_rows, shape),
        "· `second_piola` (S_iso)": lambda: second_piola(x, P),
        "· H0 = einsum(e, h) + sum(a) S_n": lambda: np.einsum("m,...mk->...k", e, history["h"]) + a.sum() * history["S"],
        "· `f_times(x, H0)` + c P_iso, negated": lambda: -(f_times(x, H0) + b.sum() * P),
        "· `d_f_times(H0)` + c A_iso, negated": lambda: -(d_f_times(H0) + b.sum() * A),
        "· trial h_i = e h + a S_n + b S on (..., m, 4)": lambda: (e[:, None] * history["h"]
                                                               + a[:, None] * history["S"][..., None, :]
                                                               + b[:, None] * S[..., None, :]),
        "the mixed branch: x, P_iso, A_iso rows to points and dA back": lambda: (
            xt.T.reshape(shape + (5,)), P_rows.T.reshape(shape + (5,)),
            A_rows.transpose(2, 0, 1).reshape(shape + (5, 5)), A_rows + dA.reshape(-1, 5, 5).transpose(1, 2, 0)),
    }
    elastic = best(lambda: law.stress_tangent(x), repeats)
    times = {name: best(f, repeats) for name, f in (branch | inside).items()}
    total = sum(times[name] for name in branch)
    rows = [["the elastic law: `stress_tangent` (P, A of the whole W)", f"{1e6 * elastic:.0f}", "1.00"]]
    rows += [[name, f"{1e6 * t:.0f}", f"{t / elastic:.2f}"] for name, t in times.items()]
    rows.insert(len(branch) + 1, ["**the displacement form's memory branch** (the four above)",
                                  f"**{1e6 * total:.0f}**", f"**{total / elastic:.2f}**"])
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
    series = "; ".join(f"{k}: g = {p.g}, tau = {p.tau}" for k, p in SERIES.items())
    text = (f"# The cost of a Prony series in a Newton iteration\n\n"
            f"`python benchmarks/viscoelastic_cost.py{' --quick' if args.quick else ''}`; {machine()}; load "
            f"average {load_average()}; GLIBC_TUNABLES {os.environ.get('GLIBC_TUNABLES', 'unset')}.\n\n"
            f"## 1. `Model.evaluate` with and without the series\n\nThe ring of `_perf_common.py` on a {n} x {n} "
            f"mesh, Mooney-Rivlin (80, 20, 1e4), the state a homogeneous stretch plus 1 % noise; the series "
            f"({series}) from a committed state with history at t = {T_COMMITTED} to t = {T_TRIAL}.  Median of "
            f"{repeats} interleaved repeats of the process CPU time, one thread; in brackets the ratio to the "
            f"elastic law in the same run.  R + K: `tangent=True` (a Newton iteration's evaluation); R: the "
            f"residual alone.\n\n{part1}\n"
            f"## 2. The pieces of the memory branch\n\n{n_points} points (F = I + 5 % random), the displacement "
            f"assembly's calls on (..., 5) arrays, 3 terms; minimum of {repeats} repeats of the CPU time; the "
            f"ratio to the elastic law's one call `stress_tangent` on the same points.\n\n{part2}")
    print(text)
    path = write_result(args.out or ("viscoelastic_cost_quick" if args.quick else "viscoelastic_cost"), text)
    print(f"wrote {path}", file=sys.stderr)


if __name__ == "__main__":
    main()
