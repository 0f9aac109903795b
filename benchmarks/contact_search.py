#!/usr/bin/env python
"""Global contact search: time against the number of slave nodes N and of master segments M.

Methods (each returns the sorted (node, segment) pairs whose node lies in the segment's
bounding box widened by `widen`, axiform.contact.search):

* buckets      axiform.contact.search.buckets (paper eqs. 31-35, default bucket width)
* binary       axiform.contact.search.binary_sort (paper section 3.1)
* brute        axiform.contact.search.brute_force (all N M pairs at once: skipped where
               N M > --brute-limit, 1e8 by default: it takes ~40 ns of CPU per pair here,
               ~4 s at N M = 1e8, so ~40 s per call and 4 GB of temporaries at 1e9)
* kdtree       scipy.spatial.cKDTree built on the nodes; each widened box is queried by its
               centre with p = inf (a square) and radius = half its larger side (times
               1 + 1e-12, so that round-off in centre +- radius cannot drop a node lying exactly
               on the box edge), then the hits are filtered to the box exactly as the others do.
               workers=1, as the NumPy methods are single-threaded.  Tree build included.

Layouts (mould: a bottle-like half profile, axis -> bottom -> ribbed wall -> shoulder -> neck,
arc length L ~ 5, cut into M equal segments):

* wall   N slave nodes along the inner side of the mould (a parison being blown into it): the
         first 60 % of the wall (by arc length) lies within [-0.5, 2] widen of the mould (touching
         or about to), the rest bulges away from it up to 0.3 (not yet in contact).
         widen = one node spacing L / N (the solver's widen is depth + the last motion of the
         nodes, depth = half the smallest element edge).
* cloud  N nodes uniformly random in the mould's bounding box; widen = sqrt(area / N).

Every method's pairs are compared with a reference: brute force where it ran, else the same
box test evaluated in chunks of nodes (exact, ~10 ns per pair) where N M <= --check-limit
(1e9 by default); beyond, the methods must agree with each other exactly, and with the
exhaustive box test on a random sample of 20 000 nodes (the table says which).

Timings: in every (layout, N, M) cell the methods are run in turn, round-robin, `--repeat`
times after a warm-up call (3 times, the first call counting, where that took over 1 s), and
the median CPU time of the process is reported (the machine is shared and noisy; every method
runs on one thread; the wall/CPU ratio is reported too).

Run:   python benchmarks/contact_search.py           (N up to 1e6, M up to 1e4; ~3.5 min)
       python benchmarks/contact_search.py --quick   (N up to 1e5, M up to 1e3; ~1 min)
Writes benchmarks/results/contact_search.md and contact_search.png (with --quick,
contact_search_quick.md and .png, so that a quick look never overwrites the full table).
"""

from __future__ import annotations

import argparse
import datetime
import gc
import os
import statistics
import sys
import time
from pathlib import Path

import numpy as np
from scipy.spatial import cKDTree

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))
from _perf_common import RESULTS, machine, table  # noqa: E402

from axiform.contact import search  # noqa: E402


# --------------------------------------------------------------------------- geometry
def mould_profile(n_fine: int = 20001) -> np.ndarray:
    """A finely sampled bottle-like half profile (r, z), walking with the body (the inside of
    the bottle) on the left: along the bottom from the axis outwards, up the ribbed wall,
    in over the shoulder to the neck."""
    pieces = []
    t = np.linspace(0.0, 1.0, 400)
    # bottom with a push-up: from (0, 0.15) to (0.85, 0)
    pieces.append(np.column_stack([0.85 * t, 0.15 * (1 - t) ** 2]))
    # heel: quarter circle of radius 0.15 centred at (0.85, 0.15)
    a = np.linspace(-np.pi / 2, 0.0, 200)
    pieces.append(np.column_stack([0.85 + 0.15 * np.cos(a), 0.15 + 0.15 * np.sin(a)]))
    # ribbed wall r = 1 + 0.03 sin, z from 0.15 to 2.2 (six ribs)
    z = np.linspace(0.15, 2.2, 2000)
    pieces.append(np.column_stack([1.0 + 0.03 * np.sin(6 * np.pi * (z - 0.15) / 2.05), z]))
    # shoulder: r from 1 to 0.3 along a cosine, z from 2.2 to 2.9
    pieces.append(np.column_stack([0.3 + 0.7 * 0.5 * (1 + np.cos(np.pi * t)), 2.2 + 0.7 * t]))
    # neck
    pieces.append(np.column_stack([np.full(200, 0.3), np.linspace(2.9, 3.3, 200)]))
    P = np.vstack(pieces)
    keep = np.r_[True, np.linalg.norm(np.diff(P, axis=0), axis=1) > 1e-12]
    P = P[keep]
    return resample(P, n_fine - 1)


def resample(P: np.ndarray, m: int) -> np.ndarray:
    """m + 1 points at equal arc length along the polyline P."""
    s = np.r_[0.0, np.cumsum(np.linalg.norm(np.diff(P, axis=0), axis=1))]
    u = np.linspace(0.0, s[-1], m + 1)
    return np.column_stack([np.interp(u, s, P[:, 0]), np.interp(u, s, P[:, 1])])


FINE = None
LOAD = (0.0, 0.0, 0.0)


def layout(kind: str, n: int, m: int, seed: int = 0):
    """Nodes x (n, 2), segment ends a, b (m, 2) and widen for one cell of the study."""
    global FINE
    if FINE is None:
        FINE = mould_profile()
    rng = np.random.default_rng(seed + 1000 * n + m)
    poly = resample(FINE, m)
    a, b = poly[:-1], poly[1:]
    s_f = np.r_[0.0, np.cumsum(np.linalg.norm(np.diff(FINE, axis=0), axis=1))]
    L = s_f[-1]
    if kind == "wall":
        widen = L / n
        s = np.sort(rng.uniform(0.0, L, n))
        p = np.column_stack([np.interp(s, s_f, FINE[:, 0]), np.interp(s, s_f, FINE[:, 1])])
        tx = np.gradient(FINE[:, 0], s_f)
        tz = np.gradient(FINE[:, 1], s_f)
        t = np.column_stack([np.interp(s, s_f, tx), np.interp(s, s_f, tz)])
        t /= np.linalg.norm(t, axis=1)[:, None]
        nrm = np.column_stack([-t[:, 1], t[:, 0]])  # left of the direction of travel: the body side
        frac = s / L
        gap = np.where(
            frac < 0.6,
            rng.uniform(-0.5, 2.0, n) * widen,
            0.3 * np.sin(np.pi * np.clip((frac - 0.6) / 0.4, 0, 1)) + 2.0 * widen,
        )
        x = p + gap[:, None] * nrm
        x[:, 0] = np.maximum(x[:, 0], 0.0)
    elif kind == "cloud":
        lo, hi = FINE.min(axis=0), FINE.max(axis=0)
        x = rng.uniform(lo, hi, (n, 2))
        widen = float(np.sqrt(np.prod(hi - lo) / n))
    else:
        raise ValueError(kind)
    return x, a, b, widen


# --------------------------------------------------------------------------- methods
def kdtree(x: np.ndarray, a: np.ndarray, b: np.ndarray, widen: float) -> np.ndarray:
    """cKDTree on the nodes, one p = inf ball (a square) per widened box, filtered to the box."""
    lo = np.minimum(a, b) - widen
    hi = np.maximum(a, b) + widen
    c = 0.5 * (lo + hi)
    r = 0.5 * (hi - lo).max(axis=1)
    r = r * (1.0 + 1e-12) + 1e-300
    tree = cKDTree(x)
    hits = tree.query_ball_point(c, r, p=np.inf, workers=1, return_sorted=False)
    count = np.fromiter((len(h) for h in hits), np.int64, len(hits))
    if count.sum() == 0:
        return np.zeros((0, 2), np.int64)
    nodes = np.concatenate([np.asarray(h, np.int64) for h in hits if len(h)])
    seg = np.repeat(np.arange(len(a)), count)
    p = x[nodes]
    keep = ((p >= lo[seg]) & (p <= hi[seg])).all(axis=1)
    nodes, seg = nodes[keep], seg[keep]
    order = np.lexsort((seg, nodes))
    return np.column_stack([nodes[order], seg[order]])


def chunked_reference(x, a, b, widen, chunk_pairs: int = 20_000_000) -> np.ndarray:
    """The box test on every pair, in chunks of nodes (exact, memory-bounded)."""
    lo = np.minimum(a, b) - widen
    hi = np.maximum(a, b) + widen
    step = max(1, chunk_pairs // max(len(a), 1))
    out = []
    for i0 in range(0, len(x), step):
        p = x[i0 : i0 + step]
        ok = (p[:, None, 0] >= lo[None, :, 0]) & (p[:, None, 0] <= hi[None, :, 0])
        ok &= (p[:, None, 1] >= lo[None, :, 1]) & (p[:, None, 1] <= hi[None, :, 1])
        n, s = np.nonzero(ok)
        out.append(np.column_stack([n + i0, s]))
    pairs = np.vstack(out).astype(np.int64)
    return pairs[np.lexsort((pairs[:, 1], pairs[:, 0]))]


METHODS = {
    "buckets": search.buckets,
    "binary": search.binary_sort,
    "brute": search.brute_force,
    "kdtree": kdtree,
}


def sampled_check(x, a, b, widen, results: dict, n_sample: int = 20_000, seed: int = 1):
    """Exact check on a random sample of nodes: their pairs by the box test against every
    segment, compared with each method's pairs restricted to those nodes."""
    rng = np.random.default_rng(seed)
    sample = np.sort(rng.choice(len(x), min(len(x), n_sample), replace=False))
    ref = chunked_reference(x[sample], a, b, widen)
    ref[:, 0] = sample[ref[:, 0]]
    same = {}
    for k, pairs in results.items():
        mine = pairs[np.isin(pairs[:, 0], sample)]
        same[k] = bool(np.array_equal(mine, ref))
    return same


def run_cell(kind, n, m, repeat, brute_limit, check_limit):
    """Time every method on one (layout, N, M) cell and check its pairs.  Each method is
    called once first (warm-up, and its pairs for the check; a first call over 1 s counts as
    a sample, there is nothing to warm up in it), then the methods are called in turn,
    round-robin, until each has `repeat` samples (3 where a first call took over 1 s)."""
    x, a, b, widen = layout(kind, n, m)
    names = [k for k in METHODS if k != "brute" or n * m <= brute_limit]
    pairs, times, walls = {}, {k: [] for k in names}, {k: [] for k in names}
    for k in names:
        gc.collect()
        t, c = time.perf_counter(), time.process_time()
        pairs[k] = METHODS[k](x, a, b, widen)
        first, cpu = time.perf_counter() - t, time.process_time() - c
        if first > 1.0:
            times[k].append(cpu)
            walls[k].append(first)
    want = {k: (min(repeat, 3) if times[k] else repeat) for k in names}
    while any(len(times[k]) < want[k] for k in names):
        for k in names:
            if len(times[k]) < want[k]:
                gc.collect()
                t, c = time.perf_counter(), time.process_time()
                METHODS[k](x, a, b, widen)
                times[k].append(time.process_time() - c)
                walls[k].append(time.perf_counter() - t)
    if "brute" in names:
        ref, ref_name = pairs["brute"], "brute force"
    elif n * m <= check_limit:
        ref, ref_name = chunked_reference(x, a, b, widen), "chunked brute force"
    else:
        ref, ref_name = None, "each other + sampled brute force"
    if ref is not None:
        same = {k: bool(np.array_equal(pairs[k], ref)) for k in names}
        n_pairs = len(ref)
    else:
        sampled = sampled_check(x, a, b, widen, pairs)
        base = pairs["buckets"]
        same = {k: sampled[k] and bool(np.array_equal(pairs[k], base)) for k in names}
        n_pairs = len(base)
    return {
        "layout": kind,
        "N": n,
        "M": m,
        "widen": widen,
        "pairs": n_pairs,
        "time": {k: statistics.median(v) for k, v in times.items()},
        "spread": {k: (min(v), max(v)) for k, v in times.items()},
        "wall": {k: statistics.median(v) for k, v in walls.items()},
        "same": same,
        "reference": ref_name,
        "repeats": {k: len(v) for k, v in times.items()},
    }


def slope(xs, ys):
    """Least-squares slope of log y against log x."""
    lx, ly = np.log(np.asarray(xs, float)), np.log(np.asarray(ys, float))
    return float(np.polyfit(lx, ly, 1)[0]) if len(xs) >= 2 else float("nan")


def fmt_t(t):
    if t is None:
        return "—"
    if t < 1e-3:
        return f"{t * 1e6:.0f} µs"
    if t < 1:
        return f"{t * 1e3:.1f} ms"
    return f"{t:.2f} s"


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="N up to 1e5, M up to 1e3, 3 repeats")
    ap.add_argument("--repeat", type=int, default=None, help="timed calls per method and cell (default 5, quick 3)")
    ap.add_argument("--brute-limit", type=float, default=1e8, help="largest N*M for the library's brute force")
    ap.add_argument("--check-limit", type=float, default=1e9, help="largest N*M for the exhaustive check")
    ap.add_argument("--out", default=str(RESULTS), help="folder for contact_search.md / .png")
    args = ap.parse_args(argv)
    Ns = [10**3, 10**4, 10**5] if args.quick else [10**3, 10**4, 10**5, 10**6]
    Ms = [10**2, 10**3] if args.quick else [10**2, 10**3, 10**4]
    repeat = args.repeat or (3 if args.quick else 5)
    t_start = time.perf_counter()
    global LOAD
    LOAD = os.getloadavg()
    rows = []
    for kind in ("wall", "cloud"):
        for m in Ms:
            for n in Ns:
                r = run_cell(kind, n, m, repeat, args.brute_limit, args.check_limit)
                rows.append(r)
                print(
                    f"{kind:5s} N={n:.0e} M={m:.0e} pairs={r['pairs']:>9d}  "
                    + "  ".join(f"{k} {fmt_t(t)}" for k, t in r["time"].items())
                    + f"  same={all(r['same'].values())} ({r['reference']})",
                    flush=True,
                )
    total = time.perf_counter() - t_start
    write_report(rows, Ns, Ms, repeat, total, args)
    bad = [r for r in rows if not all(r["same"].values())]
    if bad:
        print("MISMATCH in", [(r["layout"], r["N"], r["M"], r["same"]) for r in bad])
        return 1
    return 0


def write_report(rows, Ns, Ms, repeat, total, args):
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    methods = list(METHODS)
    ratios = [r["wall"][k] / max(r["time"][k], 1e-9) for r in rows for k in r["time"]]
    lines = [
        "# Global contact search: time against N (slave nodes) and M (master segments)",
        "",
        f"Written by `benchmarks/contact_search.py{' --quick' if args.quick else ''}` on "
        f"{datetime.date.today()} in {total:.0f} s.  Machine: {machine()}; load average "
        f"{LOAD[0]:.1f} at the start, {os.getloadavg()[0]:.1f} at the end (shared with other jobs).  "
        "Times are CPU times of the calling process (time.process_time: every method here runs on "
        "one thread, and CPU time does not count the waits when the cores are taken by other jobs), "
        f"median of {repeat} round-robin repeats per method and cell after a warm-up call; a method "
        "whose first call took over 1 s gets 3 samples, that call included.  Median wall time over "
        f"median CPU time, over all cells and methods: median {statistics.median(ratios):.2f}, range "
        f"{min(ratios):.2f}-{max(ratios):.2f}.",
        "",
        "Methods: `buckets` and `binary` and `brute` are `axiform.contact.search.buckets`, "
        "`binary_sort`, `brute_force`; `kdtree` is `scipy.spatial.cKDTree` on the nodes, one "
        "p = inf ball query per widened box (radius half its larger side), filtered to the box "
        "(tree build included, workers = 1).  Each returns the sorted (node, segment) pairs.  "
        f"`brute` is skipped (—) where N M > {args.brute_limit:.0e}: it costs ~40 ns of CPU per pair "
        "here (~40 s per call and 4 GB of temporaries at N M = 1e9).  Check: every method's pairs equal "
        f"to brute force where it ran, else to the exhaustive box test run in chunks (N M ≤ "
        f"{args.check_limit:.0e}), else equal to each other and to the exhaustive test on a random "
        "sample of 20 000 nodes.",
        "",
        "Layouts: **wall** — N nodes along the inner side of a bottle-like mould (arc length ~5), "
        "60 % of them within [-0.5, 2] widen of it, the rest bulging up to 0.3 away; widen = one "
        "node spacing L/N.  **cloud** — N nodes uniformly random in the mould's bounding box; "
        "widen = sqrt(area/N).  The mould is cut into M equal segments.",
        "",
        "## Times (median)",
        "",
    ]
    for kind in ("wall", "cloud"):
        lines.append(f"### {kind}")
        lines.append("")
        hdr = ["N", "M", "pairs"] + methods + ["check"]
        body = []
        for r in rows:
            if r["layout"] != kind:
                continue
            check = (
                ("all = " + r["reference"])
                if all(r["same"].values())
                else "MISMATCH: " + ", ".join(k for k, v in r["same"].items() if not v)
            )
            body.append(
                [f"{r['N']:.0e}", f"{r['M']:.0e}", r["pairs"]] + [fmt_t(r["time"].get(k)) for k in methods] + [check]
            )
        lines.append(table(hdr, body))
    # slopes
    lines += [
        "## Observed complexity",
        "",
        "Least-squares slope of log(time) against log(N) at fixed M, and against log(M) at "
        "fixed N, as *all points / upper points* (upper: N ≥ 1e4, M ≥ 1e3, where the fixed costs "
        "of a call no longer dominate).  The number of pairs found grows too: its slopes are given "
        "for comparison (an output-sensitive method cannot beat them).  `brute` lists the points "
        "it ran on.",
        "",
    ]

    def slopes(sel, var, key):
        pts = [(r[var], key(r)) for r in sel if key(r) is not None]
        top = [(v, t) for v, t in pts if v >= (1e4 if var == "N" else 1e3)]
        a = f"{slope(*zip(*pts, strict=False)):.2f}" if len(pts) >= 2 else "—"
        b = f"{slope(*zip(*top, strict=False)):.2f}" if len(top) >= 2 else "—"
        return f"{a} / {b}" + (f" ({len(pts)} pts)" if len(pts) < len(sel) and len(pts) >= 2 else "")

    hdr = ["layout", "fixed", "pairs"] + methods
    body = []
    for kind in ("wall", "cloud"):
        for var, fixed_name, fixed_vals in (("N", "M", Ms), ("M", "N", Ns)):
            for v in fixed_vals:
                sel = [r for r in rows if r["layout"] == kind and r[fixed_name] == v]
                cells = [slopes(sel, var, lambda r: max(r["pairs"], 1))]
                cells += [slopes(sel, var, lambda r, k=k: r["time"].get(k)) for k in methods]
                body.append([kind, f"vs {var}, {fixed_name} = {v:.0e}"] + cells)
    lines.append(table(hdr, body))
    spread = {
        k: max(((r["spread"][k][1] - r["spread"][k][0]) / r["time"][k]) for r in rows if k in r["time"])
        for k in methods
    }
    lines += [
        "Noise: largest (max − min) / median of the repeats over all cells: "
        + ", ".join(f"{k} {100 * v:.0f} %" for k, v in spread.items())
        + ".",
        "",
    ]
    # ratios at the largest cells
    lines += ["## Speed relative to buckets (time / buckets time, median)", ""]
    body = []
    for r in rows:
        if r["N"] == Ns[-1] or r["M"] == Ms[-1]:
            tb = r["time"]["buckets"]
            body.append(
                [r["layout"], f"{r['N']:.0e}", f"{r['M']:.0e}"]
                + [f"{r['time'][k] / tb:.2f}" if k in r["time"] else "—" for k in methods]
            )
    lines.append(table(["layout", "N", "M"] + methods, body))
    stem = "contact_search_quick" if args.quick else "contact_search"  # --quick keeps the full table
    lines += [f"`{stem}.png` plots time against N for every M and method.", ""]
    (out / f"{stem}.md").write_text("\n".join(lines) + "\n")
    plot(rows, Ns, Ms, out / f"{stem}.png")
    print("wrote", out / f"{stem}.md")


def plot(rows, Ns, Ms, path):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, 2, figsize=(12, 5), sharey=True)
    styles = {"buckets": "o-", "binary": "s--", "brute": "x:", "kdtree": "^-."}
    colors = plt.cm.viridis(np.linspace(0, 0.85, len(Ms)))
    for ax, kind in zip(axes, ("wall", "cloud"), strict=False):
        for m, col in zip(Ms, colors, strict=False):
            for k in METHODS:
                sel = [r for r in rows if r["layout"] == kind and r["M"] == m and k in r["time"]]
                if sel:
                    ax.loglog(
                        [r["N"] for r in sel],
                        [r["time"][k] for r in sel],
                        styles[k],
                        color=col,
                        label=f"{k}, M = {m:.0e}",
                    )
        nn = np.array([Ns[0], Ns[-1]], float)
        ax.loglog(nn, 2e-7 * nn, "k-", lw=0.5, alpha=0.5)
        ax.text(nn[-1], 2e-7 * nn[-1], " slope 1", fontsize=8)
        ax.set_title(f"{kind} layout")
        ax.set_xlabel("slave nodes N")
        ax.grid(True, which="both", alpha=0.3)
    axes[0].set_ylabel("CPU time per search [s] (median)")
    axes[1].legend(fontsize=7, ncol=2)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


if __name__ == "__main__":
    sys.exit(main())
