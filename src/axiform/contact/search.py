"""Global contact search (paper section 3, eqs. 31-35): which slave nodes may touch which
master segment.  A node is a candidate of a segment when it lies in the segment's bounding
box widened by `widen` in both directions.  Three ways to find exactly those pairs: buckets
(a counting sort of the nodes by bucket code, the paper's nbox / npoint / ndsort), the binary
sort of section 3.1, and brute force.  All return the same pairs, sorted by (node, segment).
"""

from __future__ import annotations

import numpy as np


def _boxes(a: np.ndarray, b: np.ndarray, widen: float):
    lo = np.minimum(a, b) - widen
    hi = np.maximum(a, b) + widen
    return lo, hi


def _inside(x: np.ndarray, nodes: np.ndarray, segs: np.ndarray, lo, hi) -> np.ndarray:
    p, lo, hi = x[nodes], lo[segs], hi[segs]
    return (p[:, 0] >= lo[:, 0]) & (p[:, 0] <= hi[:, 0]) & (p[:, 1] >= lo[:, 1]) & (p[:, 1] <= hi[:, 1])


def _sorted_pairs(nodes: np.ndarray, segs: np.ndarray) -> np.ndarray:
    pairs = np.column_stack([nodes, segs]).astype(np.int64)
    order = np.lexsort((pairs[:, 1], pairs[:, 0]))
    return pairs[order]


def brute_force(x: np.ndarray, a: np.ndarray, b: np.ndarray, widen: float) -> np.ndarray:
    """Every (node, segment) pair tested: O(N M), in chunks of nodes to bound the memory."""
    lo, hi = _boxes(a, b, widen)
    found = []
    step = max(1, 2**22 // max(len(a), 1))
    for k in range(0, len(x), step):
        p = x[k : k + step]
        ok = (
            (p[:, None, 0] >= lo[None, :, 0])
            & (p[:, None, 0] <= hi[None, :, 0])
            & (p[:, None, 1] >= lo[None, :, 1])
            & (p[:, None, 1] <= hi[None, :, 1])
        )
        n, s = np.nonzero(ok)
        found.append(np.column_stack([n + k, s]))
    pairs = np.vstack(found) if found else np.zeros((0, 2), np.int64)
    return _sorted_pairs(pairs[:, 0], pairs[:, 1])


class Buckets:
    """The paper's buckets: cells of width bs over the nodes' bounding box (eq. 32), the code
    of each node B = (SY_i - 1) SX + SX_i (eqs. 31, 33, here 0-based), and the counting sort
    of the nodes by code into ndsort with pointers npoint (nbox nodes in each bucket)."""

    def __init__(self, x: np.ndarray, bs: float):
        self.x = x
        self.xmin = x.min(axis=0)
        span = x.max(axis=0) - self.xmin
        # no more buckets than about four per node: a tiny width would only waste memory
        cap = 4 * len(x) + 16
        if np.prod(np.floor(span / bs) + 1) > cap:
            bs = max(bs, float(np.sqrt(span[0] * span[1] / cap)), float(span.max()) / cap)
            while np.prod(np.floor(span / bs) + 1) > cap:
                bs *= 1.5
        self.bs = bs
        self.SX, self.SY = np.floor(span / bs).astype(np.int64) + 1
        cell = np.floor((x - self.xmin) / bs).astype(np.int64)
        cell = np.minimum(cell, [self.SX - 1, self.SY - 1])
        self.lbox = cell[:, 1] * self.SX + cell[:, 0]  # code of each node
        self.nbox = np.bincount(self.lbox, minlength=self.SX * self.SY)  # nodes per bucket
        self.npoint = np.concatenate([[0], np.cumsum(self.nbox)])  # pointer to each bucket
        self.ndsort = np.argsort(self.lbox, kind="stable")  # nodes sorted by code

    def candidates(self, a: np.ndarray, b: np.ndarray, widen: float) -> np.ndarray:
        """Pairs (node, segment) for the widened territory of each segment (eqs. 34-35)."""
        lo, hi = _boxes(a, b, widen)
        i0 = np.floor((lo - self.xmin) / self.bs).astype(np.int64)
        i1 = np.floor((hi - self.xmin) / self.bs).astype(np.int64)
        nmax = np.array([self.SX - 1, self.SY - 1])
        outside = (i1 < 0).any(axis=1) | (i0 > nmax).any(axis=1)
        i0 = np.clip(i0, 0, nmax)
        i1 = np.clip(i1, 0, nmax)
        ni = np.where(outside, 0, i1[:, 0] - i0[:, 0] + 1)
        nj = np.where(outside, 0, i1[:, 1] - i0[:, 1] + 1)
        count = ni * nj
        seg = np.repeat(np.arange(len(a)), count)
        k = np.arange(count.sum()) - np.repeat(np.cumsum(count) - count, count)
        ii = i0[seg, 0] + k % ni[seg]
        jj = i0[seg, 1] + k // ni[seg]
        code = jj * self.SX + ii
        # expand each (segment, bucket) into the bucket's nodes
        n_in = self.nbox[code]
        seg2 = np.repeat(seg, n_in)
        start = np.repeat(self.npoint[code], n_in)
        k2 = np.arange(n_in.sum()) - np.repeat(np.cumsum(n_in) - n_in, n_in)
        nodes = self.ndsort[start + k2]
        keep = _inside(self.x, nodes, seg2, lo, hi)
        return _sorted_pairs(nodes[keep], seg2[keep])


def buckets(x: np.ndarray, a: np.ndarray, b: np.ndarray, widen: float, bs: float | None = None) -> np.ndarray:
    """Bucket search; the bucket width defaults to the mean segment box size plus 2 widen."""
    if len(x) == 0 or len(a) == 0:
        return np.zeros((0, 2), np.int64)
    if bs is None:
        bs = float(np.mean(np.abs(b - a).max(axis=1))) + 2 * widen
        bs = max(bs, 1e-12 * max(1.0, float(np.ptp(x, axis=0).max())))
    return Buckets(x, bs).candidates(a, b, widen)


def binary_sort(x: np.ndarray, a: np.ndarray, b: np.ndarray, widen: float) -> np.ndarray:
    """Section 3.1: the nodes sorted by x and by y; for each segment the nodes within its
    widened x-range and y-range are found by bisection, and the smaller of the two lists is
    filtered by the other coordinate."""
    lo, hi = _boxes(a, b, widen)
    by_x = np.argsort(x[:, 0], kind="stable")
    by_y = np.argsort(x[:, 1], kind="stable")
    xs, ys = x[by_x, 0], x[by_y, 1]
    x0, x1 = np.searchsorted(xs, lo[:, 0], "left"), np.searchsorted(xs, hi[:, 0], "right")
    y0, y1 = np.searchsorted(ys, lo[:, 1], "left"), np.searchsorted(ys, hi[:, 1], "right")
    use_x = (x1 - x0) <= (y1 - y0)
    start = np.where(use_x, x0, y0)
    count = np.maximum(np.where(use_x, x1 - x0, y1 - y0), 0)
    seg = np.repeat(np.arange(len(a)), count)
    k = np.arange(count.sum()) - np.repeat(np.cumsum(count) - count, count)
    pos = np.repeat(start, count) + k
    nodes = np.where(use_x[seg], by_x[np.minimum(pos, len(x) - 1)], by_y[np.minimum(pos, len(x) - 1)])
    keep = _inside(x, nodes, seg, lo, hi)
    return _sorted_pairs(nodes[keep], seg[keep])


class PairCache:
    """The pairs of a search reused within a step, the same pairs a new search would return.

    The solver passes the same last converged positions x_prev at every iteration of a step,
    and the nodes x stay near them.  A node whose x lies in a box widened by w = depth + moved
    (moved >= |x - x_prev| for every node) has its x_prev in the box widened by w + moved.  So
    the pairs of x_prev for a margin W >= w + moved hold every pair of x, and the exact box
    test of x on those pairs gives exactly the pairs of a new search.  The first call of a
    step searches x_prev with W = 2 (w + moved); later calls whose w + moved fits in W only
    filter; one that does not searches again with a wider W.  Entries are keyed on the
    search method, the boxes and x_prev (compared element by element), the last `size`
    kept (a pair searches for its nodes and for its guards' mid-points; two pairs may share
    a surface).
    Every answer is that of `finder(x, a, b, w)`: a cache, no state."""

    def __init__(self, size: int = 4):
        self.size = size
        self.entries: list[tuple] = []

    def pairs(
        self, finder, x: np.ndarray, x_prev: np.ndarray, a: np.ndarray, b: np.ndarray, depth: float, moved: float
    ) -> np.ndarray:
        w = depth + moved
        need = w + moved
        # slack for the rounding of lo - w and of the coordinates (relative 1e-9 of the sizes)
        scale = max(
            float(np.abs(a).max(initial=0.0)),
            float(np.abs(b).max(initial=0.0)),
            float(np.abs(x_prev).max(initial=0.0)),
            float(np.abs(x).max(initial=0.0)),
        )
        need_safe = need * (1.0 + 1e-9) + 1e-9 * scale
        for n, (f, ka, kb, kx, W, cached) in enumerate(self.entries):
            if (
                f is finder
                and W >= need_safe
                and kx.shape == x_prev.shape
                and np.array_equal(kx, x_prev)
                and np.array_equal(ka, a)
                and np.array_equal(kb, b)
            ):
                self.entries.insert(0, self.entries.pop(n))
                lo, hi = _boxes(a, b, w)
                return cached[_inside(x, cached[:, 0], cached[:, 1], lo, hi)]
        W = 2.0 * need_safe
        cached = finder(x_prev, a, b, W)
        self.entries = [(finder, a.copy(), b.copy(), np.array(x_prev, float), W, cached)] + [
            e
            for e in self.entries
            if not (e[0] is finder and e[3].shape == x_prev.shape and np.array_equal(e[3], x_prev))
        ][: self.size - 1]
        lo, hi = _boxes(a, b, w)
        return cached[_inside(x, cached[:, 0], cached[:, 1], lo, hi)]
