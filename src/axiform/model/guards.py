"""Checks that refuse nonsense before any work: outlines that cross themselves (moulds, mesh
boundaries), bodies free to move rigidly.

Each check returns what it found (None when all is well); the case file turns a finding into
a CaseError naming the key.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
import scipy.sparse as sp

from ..fem.graphs import connected_components


def _crossing_pairs(
    a: np.ndarray, b: np.ndarray, skip: Callable[[np.ndarray, np.ndarray], np.ndarray], block: int = 2048
) -> tuple[int, int] | None:
    """The first pair (i, j), i < j, of segments a[i]-b[i], a[j]-b[j] ((n, 2) arrays) that
    cross, touch or overlap, leaving out the pairs skip(i, j) marks (neighbours that share an
    end); skip is a function of two index arrays returning a boolean array.  Work in blocks
    of rows, so memory stays at block * n."""
    n = len(a)
    both = np.vstack([a, b])
    lo, scale = both.min(axis=0), float(np.ptp(both, axis=0).max())
    a, b = (a - lo) / (scale or 1.0), (b - lo) / (scale or 1.0)  # in a unit box: no overflow
    eps = 1e-12

    def orient(p, q, r):
        return (q[..., 0] - p[..., 0]) * (r[..., 1] - p[..., 1]) - (q[..., 1] - p[..., 1]) * (r[..., 0] - p[..., 0])

    for start in range(0, n, block):
        i = np.arange(start, min(start + block, n))[:, None]
        j = np.arange(n)[None, :]
        ai, bi, aj, bj = a[i], b[i], a[j], b[j]
        o1, o2 = orient(ai, bi, aj), orient(ai, bi, bj)
        o3, o4 = orient(aj, bj, ai), orient(aj, bj, bi)
        # each segment's ends on both sides of (or on) the other's line; collinear ones
        # (every orientation zero) meet where their boxes overlap
        sides = (o1 * o2 <= eps * eps) & (o3 * o4 <= eps * eps)
        lo_i, hi_i = np.minimum(ai, bi), np.maximum(ai, bi)
        lo_j, hi_j = np.minimum(aj, bj), np.maximum(aj, bj)
        boxes = ((lo_i <= hi_j + eps) & (lo_j <= hi_i + eps)).all(axis=-1)
        hit = sides & boxes & (j > i) & ~skip(i, j)
        if hit.any():
            r, c = np.argwhere(hit)[0]
            return int(i[r, 0]), int(c)
    return None


def chain_crossing(points: np.ndarray) -> tuple[int, int] | None:
    """Pieces (i, j) of the chain points[0] - points[1] - ... that cross each other, or
    neighbours (which share their common point) where the second runs back along the first;
    a closed chain (last point = first) also joins its ends."""
    P = np.asarray(points, float)
    m = len(P) - 1
    d = np.diff(P, axis=0)
    d /= np.maximum(np.linalg.norm(d, axis=1), 1e-300)[:, None]
    back = np.flatnonzero(np.einsum("ij,ij->i", d[:-1], d[1:]) < -1.0 + 1e-9)
    if back.size:  # a piece running straight back along the one before
        return int(back[0]), int(back[0]) + 1
    closed = m > 2 and np.array_equal(P[0], P[-1])

    def skip(i, j):
        return (j - i <= 1) | (closed & (i == 0) & (j == m - 1))

    return _crossing_pairs(P[:-1], P[1:], skip)


def boundary_crossing(points: np.ndarray, edges: np.ndarray) -> tuple[int, int] | None:
    """Boundary edges (i, j) (rows of edges, (m, >= 2) node numbers, the first two the ends)
    whose chords cross; edges sharing a node are neighbours."""
    ends = np.asarray(edges)[:, :2]

    def skip(i, j):
        ei, ej = ends[i[:, 0]][:, None, :, None], ends[j[0]][None, :, None, :]
        return (ei == ej).any(axis=(-1, -2))

    return _crossing_pairs(points[ends[:, 0]], points[ends[:, 1]], skip)


def bodies(n_nodes: int, cells: np.ndarray) -> np.ndarray:
    """The connected body (0, 1, ...) each node belongs to, (n_nodes,), through shared cells."""
    rows = np.repeat(cells[:, 0], cells.shape[1])
    graph = sp.coo_matrix((np.ones(rows.size), (rows, cells.ravel())), shape=(n_nodes, n_nodes))
    return connected_components(graph, directed=False)[1]


def free_to_slide(n_nodes: int, cells: np.ndarray, held_uz: np.ndarray, touching: np.ndarray) -> list[int]:
    """The bodies free to translate along z, the only rigid motion of an axisymmetric body
    (any radial motion strains the hoop direction): no node of theirs has a prescribed uz
    (held_uz, node numbers) and no contact pair has slaves on them (touching, node numbers)."""
    body = bodies(n_nodes, cells)
    held = np.zeros(body.max() + 1, dtype=bool)
    held[body[np.asarray(held_uz, dtype=np.int64)]] = True
    held[body[np.asarray(touching, dtype=np.int64)]] = True
    used = np.unique(body[cells.ravel()])
    return [int(b) for b in used if not held[b]]


def evaluation_fault(system, r_full: np.ndarray, K: sp.spmatrix | None) -> str | None:
    """What makes a state unusable, with its place: a residual (r_full, (n_full,)) that is not
    finite (node, dof, an element holding the node), or a tangent K (n_free, n_free) left
    without stiffness against a rigid translation along z (a mechanism; the system's
    rigid_modes)."""
    bad = np.flatnonzero(~np.isfinite(r_full))
    if bad.size:
        node, k = divmod(int(bad[0]), system.dpn)
        element = int(np.argmax((system.mesh.cells == node).any(axis=1)))
        return (
            f"the residual is not finite at node {node} ({('ur', 'uz', 'rot')[k]}, element {element}): "
            "an overflow of the material law or a collapsed element"
        )
    if K is None or not K.nnz:
        return None
    modes = system.rigid_modes
    if not modes.shape[1]:
        return None
    # ||K m||_1 against ||K||_1 ||m||_1: zero to round-off for a free mode, about 1 / (nodes of
    # the body) for a body held at a few nodes
    force = np.asarray(abs(sp.csr_matrix(K) @ modes).sum(axis=0)).ravel()
    size = abs(K).sum(axis=0).max() * np.asarray(modes.sum(axis=0)).ravel()
    free = np.flatnonzero(force <= 1e-9 * size)
    if free.size:
        return (
            "a mechanism: the tangent has no stiffness against a rigid translation along z of "
            f"{free.size} bod{'y' if free.size == 1 else 'ies'} (hold uz somewhere: a [[fix]], or contact)"
        )
    return None
