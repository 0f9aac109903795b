"""Axisymmetric elements: shape functions, Gauss rules and the gradient operator G.

Every element supplies, at each quadrature point q, the operator G_q (5 x ndof_e) with
g_q = G_q u_e, g = (U,R, U,Z, W,R, W,Z, U/R), and the reference volume weight
dV_q = 2 pi R_q detJ_q w_q (eq. 28).  The internal force and tangent of any material are
then f_e = sum_q G_q^T P_q dV_q and K_e = sum_q G_q^T A_q G_q dV_q (eqs. 17-30 in compact form).
"""

from __future__ import annotations

import functools
from dataclasses import dataclass

import numpy as np

# node pairs of the four edges of a quadrilateral, counter-clockwise, with Q8 mid-side nodes
QUAD_EDGES = np.array([[0, 1], [1, 2], [2, 3], [3, 0]])
Q8_EDGE_MIDS = np.array([4, 5, 6, 7])


def _frozen(a: np.ndarray, b: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    a.flags.writeable = False
    b.flags.writeable = False
    return a, b


@functools.cache
def gauss_1d(n: int) -> tuple[np.ndarray, np.ndarray]:
    """Gauss-Legendre points and weights on [-1, 1].  Built once per n (numpy's leggauss
    costs ~0.4 ms, and contact asks for the rule at every evaluation): the arrays are shared
    and read-only; copy them to change them."""
    return _frozen(*np.polynomial.legendre.leggauss(int(n)))


@functools.cache
def gauss_quad(n: int) -> tuple[np.ndarray, np.ndarray]:
    """n x n Gauss rule on the square [-1, 1]^2: points (n*n, 2) and weights (n*n,).  Built
    once per n, shared and read-only, as `gauss_1d`."""
    x, w = gauss_1d(n)
    xi, eta = np.meshgrid(x, x, indexing="xy")
    return _frozen(np.column_stack([xi.ravel(), eta.ravel()]), np.outer(w, w).ravel())


def q4_shape(xi: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Bilinear shape functions (eq. 5) N (p, 4) and derivatives dN/dxi (p, 4, 2)."""
    s, t = xi[:, 0], xi[:, 1]
    sn = np.array([-1.0, 1.0, 1.0, -1.0])
    tn = np.array([-1.0, -1.0, 1.0, 1.0])
    N = 0.25 * (1 + np.outer(s, sn)) * (1 + np.outer(t, tn))
    dN = np.empty((len(s), 4, 2))
    dN[:, :, 0] = 0.25 * sn * (1 + np.outer(t, tn))
    dN[:, :, 1] = 0.25 * tn * (1 + np.outer(s, sn))
    return N, dN


def q8_shape(xi: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Serendipity shape functions N (p, 8) and dN/dxi (p, 8, 2); nodes 4-7 mid-side."""
    s, t = xi[:, [0]], xi[:, [1]]
    sc = np.array([-1.0, 1.0, 1.0, -1.0])
    tc = np.array([-1.0, -1.0, 1.0, 1.0])
    N = np.empty((len(xi), 8))
    dN = np.empty((len(xi), 8, 2))
    # corners
    N[:, :4] = 0.25 * (1 + s * sc) * (1 + t * tc) * (s * sc + t * tc - 1)
    dN[:, :4, 0] = 0.25 * sc * (1 + t * tc) * (2 * s * sc + t * tc)
    dN[:, :4, 1] = 0.25 * tc * (1 + s * sc) * (s * sc + 2 * t * tc)
    # mid-side nodes 4 (t=-1), 6 (t=+1): xi varies; 5 (s=+1), 7 (s=-1): eta varies
    for k, tt in ((4, -1.0), (6, 1.0)):
        N[:, k] = 0.5 * (1 - s[:, 0] ** 2) * (1 + t[:, 0] * tt)
        dN[:, k, 0] = -s[:, 0] * (1 + t[:, 0] * tt)
        dN[:, k, 1] = 0.5 * (1 - s[:, 0] ** 2) * tt
    for k, ss in ((5, 1.0), (7, -1.0)):
        N[:, k] = 0.5 * (1 - t[:, 0] ** 2) * (1 + s[:, 0] * ss)
        dN[:, k, 0] = 0.5 * (1 - t[:, 0] ** 2) * ss
        dN[:, k, 1] = -t[:, 0] * (1 + s[:, 0] * ss)
    return N, dN


@dataclass(frozen=True)
class ElementKind:
    """An element family: its nodes, dofs per node, shape functions and Gauss rule."""

    name: str
    nodes: int  # nodes per cell
    dofs_per_node: int  # 2 (U, W) or 3 (U, W, theta)
    gauss: int  # n of the n x n Gauss rule
    edge_nodes: int  # nodes per edge (2 or 3)

    @property
    def dofs(self) -> int:
        return self.nodes * self.dofs_per_node

    def shape(self, xi: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        return q8_shape(xi) if self.nodes == 8 else q4_shape(xi)

    def edge_local_nodes(self) -> np.ndarray:
        """Local node numbers of each of the 4 edges, (4, edge_nodes), counter-clockwise."""
        if self.nodes == 8:
            return np.column_stack([QUAD_EDGES, Q8_EDGE_MIDS])
        return QUAD_EDGES.copy()


Q4 = ElementKind("q4", nodes=4, dofs_per_node=2, gauss=2, edge_nodes=2)
Q8 = ElementKind("q8", nodes=8, dofs_per_node=2, gauss=3, edge_nodes=3)
SFR = ElementKind("sfr", nodes=4, dofs_per_node=3, gauss=2, edge_nodes=2)
ELEMENTS = {"q4": Q4, "q8": Q8, "sfr": SFR}


def jacobian(kind: ElementKind, X: np.ndarray, xi: np.ndarray):
    """Reference Jacobian at points xi for cells with nodal coordinates X (e, k, 2).

    Returns N (p, k), dN/dX (e, p, k, 2), detJ (e, p) and the point coordinates (e, p, 2).
    """
    N, dN = kind.shape(xi)
    J = np.einsum("ekd,pkx->epdx", X, dN)  # J[d, x] = dX_d / dxi_x
    detJ = J[..., 0, 0] * J[..., 1, 1] - J[..., 0, 1] * J[..., 1, 0]
    inv = np.empty_like(J)
    with np.errstate(divide="ignore", invalid="ignore"):
        inv[..., 0, 0] = J[..., 1, 1] / detJ
        inv[..., 1, 1] = J[..., 0, 0] / detJ
        inv[..., 0, 1] = -J[..., 0, 1] / detJ
        inv[..., 1, 0] = -J[..., 1, 0] / detJ
    dNdX = np.einsum("pkx,epxd->epkd", dN, inv)
    Xq = np.einsum("pk,ekd->epd", N, X)
    return N, dNdX, detJ, Xq


def gradient_operator(
    kind: ElementKind, X: np.ndarray, points: tuple[np.ndarray, np.ndarray] | None = None
) -> tuple[np.ndarray, np.ndarray]:
    """G (e, q, 5, ndof_e) with g = G u_e, and dV = 2 pi R detJ w (e, q) (eq. 28), at the
    element's Gauss points, or at the points (xi (q, 2), w (q,)) given.

    Element dofs are ordered node by node: (U, W) or, for SFR, (U, W, theta) (eq. 4).  At a
    point on the axis (R = 0) the row of U/R is not finite.
    """
    xi, w = gauss_quad(kind.gauss) if points is None else points
    N, dNdX, detJ, Xq = jacobian(kind, X, xi)
    e, q, k = dNdX.shape[:3]
    R = Xq[..., 0]
    NR, NZ = dNdX[..., 0], dNdX[..., 1]
    Nq = np.broadcast_to(N, (e, q, k))
    G = np.zeros((e, q, 5, k, kind.dofs_per_node))
    G[:, :, 0, :, 0] = NR
    G[:, :, 1, :, 0] = NZ
    G[:, :, 2, :, 1] = NR
    G[:, :, 3, :, 1] = NZ
    G[:, :, 4, :, 0] = Nq / R[..., None]
    if kind.dofs_per_node == 3:
        # space fibre rotation (eqs. 2-4): U += -N_i theta_i (Z - Z_i), W += N_i theta_i (R - R_i)
        dR = R[..., None] - X[:, None, :, 0]  # R - R_i  (e, q, k)
        dZ = Xq[..., 1][..., None] - X[:, None, :, 1]  # Z - Z_i
        G[:, :, 0, :, 2] = -NR * dZ
        G[:, :, 1, :, 2] = -(NZ * dZ + Nq)
        G[:, :, 2, :, 2] = NR * dR + Nq
        G[:, :, 3, :, 2] = NZ * dR
        G[:, :, 4, :, 2] = -Nq * dZ / R[..., None]
    dV = 2.0 * np.pi * R * detJ * w
    return G.reshape(e, q, 5, k * kind.dofs_per_node), dV


def node_coordinates(kind: ElementKind) -> np.ndarray:
    """The element's nodes in its reference square, (k, 2): corners, then Q8 mid-sides."""
    corners = np.array([[-1.0, -1.0], [1.0, -1.0], [1.0, 1.0], [-1.0, 1.0]])
    if kind.nodes == 8:
        return np.vstack([corners, [[0.0, -1.0], [1.0, 0.0], [0.0, 1.0], [-1.0, 0.0]]])
    return corners


def edge_shape(n: int, s: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """1D shape functions on an edge (ends first, then middle) and their derivatives."""
    if n == 2:
        N = np.column_stack([(1 - s) / 2, (1 + s) / 2])
        dN = np.column_stack([-0.5 * np.ones_like(s), 0.5 * np.ones_like(s)])
    else:
        N = np.column_stack([s * (s - 1) / 2, s * (s + 1) / 2, 1 - s**2])
        dN = np.column_stack([s - 0.5, s + 0.5, -2 * s])
    return N, dN


@functools.cache
def edge_rule(edge_nodes: int, npoints: int = 3) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """The npoints Gauss rule on an edge of edge_nodes nodes with its shape functions there:
    points s (p,), weights w (p,), N (p, k) and dN/ds (p, k), exactly
    `gauss_1d(npoints)` and `edge_shape(edge_nodes, s)`; built once, shared and read-only."""
    s, w = gauss_1d(npoints)
    return (s, w, *_frozen(*edge_shape(int(edge_nodes), s)))


def edge_interpolation(kind: ElementKind, X: np.ndarray, npoints: int = 3):
    """Displacement interpolation along edges, as the element itself interpolates it.

    X (m, n_edge, 2) are the reference coordinates of the edge nodes (ends first).  Returns
    the reference point coordinates Xs (m, p, 2) and tangents dXs (m, p, 2), the operators
    H (m, p, 2, ndof_edge) and dH = dH/ds with u(s) = H u_edge, and the weights (p,).
    For SFR the theta bubble is part of H: u += theta_i e_y x (X - X_i) (eq. 3).
    """
    s, w = gauss_1d(npoints)
    N, dN = edge_shape(X.shape[1], s)
    Xs = np.einsum("pk,mkd->mpd", N, X)
    dXs = np.einsum("pk,mkd->mpd", dN, X)
    m, p, k = X.shape[0], len(s), X.shape[1]
    H = np.zeros((m, p, 2, k, kind.dofs_per_node))
    dH = np.zeros_like(H)
    H[:, :, 0, :, 0] = N
    H[:, :, 1, :, 1] = N
    dH[:, :, 0, :, 0] = dN
    dH[:, :, 1, :, 1] = dN
    if kind.dofs_per_node == 3:
        dR = Xs[:, :, None, 0] - X[:, None, :, 0]
        dZ = Xs[:, :, None, 1] - X[:, None, :, 1]
        H[:, :, 0, :, 2] = -N * dZ
        H[:, :, 1, :, 2] = N * dR
        dH[:, :, 0, :, 2] = -(dN * dZ + N * dXs[:, :, None, 1])
        dH[:, :, 1, :, 2] = dN * dR + N * dXs[:, :, None, 0]
    nd = k * kind.dofs_per_node
    return Xs, dXs, H.reshape(m, p, 2, nd), dH.reshape(m, p, 2, nd), w
