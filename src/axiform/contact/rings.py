"""The ring areas of a slave face of the body of revolution: the consistent area of each node
(integral of 2 pi r N_i ds over its edges) and the consistent row of a node on the axis (a
pole), with their derivatives; the slave edges of a node set; the cell height under an edge.
Arrays over the edges of a slave face, vectorized."""

from __future__ import annotations

import functools

import numpy as np

from ..fem.elements import edge_rule
from ..fem.mesh import Mesh


def slave_edges(mesh: Mesh, nodes: np.ndarray) -> np.ndarray:
    """Boundary edges (m, edge_nodes) all of whose nodes (Q8: the mid-side node too) are among
    `nodes`, ends first, as the owning cell runs."""
    is_slave = np.zeros(mesh.n_nodes, bool)
    is_slave[nodes] = True
    e = mesh.boundary_edges
    return e[is_slave[e].all(axis=1)]


@functools.cache
def _ring_weights(edge_nodes: int):
    """The constant matrices of `ring_areas` for edges of edge_nodes nodes k, from
    `edge_rule`: 2 pi w_p N_pi (p, k), 2 pi w_p N_pi N_pj (p, k k) and 2 pi w_p N_pi dN_pj
    (p, k k); built once, shared and read-only."""
    _, wq, N, dN = edge_rule(edge_nodes, 3)
    k = N.shape[1]
    wN = 2 * np.pi * wq[:, None] * N
    out = (
        wN,
        (wN[:, :, None] * N[:, None, :]).reshape(-1, k * k),
        (wN[:, :, None] * dN[:, None, :]).reshape(-1, k * k),
    )
    for arr in out:
        arr.flags.writeable = False
    return out


def ring_areas(x: np.ndarray, edges: np.ndarray, derivative: bool = False):
    """The consistent ring areas of the edge nodes, a_i = int 2 pi r N_i ds over each edge
    with the edge's own shape functions N_i (linear, or quadratic for Q8: Simpson's corner
    weight 1/6 and mid-side weight 2/3 on a straight edge at constant r), in the
    configuration x (n_nodes, 2) (reference or current).

    Returns per edge and edge node the part a (m, k) and, if asked, its derivative
    da[m, i, j, :] = d a_i / d x_j (m, k, k, 2) with respect to the positions of the edge's
    nodes; a node's area is the sum of its parts over its edges."""
    m, k = edges.shape
    if k == 2:
        return _straight_ring_areas(x, edges, derivative)
    _, _, N, dN = edge_rule(k, 3)  # (p, k): built once
    wN, wNN, wNdN = _ring_weights(k)
    X = x[edges]  # (m, k, 2)
    t = dN @ X  # dx/ds (m, p, 2)
    L = np.sqrt(t[..., 0] ** 2 + t[..., 1] ** 2)  # (m, p)
    r = X[..., 0] @ N.T  # (m, p)
    a = (r * L) @ wN
    if not derivative:
        return a
    # d(r L) / dx_j = N_j L e_r + r dN_j t / L: (m, 2, k k), then (m, k, k, 2)
    da = np.swapaxes((r / L)[..., None] * t, 1, 2) @ wNdN
    da[:, 0] += L @ wNN
    return a, da.reshape(m, 2, k, k).transpose(0, 2, 3, 1)


# a_i = (pi / 3) l (2 r_i + r_j) on a straight edge of length l: the linear N_i integrated
_STRAIGHT = (np.pi / 3.0) * np.array([[2.0, 1.0], [1.0, 2.0]])


def _straight_ring_areas(x: np.ndarray, edges: np.ndarray, derivative: bool):
    """`ring_areas` of straight two-node edges in closed form (the rule is exact there):
    a_i = (pi / 3) l (2 r_i + r_j), d a_i / d x_j = (pi / 3) (1 + delta_ij) l e_r
    + (pi / 3) (2 r_i + r_j) dl/dx_j, dl/dx_1 = -dl/dx_0 = (x_1 - x_0) / l."""
    X = x.take(edges, axis=0)  # (m, 2, 2)
    d = X[:, 1] - X[:, 0]
    length = np.sqrt(d[:, 0] * d[:, 0] + d[:, 1] * d[:, 1])
    s = X[..., 0] @ _STRAIGHT  # (pi / 3) (2 r_i + r_j), (m, 2)
    a = s * length[:, None]
    if not derivative:
        return a
    da = np.empty((len(edges), 2, 2, 2))
    np.multiply(s[:, :, None], (d / length[:, None])[:, None, :], out=da[:, :, 1])
    np.negative(da[:, :, 1], out=da[:, :, 0])
    da[..., 0] += length[:, None, None] * _STRAIGHT
    return a, da


def pole_rows(x: np.ndarray, edges: np.ndarray, corner: np.ndarray, derivative: bool = False):
    """The row of the consistent ring-area matrix M_ij = int 2 pi r N_i N_j ds of each edge's
    node on the axis i = corner (the pole), over the nodes j of that edge, in the
    configuration x (n_nodes, 2); edges (q, k), corner (q,) in {0, 1}.

    The row sums to the pole's consistent ring area, which is zero for a Q8 corner on the
    axis (int r N_0 ds = 0 where r grows linearly along the edge); the row itself is not:
    M_00 = -M_01 = 2 pi r_1 L / 60 on a straight edge.

    Returns M (q, k) and, if asked, dM[q, j, l, :] = d M_ij / d x_l (q, k, k, 2)."""
    q, k = edges.shape
    _, _, N, dN = edge_rule(k, 3)  # the rule of `ring_areas`: the row sums to its area exactly
    wN, wNN, wNdN = _ring_weights(k)
    X = x[edges]  # (q, k, 2)
    t = dN @ X  # (q, p, 2)
    L = np.sqrt(t[..., 0] ** 2 + t[..., 1] ** 2)  # (q, p)
    r = X[..., 0] @ N.T  # (q, p)
    Ni = N[:, corner].T  # (q, p)
    M = (Ni * r * L) @ wN
    if not derivative:
        return M
    # d(r L) / dx_l = N_l L e_r + r dN_l t / L, as in `ring_areas`: (q, 2, k k), then (q, k, k, 2)
    dM = np.swapaxes((Ni * r / L)[..., None] * t, 1, 2) @ wNdN
    dM[:, 0] += (Ni * L) @ wNN
    return M, dM.reshape(q, 2, k, k).transpose(0, 2, 3, 1)


def edge_heights(mesh: Mesh, edges: np.ndarray) -> np.ndarray:
    """Height of the cell under each boundary edge (m,): the cell's area in the (r, z) plane
    over the edge's chord."""
    local = mesh.element.edge_local_nodes()[:, :2]  # (4, 2) corner pairs of the cell edges
    ends = np.sort(mesh.cells[:, local], axis=2).reshape(-1, 2)  # (4 e, 2)
    n = mesh.n_nodes
    keys = ends[:, 0] * n + ends[:, 1]
    order = np.argsort(keys)
    want = np.sort(edges[:, :2], axis=1)
    cell = order[np.searchsorted(keys[order], want[:, 0] * n + want[:, 1])] // 4
    c = mesh.points[mesh.cells[cell, :4]]  # corners, counter-clockwise
    area = 0.5 * np.abs(
        (c[..., 0] * np.roll(c[..., 1], -1, axis=1) - np.roll(c[..., 0], -1, axis=1) * c[..., 1]).sum(axis=1)
    )
    chord = np.linalg.norm(mesh.points[edges[:, 1]] - mesh.points[edges[:, 0]], axis=1)
    return area / chord
