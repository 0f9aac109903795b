#!/usr/bin/env python
"""Residual + tangent assembly throughput (Gauss points per second) of Model.evaluate.

For each element (q4, q8, sfr) and mesh size (1e3 .. 1e5 elements) the script builds
Model(mesh, MooneyRivlin(80, 20, 1e4)) with supports, a follower pressure and a prescribed
displacement (benchmarks/_perf_common.py), puts it in a deformed state (F != I at every Gauss
point) and measures

* the main figure: model.evaluate(u_f, lam) with the tangent (element kernel, sparse value
  refill, K_ff / K_fp extraction, external load, force gathers), in Gauss points per second;
* its pieces: the steps of SolidAssembly.evaluate timed one by one inside its own chunk loop
  (F at the Gauss points, the J > 0 check, the material P and A, f_e = G^T P dV, A G,
  G^T (A G) dV; `solid_pieces` below, checked to give exactly src's f_e and K_e), then the
  parts of Model.evaluate around it (expand, sparse refill, K_ff / K_fp blocks, force
  gathers, pressure load, round-off estimate) and the rest;
* the model construction: mesh and Model set-up, then `finalize()` and its main parts timed
  inside it (SolidAssembly: G and dV; SparsePattern; the positions of the element blocks),
  with np.unique on the same pattern keys for comparison (SparsePattern de-duplicates by one
  sort);
* for the largest mesh of each element, the choices made in src/: the chunk size of
  SolidAssembly.evaluate (256 .. 8192 elements and the whole mesh, through model.evaluate),
  and matmul / einsum / memory layout variants of each batched product, run in the same
  chunks of elements as src, and the cost of writing K_e into a new array on every call.

    python benchmarks/assembly_throughput.py            # full run, a few minutes
    python benchmarks/assembly_throughput.py --quick    # smoke run, seconds

Times are the minimum over interleaved repeats of the process CPU time (single-threaded
NumPy: on a shared machine this is steadier than the wall time, which is also recorded).  The
tables go to stdout and to benchmarks/results/assembly_throughput.md (a run with other
--sizes / --elements / --no-variants to assembly_throughput_partial.md, or --out NAME).

The evaluation allocates its arrays afresh on every call, so its time also depends on whether
glibc's malloc hands back memory it kept or maps new pages (which the kernel must fault in and
zero): on small meshes the same case can measure up to 2x apart from one process to the next
(benchmarks/README.md).  To see the time without that cost, run with
    GLIBC_TUNABLES=glibc.malloc.mmap_threshold=268435456:glibc.malloc.trim_threshold=1073741824
"""

from __future__ import annotations

import argparse
import gc
import os
import sys
import time

if __name__ == "__main__":  # thread counts must be set before NumPy is imported
    for _var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
        os.environ.setdefault(_var, "1")

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from _perf_common import (
    Timing,
    build_model,
    deformed_state,
    divisions_for_elements,  # noqa: E402
    load_average,
    machine,
    table,
    write_result,
)

from axiform.fem.assembly import SolidAssembly  # noqa: E402
from axiform.fem.constraints import SparsePattern  # noqa: E402
from axiform.materials import deformation_gradient  # noqa: E402

SOLID_PIECES = ["F", "J>0", "P,A", "AG", "GᵀAG", "GᵀP"]
MODEL_PIECES = ["expand", "refill", "blocks", "forces", "load", "noise"]
CHUNKS = [256, 512, 1024, 2048, 4096, 8192, None]  # None: the whole mesh in one chunk


# --------------------------------------------------------------------------------------------
# Pieces of the evaluation
# --------------------------------------------------------------------------------------------


def solid_pieces(solid: SolidAssembly, u: np.ndarray):
    """The steps of SolidAssembly.evaluate (with the tangent), in its chunks, with a CPU timer
    around each one: the seconds of each piece, summed over the chunks, and f_e, K_e (which
    main() compares with solid.evaluate's, so that this profile follows src)."""
    clock = time.process_time
    e, q, _, nd = solid.G.shape
    t = dict.fromkeys(SOLID_PIECES, 0.0)
    fe = np.empty((e, nd))
    Ke = np.empty((e, nd, nd))
    for start in range(0, e, solid.chunk):
        sl = slice(start, min(start + solid.chunk, e))
        m = sl.stop - sl.start
        c0 = clock()
        ue = u[solid.dofs[sl]]
        x = deformation_gradient(np.matmul(solid._G2[sl], ue[:, :, None]).reshape(m, q, 5))
        c1 = clock()
        solid.check_inverted(x, start)
        c2 = clock()
        P, A, _ = solid.law.update(x, {}, 0.0, None)
        c3 = clock()
        GdV_T = solid._GdV[sl].transpose(0, 2, 1)
        AG = np.matmul(A, solid.G[sl]).reshape(m, q * 5, nd)
        c4 = clock()
        np.matmul(GdV_T, AG, out=Ke[sl])
        c5 = clock()
        np.matmul(GdV_T, P.reshape(m, q * 5, 1), out=fe[sl, :, None])
        c6 = clock()
        for k, a, b in zip(SOLID_PIECES, (c0, c1, c2, c3, c4, c5), (c1, c2, c3, c4, c5, c6), strict=False):
            t[k] += b - a
    return t, fe, Ke


def interleaved(fns: dict, min_time: float, min_repeat: int = 5, max_repeat: int = 30) -> dict:
    """Minimum CPU and wall time of each fn over rounds in which every fn runs once (after a
    warm-up round).  Interleaving keeps the figures of one table comparable when the speed of
    the shared machine drifts (other virtual machines on the host).  A fn that returns a dict
    {piece: CPU s} (solid_pieces) gives the minimum of each piece instead of its own time."""
    for fn in fns.values():
        fn()
    best: dict = {}
    start = time.perf_counter()
    n = 0
    while n < min_repeat or (time.perf_counter() - start < min_time and n < max_repeat):
        for name, fn in fns.items():
            gc.collect()
            w, c = time.perf_counter(), time.process_time()
            r = fn()
            t = Timing(time.perf_counter() - w, time.process_time() - c)
            for k, v in r.items() if isinstance(r, dict) else [(name, t)]:
                b = best.get(k)
                best[k] = (
                    v
                    if b is None
                    else (min(b, v) if isinstance(v, float) else Timing(min(b.wall, v.wall), min(b.cpu, v.cpu)))
                )
        n += 1
    return best


def timed_once(fn):
    gc.collect()
    c = time.process_time()
    r = fn()
    return r, time.process_time() - c


def timed_finalize(model) -> tuple:
    """The System of model.finalize() and the CPU s of that call and of its main parts, timed inside it: the
    SolidAssembly and SparsePattern constructors and SparsePattern.positions (subclasses with
    timers, put in axiform.model.model's namespace for the call)."""
    import axiform.model.model as am

    t = dict(solid=0.0, pattern=0.0, pos=0.0)
    clock = time.process_time

    class Solid(SolidAssembly):
        def __init__(self, *args):
            c = clock()
            super().__init__(*args)
            t["solid"] += clock() - c

    class Pattern(SparsePattern):
        def __init__(self, *args):
            c = clock()
            super().__init__(*args)
            t["pattern"] += clock() - c

        def positions(self, dofs):
            c = clock()
            r = super().positions(dofs)
            t["pos"] += clock() - c
            return r

    am.SolidAssembly, am.SparsePattern = Solid, Pattern
    try:
        system, t["finalize"] = timed_once(model.finalize)
    finally:
        am.SolidAssembly, am.SparsePattern = SolidAssembly, SparsePattern
    return system, t


# --------------------------------------------------------------------------------------------
# Measurements
# --------------------------------------------------------------------------------------------


def measure_case(element: str, n_elements: int, min_time: float, unique_limit: int) -> dict:
    builder, t_setup = timed_once(lambda: build_model(element, divisions_for_elements(n_elements), finalize=False))
    model, build = timed_finalize(builder)
    build |= dict(setup=t_setup, unique=None)
    keys = np.concatenate(
        [model.pattern._keys(b).ravel() for b in [model.solid.dofs] + [p.dofs for p in model.pressures]]
    )
    if keys.size <= unique_limit:  # NumPy 2.4's np.unique: seconds at 1e5 elements
        uniq, build["unique"] = timed_once(lambda: np.unique(keys))  # noqa: F821 (bound before the del below)
        assert np.array_equal(uniq, model.pattern.keys)
        del uniq
    del keys

    u_f, lam = deformed_state(model)
    s = model.solid
    e, q = s.G.shape[:2]
    u = model.expand(u_f, lam)
    fe, Ke = s.evaluate(u)
    _, fe1, Ke1 = solid_pieces(s, u)
    if not (np.array_equal(fe, fe1) and np.array_equal(Ke, Ke1)):
        raise RuntimeError("solid_pieces no longer follows SolidAssembly.evaluate: update it")
    del fe1, Ke1
    pat, dm = model.pattern, model.dofmap
    solid_pos = pat.positions(s.dofs)
    data = pat.accumulate(solid_pos, Ke)
    K, _ = pat.blocks(data)
    dofs = s.dofs.ravel()

    def forces():  # the gathers of Model.evaluate: f_int, |f| and the equations' residual
        f = np.bincount(dofs, weights=fe.ravel(), minlength=model.n_full)
        np.bincount(dofs, weights=np.abs(fe).ravel(), minlength=model.n_full)
        dm.gather(f)

    def noise():  # Model.evaluate's round-off level: row sums of |K|
        np.add.reduceat(np.abs(K.data), K.indptr[:-1][np.diff(K.indptr) > 0]).max()

    best = interleaved(
        {
            "total": lambda: model.evaluate(u_f, lam),
            "solid": lambda: solid_pieces(s, u)[0],
            "expand": lambda: model.expand(u_f, lam),
            "refill": lambda: pat.accumulate(solid_pos, Ke),
            "blocks": lambda: pat.blocks(data),
            "forces": forces,
            "load": lambda: model.external_load(u),
            "noise": noise,
        },
        min_time,
    )
    total = best.pop("total")
    pieces = {k: best[k] for k in SOLID_PIECES}
    pieces |= {k: best[k].cpu for k in MODEL_PIECES}
    rest = total.cpu - sum(pieces.values())
    return dict(
        element=element, n=e, gp=e * q, nf=model.n_free, nnz=K.nnz, total=total, pieces=pieces, rest=rest, build=build
    )


def chunk_table(element: str, n_elements: int, min_time: float) -> dict:
    """Gauss points/s of model.evaluate for each chunk size of SolidAssembly.evaluate."""
    model = build_model(element, divisions_for_elements(n_elements))
    u_f, lam = deformed_state(model)
    s = model.solid
    gp = s.G.shape[0] * s.G.shape[1]

    def run(c):
        s.chunk = c or s.G.shape[0]  # an instance attribute shadows SolidAssembly.chunk
        model.evaluate(u_f, lam)

    best = interleaved({c: (lambda c=c: run(c)) for c in CHUNKS}, min_time)
    del s.chunk
    return dict(element=element, n=s.G.shape[0], gp_s={c: gp / best[c].cpu for c in CHUNKS})


def variants(element: str, n_elements: int, min_time: float) -> dict:
    """CPU s of each batched product of SolidAssembly.evaluate as src does it and in
    alternatives, all looped over the elements in src's chunks, on the same inputs."""
    model = build_model(element, divisions_for_elements(n_elements))
    u_f, lam = deformed_state(model)
    s = model.solid
    e, q, _, nd = s.G.shape
    c = s.chunk
    u = model.expand(u_f, lam)
    ue = u[s.dofs]
    x = s.gradient(u)
    P, A, _ = s.law.update(x, {}, 0.0, None)
    P2 = P.reshape(e, q * 5)
    AG = np.matmul(A, s.G).reshape(e, q * 5, nd)
    GdV_T_copy = np.ascontiguousarray(s._GdV.transpose(0, 2, 1))  # (e, nd, 5q), as src did before
    fe = np.empty((e, nd))
    Ke = np.empty((e, nd, nd))
    chunks = [slice(i, min(i + c, e)) for i in range(0, e, c)]

    def loop(body):
        def run():
            for sl in chunks:
                body(sl)

        return run

    def fresh_Ke():  # src: a new K_e array on every call, written for the first time here
        out = np.empty((e, nd, nd))
        for sl in chunks:
            np.matmul(s._GdV[sl].transpose(0, 2, 1), AG[sl], out=out[sl])

    cases = [
        ("g = G u_e", "matmul G2 (e,5q,nd) · u_e (src)", loop(lambda sl: np.matmul(s._G2[sl], ue[sl, :, None]))),
        ("g = G u_e", "einsum eqik,ek->eqi", loop(lambda sl: np.einsum("eqik,ek->eqi", s.G[sl], ue[sl]))),
        ("P, A", "the law's update, MooneyRivlin (src)", loop(lambda sl: s.law.update(x[sl], {}, 0.0, None))),
        (
            "f_e = GᵀP dV",
            "matmul, transposed view of GdV (e,5q,nd) (src)",
            loop(lambda sl: np.matmul(s._GdV[sl].transpose(0, 2, 1), P2[sl, :, None], out=fe[sl, :, None])),
        ),
        ("f_e = GᵀP dV", "einsum epk,ep->ek on GdV", loop(lambda sl: np.einsum("epk,ep->ek", s._GdV[sl], P2[sl]))),
        (
            "f_e = GᵀP dV",
            "matmul on a contiguous (e,nd,5q) copy",
            loop(lambda sl: np.matmul(GdV_T_copy[sl], P2[sl, :, None], out=fe[sl, :, None])),
        ),
        ("A G", "matmul (src)", loop(lambda sl: np.matmul(A[sl], s.G[sl]))),
        ("A G", "einsum eqij,eqjk->eqik", loop(lambda sl: np.einsum("eqij,eqjk->eqik", A[sl], s.G[sl]))),
        ("Gᵀ(AG) dV", "matmul, transposed view of GdV (e,5q,nd), into a new K_e (src)", fresh_Ke),
        (
            "Gᵀ(AG) dV",
            "same, into a K_e array kept between calls",
            loop(lambda sl: np.matmul(s._GdV[sl].transpose(0, 2, 1), AG[sl], out=Ke[sl])),
        ),
        (
            "Gᵀ(AG) dV",
            "matmul on a contiguous (e,nd,5q) copy, kept K_e",
            loop(lambda sl: np.matmul(GdV_T_copy[sl], AG[sl], out=Ke[sl])),
        ),
        ("Gᵀ(AG) dV", "einsum epk,epl->ekl", loop(lambda sl: np.einsum("epk,epl->ekl", s._GdV[sl], AG[sl]))),
    ]
    best = interleaved({(op, v): fn for op, v, fn in cases}, min_time)
    return dict(element=element, n=e, chunk=c, ms={k: t.cpu * 1e3 for k, t in best.items()})


# --------------------------------------------------------------------------------------------
# Report
# --------------------------------------------------------------------------------------------


def report(results, chunks, var, head, t_start) -> str:
    main_rows, piece_rows, build_rows = [], [], []
    for r in results:
        tot, p, b = r["total"], r["pieces"], r["build"]
        main_rows.append(
            [
                r["element"],
                f"{r['n']:,}",
                f"{r['gp']:,}",
                f"{r['nf']:,}",
                f"{r['nnz']:,}",
                f"{tot.cpu * 1e3:.1f}",
                f"{tot.wall * 1e3:.1f}",
                f"**{r['gp'] / tot.cpu:.2e}**",
                f"{tot.cpu / r['gp'] * 1e9:.0f}",
            ]
        )
        solid = sum(p[k] for k in SOLID_PIECES)
        piece_rows.append(
            [r["element"], f"{r['n']:,}"]
            + [f"{p[k] * 1e3:.1f} ({100 * p[k] / tot.cpu:.0f}%)" for k in SOLID_PIECES]
            + [f"**{solid * 1e3:.1f} ({100 * solid / tot.cpu:.0f}%)**"]
            + [f"{p[k] * 1e3:.1f} ({100 * p[k] / tot.cpu:.0f}%)" for k in MODEL_PIECES]
            + [f"{r['rest'] * 1e3:.1f}", f"{tot.cpu * 1e3:.1f}"]
        )
        other = b["finalize"] - b["solid"] - b["pattern"] - b["pos"]
        build_rows.append(
            [
                r["element"],
                f"{r['n']:,}",
                f"{b['setup']:.2f}",
                f"**{b['finalize']:.2f}**",
                f"{b['solid']:.2f}",
                f"{b['pattern']:.2f}",
                f"{b['pos']:.2f}",
                f"{other:.2f}",
                "–" if b["unique"] is None else f"{b['unique']:.2f}",
            ]
        )
    out = ["# Assembly throughput: Model.evaluate (residual + tangent)", ""] + head
    out += [
        "Gauss points per second = (elements × Gauss points) / CPU time of one "
        "`model.evaluate(u_f, lam)` with the tangent (minimum over repeats); ns/gp = its "
        "inverse. src/ as it is: material law on component rows, element kernel in chunks "
        f"of {SolidAssembly.chunk} elements.",
        "",
    ]
    out.append(
        table(
            [
                "element",
                "elements",
                "Gauss points",
                "free dofs",
                "nnz(K_ff)",
                "evaluate CPU ms",
                "wall ms",
                "Gauss points/s",
                "ns/gp",
            ],
            main_rows,
        )
    )
    worst = {}
    for r in results:
        worst[r["element"]] = min(worst.get(r["element"], np.inf), r["gp"] / r["total"].cpu)
    out += [
        "Lowest throughput per element: " + ", ".join(f"{k} {v:.2e}" for k, v in worst.items()) + " Gauss points/s.",
        "",
    ]
    out += [
        "## Pieces of evaluate (CPU ms, share of the total)",
        "",
        "Inside `SolidAssembly.evaluate`, summed over its chunks: F: u_e gather, G u_e and "
        "F = I + g; J>0: inversion check; P,A: `MooneyRivlin.stress_tangent`; AG and GᵀAG: "
        "the two batched products of the element tangent; GᵀP: internal forces; solid: their "
        "sum. Around it in `Model.evaluate`: expand: free unknowns to the full vector; "
        "refill: bincount of the element tangents into the pattern's data; blocks: K_ff and "
        "K_fp as CSR; forces: bincounts of f_int and |f_e|, residual gather; load: follower "
        "pressure with its stiffness; noise: row sums of |K| (round-off level); rest: the "
        "difference to the total (allocation, page faults of the new arrays, small items).",
        "",
    ]
    out.append(table(["element", "elements"] + SOLID_PIECES + ["solid"] + MODEL_PIECES + ["rest", "total"], piece_rows))
    out += [
        "## Model construction (CPU s)",
        "",
        "setup: mesh + `Model(...)`, supports and pressure; finalize: `model.finalize()`; "
        "of which (timed inside that call): SolidAssembly (G, dV, G dV), SparsePattern "
        "(keys of all element and edge blocks, sort, de-duplication, CSR structure), "
        "positions (`searchsorted` of the blocks' keys in the pattern); other: the rest of "
        "finalize (DofMap, SFR ties). np.unique: NumPy's `np.unique` on the same keys, for "
        "comparison with SparsePattern's sort + mask (not run above 8 million keys).",
        "",
    ]
    out.append(
        table(
            [
                "element",
                "elements",
                "setup",
                "finalize",
                "SolidAssembly",
                "SparsePattern",
                "positions",
                "other",
                "np.unique(keys)",
            ],
            build_rows,
        )
    )
    if chunks:
        hdr = ["element", "elements"] + [
            ("whole mesh" if c is None else f"{c}") + (" (src)" if c == SolidAssembly.chunk else "") for c in CHUNKS
        ]
        rows = []
        for r in chunks:
            best = max(r["gp_s"].values())
            rows.append(
                [r["element"], f"{r['n']:,}"]
                + [(f"**{v:.2e}**" if v == best else f"{v:.2e}") for v in r["gp_s"].values()]
            )
        out += [
            "## Chunk size of SolidAssembly.evaluate (Gauss points/s of model.evaluate)",
            "",
            "`model.solid.chunk` set to each value (elements per chunk); bold: the fastest.",
            "",
        ]
        out.append(table(hdr, rows))
    if var:
        keys = list(var[0]["ms"])
        rows = []
        for op, v in keys:
            ref = next(k for k in keys if k[0] == op)  # the first variant of each operation: src
            rows.append([op, v] + [f"{r['ms'][(op, v)]:.1f} ({r['ms'][ref] / r['ms'][(op, v)]:.2f})" for r in var])
        out += [
            f"## Kernel variants (CPU ms over the whole mesh, in src's chunks of {var[0]['chunk']} elements)",
            "",
            "In brackets: the first (src) variant's time / this one's; > 1: faster than src. "
            "Inputs (u_e, P, A, AG) precomputed for the whole mesh.",
            "",
        ]
        out.append(table(["operation", "variant"] + [f"{r['element']}, {r['n']:,} el." for r in var], rows))
    out.append(f"Total run time {time.perf_counter() - t_start:.0f} s; load average at the end: {load_average()}.\n")
    return "\n".join(out)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--quick", action="store_true", help="small meshes only (smoke run)")
    ap.add_argument("--elements", nargs="+", default=["q4", "sfr", "q8"])
    ap.add_argument("--sizes", nargs="+", type=float, help="numbers of elements")
    ap.add_argument("--no-variants", action="store_true", help="skip the chunk-size and kernel-variant tables")
    ap.add_argument(
        "--out",
        default=None,
        help="results name (default: assembly_throughput for the full default run, "
        "assembly_throughput_quick with --quick, assembly_throughput_partial "
        "otherwise)",
    )
    args = ap.parse_args(argv)
    sizes = [int(n) for n in (args.sizes or ([1e3, 3e3] if args.quick else [1e3, 1e4, 1e5]))]
    min_time = 0.1 if args.quick else 1.0
    t_start = time.perf_counter()
    tunables = os.environ.get("GLIBC_TUNABLES")
    head = [
        f"Machine: {machine()}; BLAS threads: {os.environ.get('OPENBLAS_NUM_THREADS')}; "
        + (f"GLIBC_TUNABLES={tunables}; " if tunables else "")
        + f"load average at start: {load_average()}",
        "",
    ]
    print(head[0], flush=True)

    results = []
    for element in args.elements:
        for n in sizes:
            r = measure_case(element, n, min_time, unique_limit=8_000_000)
            results.append(r)
            print(
                f"{element} {r['n']} elements: {r['gp'] / r['total'].cpu:.3g} Gauss points/s, "
                f"finalize {r['build']['finalize']:.2f} s",
                flush=True,
            )
    chunks, var = [], []
    if not args.no_variants:
        for element in args.elements:
            print(f"chunk sizes and variants, {element}, {max(sizes)} elements", flush=True)
            chunks.append(chunk_table(element, max(sizes), min_time))
            var.append(variants(element, max(sizes), min_time))
    text = report(results, chunks, var, head, t_start)
    print()
    print(text)
    partial = args.sizes or args.no_variants or args.elements != ap.get_default("elements")
    name = args.out or ("assembly_throughput" + ("_quick" if args.quick else "_partial" if partial else ""))
    path = write_result(name, text)
    print(f"written to {path}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
