#!/usr/bin/env python
"""Time of one Newton iteration against the number of dofs, for several sparse solvers.

One iteration of the displacement-controlled Newton (solve.newton.newton_displacement) is
    ev = model.evaluate(u_f, lam);  solve = factorize(ev.K);  solve([-r, -dR/dlambda])
i.e. the residual and tangent, one LU factorization and two right-hand sides.  The model is
the benchmark ring of benchmarks/_perf_common.py on square meshes (Q4 up to 1e6 dofs, SFR up
to 1e5): a follower pressure on part of the inner face (K_ff non-symmetric, its pattern
symmetric) and a prescribed top displacement, in a deformed state.

Solvers, side by side on the same matrices (what is not installed is skipped):
  src                    axiform.solve.linsolve.factorize as it is in src/ now: PARDISO (type 11)
                         where pypardiso is installed, otherwise SuperLU with MMD_ATA
  superlu-<PERMC>        scipy.sparse.linalg.splu(K, permc_spec=PERMC), SciPy's defaults
                         otherwise (partial pivoting, diag_pivot_thresh=1);
                         superlu-MMD_AT_PLUS_A is what linsolve.py did before this benchmark
  superlu-mmd-sym        splu(K, "MMD_AT_PLUS_A", diag_pivot_thresh=0.001,
                         options={"SymmetricMode": True}): the symmetric-pattern mode that
                         SuperLU's guide recommends for such matrices (prefers the diagonal)
  umfpack                scikits.umfpack.splu (scikit-umfpack; UMFPACK, as spsolve with
                         use_umfpack=True, but factorized once for both right-hand sides)
  pardiso                pypardiso (MKL PARDISO), matrix type 11 (real non-symmetric), and
  pardiso-ss             matrix type 1 (real, structurally symmetric)
A solver is dropped for the larger meshes once its factorization, extrapolated as
n^1.5, would take more than --budget seconds.  Two more tables: the factorization of six
tangents of one mesh (SuperLU's fill with partial pivoting depends on the values), and what
each solver does with a singular tangent.

    python benchmarks/newton_iteration.py            # about 6 minutes
    python benchmarks/newton_iteration.py --quick    # smoke run, seconds

Times: minimum over --repeat interleaved repeats.  With --threads 1 (default) every solver
runs on one core and the table's main figures are CPU times of the process, which a busy,
shared machine disturbs much less than wall times (also given); with --threads 2 compare the
wall times (pardiso and UMFPACK's BLAS then use both cores, SuperLU still one).  Written to
benchmarks/results/newton_iteration.md.
"""

from __future__ import annotations

import argparse
import os
import sys
import time

if __name__ == "__main__":  # thread counts must be set before NumPy / MKL are loaded
    _threads = "1"
    for _i, _a in enumerate(sys.argv):
        if _a == "--threads" and _i + 1 < len(sys.argv):
            _threads = sys.argv[_i + 1]
        elif _a.startswith("--threads="):
            _threads = _a.split("=", 1)[1]
    for _var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
        os.environ[_var] = _threads

import numpy as np
import scipy.sparse.linalg as sla

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from _perf_common import (
    Timing,
    build_model,
    deformed_state,
    divisions_for_dofs,  # noqa: E402
    load_average,
    machine,
    table,
    write_result,
)

from axiform.solve import linsolve  # noqa: E402

# --------------------------------------------------------------------------------------------
# Solvers: K (CSR) -> (solve(B) for B (n, k), nnz of the factors or None)
# --------------------------------------------------------------------------------------------


def _superlu(permc: str, **kw):
    def factor(K):
        lu = sla.splu(K.tocsc(), permc_spec=permc, **kw)
        return lu.solve, lu.L.nnz + lu.U.nnz

    return factor


# the analysis of the pattern kept from one factorization to the next, as a run keeps it (a tree
# from before LinearSolver: its module-level factorize keeps it)
_SRC = linsolve.LinearSolver().factorize if hasattr(linsolve, "LinearSolver") else linsolve.factorize


def _src(K):
    return _SRC(K), None


def src_solver() -> str:
    """What axiform.solve.linsolve.factorize uses on this machine."""
    if linsolve._mkl() is None:
        return "SciPy SuperLU, permc_spec MMD_ATA (MKL is not installed)"
    return (
        "MKL PARDISO, matrix type 11, through ctypes (analysis kept per pattern; minimum degree "
        f"up to {linsolve.MINIMUM_DEGREE_MAX} unknowns, METIS above)"
    )


def _umfpack():
    try:
        import scikits.umfpack as um
    except ImportError:
        return None

    def factor(K):
        lu = um.splu(K.tocsc())
        return lu.solve, None

    return factor


def _pardiso(mtype: int):
    try:
        import pypardiso
    except ImportError:
        return None
    # one solver object, made once: its constructor looks for libmkl_rt (ctypes.util.find_library
    # and a glob), which costs about 0.1 s, more than a whole small factorization
    s = pypardiso.PyPardisoSolver(mtype=mtype)

    def factor(K):
        K = K.tocsr()
        K.sort_indices()
        s.iparm[17] = -1  # ask for the number of non-zeros in the factors
        s.factorize(K)  # analysis + numerical factorization (phase 12)
        nnz = int(s.iparm[17])

        def solve(B):
            return s.solve(K, B)  # phase 33: forward and back substitution

        solve.release = lambda: s.free_memory(everything=True)
        return solve, nnz

    return factor


def solvers() -> dict:
    out = {
        "src": _src,
        "superlu-COLAMD": _superlu("COLAMD"),
        "superlu-MMD_AT_PLUS_A": _superlu("MMD_AT_PLUS_A"),
        "superlu-MMD_ATA": _superlu("MMD_ATA"),
        "superlu-NATURAL": _superlu("NATURAL"),
        "superlu-mmd-sym": _superlu("MMD_AT_PLUS_A", diag_pivot_thresh=0.001, options={"SymmetricMode": True}),
        "umfpack": _umfpack(),
        "pardiso": _pardiso(11),
        "pardiso-ss": _pardiso(1),
    }
    return {k: v for k, v in out.items() if v is not None}


def timed(fn):
    w, c = time.perf_counter(), time.process_time()
    r = fn()
    return r, Timing(time.perf_counter() - w, time.process_time() - c)


def tmin(a: Timing | None, b: Timing) -> Timing:
    return b if a is None else Timing(min(a.wall, b.wall), min(a.cpu, b.cpu))


# --------------------------------------------------------------------------------------------


def run(
    element: str, dof_targets: list[int], names: list[str], repeat: int, budget: float, log
) -> tuple[list[dict], dict]:
    available = solvers()
    names = [n for n in names if n in available]
    last: dict[str, tuple[int, float]] = {}  # solver -> (n, factorization time) at the last size
    dropped: dict[str, str] = {}
    rows = []
    for target in dof_targets:
        t0 = time.perf_counter()
        model = build_model(element, divisions_for_dofs(element, target))
        t_build = time.perf_counter() - t0
        u_f, lam = deformed_state(model)
        n = model.n_free
        ev = model.evaluate(u_f, lam)
        K = ev.K.tocsr()  # SciPy's, for the solvers compared
        B = np.column_stack([-ev.r, -ev.dr_dlam])
        reps = repeat if n <= 150_000 else 1
        t_eval = None
        for _ in range(max(reps, 2)):
            _, t = timed(lambda m=model, u=u_f, t=lam: m.evaluate(u, t))
            t_eval = tmin(t_eval, t)
        del ev
        asym = abs(K - K.T).max() / abs(K).max()
        log(
            f"{element}: {n:,} free dofs, nnz(K) {K.nnz:,}, |K-K^T|/|K| {asym:.1e}, "
            f"evaluate {t_eval.cpu:.2f} s CPU, built in {t_build:.1f} s"
        )
        todo = []
        for name in names:
            if name in dropped:
                continue
            if name in last:
                n0, t0_ = last[name]
                guess = t0_ * (n / n0) ** 1.5
                if guess > budget:
                    dropped[name] = f"skipped from {n:,} dofs on (factorization ~{guess:.0f} s predicted)"
                    log(f"  {name}: {dropped[name]}")
                    continue
            todo.append(name)
        res: dict[str, dict] = {name: {} for name in todo}
        for rep in range(reps):
            order = todo[rep % len(todo) :] + todo[: rep % len(todo)] if todo else []
            for name in order:
                r = res[name]
                if r.get("error"):
                    continue
                try:
                    (solve, fill), tf = timed(lambda f=available[name], K=K: f(K))
                    X, ts = timed(lambda s=solve, B=B: s(B))
                except Exception as exc:  # noqa: BLE001  (a solver that fails is reported)
                    r["error"] = f"{type(exc).__name__}: {exc}"[:80]
                    log(f"  {name}: failed: {r['error']}")
                    continue
                r["fact"] = tmin(r.get("fact"), tf)
                r["solve"] = tmin(r.get("solve"), ts)
                r["fill"] = fill
                r["res"] = float(np.linalg.norm(K @ X - B) / np.linalg.norm(B))
                if hasattr(solve, "release"):
                    solve.release()
                del solve, X
                log(
                    f"  {name:24s} factorize {tf.cpu:7.3f} s CPU ({tf.wall:7.3f} wall), "
                    f"solve {ts.cpu:6.3f} s, fill {fill or '-'}, residual {r['res']:.1e}"
                )
        for name, r in res.items():
            if "fact" in r:
                last[name] = (n, r["fact"].cpu)
        rows.append(dict(n=n, nnz=K.nnz, eval=t_eval, res=res, asym=asym))
    return rows, dropped


def sensitivity(element: str, target: int, names: list[str], log) -> str:
    """Fill and factorization time of each solver on several tangents of one mesh: the
    pressed patch (half or whole inner face) and the random part of the state change.  With
    partial pivoting (SciPy's default diag_pivot_thresh=1) SuperLU's pivots, hence its fill,
    depend on the values, not only on the ordering."""
    available = solvers()
    names = [n for n in names if n in available]
    rows = []
    for pressed in (0.5, 1.0):
        model = build_model(element, divisions_for_dofs(element, target), pressed=pressed)
        for seed, noise in ((0, 0.01), (1, 0.01), (2, 0.03)):
            u_f, lam = deformed_state(model, seed=seed, noise=noise)
            K = model.evaluate(u_f, lam).K.tocsr()
            cells = [
                f"{'half' if pressed < 1 else 'whole'} face, seed {seed}, noise {noise:g} h",
                f"{abs(K - K.T).max() / abs(K).max():.0e}",
            ]
            for name in names:
                (solve, fill), t = timed(lambda f=available[name], K=K: f(K))
                if hasattr(solve, "release"):
                    solve.release()
                cells.append(f"{t.cpu:.2f} / {fill / 1e6:.1f}M" if fill else f"{t.cpu:.2f}")
            log("  " + " | ".join(cells))
            rows.append(cells)
    n = model.n_free
    return (
        f"## Sensitivity to the matrix values ({element}, {n:,} free dofs)\n\n"
        "Factorization CPU s / fill (non-zeros of L + U, millions) on six tangents of the "
        "same mesh. asym = |K - Kᵀ|max / |K|max (whole face: the load stiffness cancels, "
        "K_ff is symmetric to round-off).\n\n" + table(["tangent", "asym"] + names, rows)
    )


def singular(element: str, names: list[str], log) -> str:
    """What each solver does with a singular K_ff: the ring without any axial support (a rigid
    axial translation), which linsolve.factorize must report as SingularTangentError."""
    available = solvers()
    names = [n for n in names if n in available]
    from _perf_common import MATERIAL

    from axiform import Model, rectangle

    mesh = rectangle((1.0, 2.0), (0.0, 1.0), (30, 30), element)
    model = Model(mesh, MATERIAL, formulation="displacement")
    model.pressure(mesh.edge_sets["left"], 5.0)
    model = model.finalize()
    u_f, lam = deformed_state(model)
    ev = model.evaluate(u_f, lam)
    K, b = ev.K.tocsr(), -ev.r
    rows = []
    for name in names:
        try:
            solve, _ = available[name](K)
            x = solve(b)
            if not np.all(np.isfinite(x)):
                what = "returns inf / nan"
            else:
                what = (
                    f"returns a finite x: |x|max {np.abs(x).max():.0e}, residual "
                    f"{np.linalg.norm(K @ x - b) / np.linalg.norm(b):.0e}"
                )
            if hasattr(solve, "release"):
                solve.release()
        except Exception as exc:  # noqa: BLE001
            what = f"raises {type(exc).__name__}: {str(exc)[:50]}"
        log(f"  singular K: {name}: {what}")
        rows.append([name, what])
    return f"## A singular tangent ({element}, {K.shape[0]:,} dofs, no axial support)\n\n" + table(
        ["solver", "factorize + solve"], rows
    )


def report(element, rows, dropped, key) -> str:
    """The tables of one element: iteration time, factorize + solve with ratios, details."""
    names = []
    for r in rows:
        for name in r["res"]:
            if name not in names:
                names.append(name)
    base = "superlu-MMD_AT_PLUS_A" if "superlu-MMD_AT_PLUS_A" in names else names[0]
    out = [f"## {element.upper()}: time of one Newton iteration (s)", ""]
    hdr = ["free dofs", "nnz(K)", "evaluate"] + names
    trows = []
    for r in rows:
        cells = [f"{r['n']:,}", f"{r['nnz']:,}", f"{getattr(r['eval'], key):.3f}"]
        for name in names:
            x = r["res"].get(name)
            if not x:
                cells.append("–")
            elif "fact" not in x:
                cells.append("failed")
            else:
                it = getattr(r["eval"], key) + getattr(x["fact"], key) + getattr(x["solve"], key)
                cells.append(f"{it:.3f}")
        trows.append(cells)
    out.append(table(hdr, trows))
    what = " (the solver of linsolve.py before this benchmark)" if base == "superlu-MMD_AT_PLUS_A" else ""
    out += [
        f"## {element.upper()}: factorize + solve (s), and in brackets the ratio to {base}{what}; < 1: faster than it",
        "",
    ]
    trows = []
    for r in rows:
        b = r["res"].get(base)
        bt = (getattr(b["fact"], key) + getattr(b["solve"], key)) if b and "fact" in b else None
        cells = [f"{r['n']:,}"]
        for name in names:
            x = r["res"].get(name)
            if not x or "fact" not in x:
                cells.append("–")
                continue
            t = getattr(x["fact"], key) + getattr(x["solve"], key)
            cells.append(f"{t:.3f}" + (f" ({t / bt:.2f})" if bt else ""))
        trows.append(cells)
    out.append(table(["free dofs"] + names, trows))
    out += [f"## {element.upper()}: details (factorize and solve s, factorize wall s, fill, residual)", ""]
    trows = []
    for r in rows:
        for name in names:
            x = r["res"].get(name)
            if not x or "fact" not in x:
                continue
            trows.append(
                [
                    f"{r['n']:,}",
                    name,
                    f"{getattr(x['fact'], key):.3f}",
                    f"{getattr(x['solve'], key):.3f}",
                    f"{x['fact'].wall:.3f}",
                    f"{x['fill']:,}" if x.get("fill") else "–",
                    f"{x['res']:.1e}",
                ]
            )
    out.append(table(["free dofs", "solver", "factorize", "solve", "factorize wall", "fill", "residual"], trows))
    if dropped:
        out += ["Dropped: " + "; ".join(f"{k} {v}" for k, v in dropped.items()) + ".", ""]
    return "\n".join(out)


DEFAULT_DOFS = {"q4": [1e4, 3e4, 1e5, 3e5, 1e6], "sfr": [1e4, 3e4, 1e5], "q8": [1e4, 3e4, 1e5, 3e5]}
QUICK_DOFS = {"q4": [3e3, 1e4], "sfr": [3e3], "q8": [3e3]}


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--quick", action="store_true", help="small meshes only (smoke run)")
    ap.add_argument("--elements", nargs="+", default=["q4", "sfr"], choices=["q4", "q8", "sfr"])
    ap.add_argument("--dofs", nargs="+", type=float, help="target numbers of dofs (all elements)")
    ap.add_argument("--solvers", nargs="+", help="subset of the solver names")
    ap.add_argument("--threads", type=int, default=1, help="BLAS / MKL / OpenMP threads")
    ap.add_argument("--repeat", type=int, default=2, help="interleaved repeats per size")
    ap.add_argument(
        "--budget", type=float, default=40.0, help="drop a solver whose factorization would take longer (s)"
    )
    ap.add_argument(
        "--sensitivity-dofs", type=int, default=30000, help="mesh size of the value-sensitivity table (0: none)"
    )
    ap.add_argument("--out", default=None, help="results name (default newton_iteration)")
    args = ap.parse_args(argv)
    names = args.solvers or list(solvers())
    log = lambda s: print(s, flush=True)  # noqa: E731
    key = "cpu" if args.threads == 1 else "wall"
    t_start = time.perf_counter()
    log(f"Machine: {machine()}; threads {args.threads}; load average {load_average()}")
    sections = []
    for element in args.elements:
        dofs = [int(d) for d in (args.dofs or (QUICK_DOFS if args.quick else DEFAULT_DOFS)[element])]
        rows, dropped = run(element, dofs, names, args.repeat, args.budget, log)
        sections.append(report(element, rows, dropped, key))
    if not args.quick and args.sensitivity_dofs:
        log("values sensitivity")
        sections.append(sensitivity(args.elements[0], args.sensitivity_dofs, names, log))
    sections.append(singular(args.elements[0], names, log))
    what = "CPU time of the process (one thread: about the wall time of an idle core)" if key == "cpu" else "wall clock"
    text = "\n".join(
        [
            "# Newton iteration: evaluate + factorize + solve (2 right-hand sides)",
            "",
            f"Machine: {machine()}; square meshes; solver threads: {args.threads}; load average "
            f"at the end: {load_average()}.",
            "",
            f"Times in s, {what}, minimum over {args.repeat} interleaved repeats (1 above 150,000 "
            "dofs). Iteration = evaluate + factorize + solve. fill = non-zeros of L + U. residual "
            "= ||K X - B|| / ||B||. src = axiform.solve.linsolve.factorize as it is now: "
            f"{src_solver()}; evaluate = `model.evaluate` as it is now.",
            "",
        ]
        + sections
        + [f"Total run time {time.perf_counter() - t_start:.0f} s.", ""]
    )
    print()
    print(text)
    name = args.out or ("newton_iteration" + ("_quick" if args.quick else ""))
    print(f"written to {write_result(name, text)}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
