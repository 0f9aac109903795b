"""Transient heat conduction in the body of revolution (docs/internals.md, Time, temperature and heat):

    rho c dT/dt = div(k grad T)   in the current configuration,
    -k dT/dn = h (T - T_inf)      on convected edges (a film),
    -k dT/dn = h_c (T - T_mould)  at slave nodes in contact with a mould (a conductance),
    insulated elsewhere.

Nodal temperatures T (n,) with bilinear shape functions on every element's four corners (a
Q8's mid-side nodes take the mean of their edge's corners).  Backward Euler over a step dt,
on the geometry x = X + u at the step's end:

    (C / dt + K(x) + H(x)) T' = C / dt T + f(x).

The scheme keeps the discrete maximum principle (no point warmer than the warmest initial or
boundary temperature, none colder than the coldest) by construction: the matrix on the left
is an M-matrix (positive diagonal, no positive entry off it, rows summing to C / dt + H >= 0),
so T' is a weighted mean of T and the boundary temperatures.  The parts:

- C, the heat capacity of the reference configuration (mass is conserved, rho dv = rho0 dV0),
  int rho0 c N N^T dV0 lumped to its row sums, a positive diagonal.  A Q8's serendipity
  functions have negative row sums at the corners: no positive lumping of them is
  consistent (HRZ left an error of 0.8 % of T0 - T_inf on a slab that did not fall with the
  mesh), hence the bilinear field on its corners.
- K(x) = int k grad_x N . grad_x N^T dv, the conduction of the current configuration, with
  the products of the shape functions across each direction of the element lumped (in
  grad N . grad N = sum_ab dN/dxi_a G^ab dN/dxi_b, the factor of dN/dxi_1 along xi_2
  lumped, and the other way round): on a rectangle of any aspect ratio no entry off the
  diagonal is positive (the full bilinear K has positive ones beyond an aspect ratio of
  sqrt 2, and a thin wall's elements are long), and a field that varies along one
  direction of the element only is treated exactly as by the full K.  A skewed element's
  cross terms (G^12) may still leave a positive entry: each such entry is moved to the
  diagonal (K_ij = 0, K_ii += k_ij, K_jj += k_ij: the rows still sum to zero, heat is
  conserved).
- H and f from the films (their edge integrals lumped to the nodes) and the contact
  conductances (per node), a diagonal.  dv = 2 pi r da.

The properties k, rho c are numbers (or, for tables of T, taken at the step's start
temperature per element: lagged, first order in dt like the time integration itself).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp

from .curves import Curve
from .elements import Q4, QUAD_EDGES, edge_rule, gauss_quad, jacobian
from .mesh import Mesh

Property = Callable[[np.ndarray], np.ndarray]  # T (...) -> value (...)

# the reference corners of a Q4 (their signs along xi and eta)
_SN = np.array([-1.0, 1.0, 1.0, -1.0])
_TN = np.array([-1.0, -1.0, 1.0, 1.0])


def constant(value: float) -> Property:
    """A property that does not depend on T."""
    return lambda T: np.full(np.shape(T), float(value))


@dataclass
class Film:
    """Convection on boundary edges (indices into mesh.boundary_edges): film coefficient h,
    ambient temperature `ambient(t)` (a function of the time); `curve`: the load curve that
    ambient follows, if any (its knots are times the steps land on)."""

    edges: np.ndarray
    h: float
    ambient: Callable[[float], float]
    curve: Curve | None = None


@dataclass
class Conductance:
    """Heat flow to a mould through nodes in contact: h_c (T - T_mould(t)) per unit current
    contact area; `contact(state)` gives (nodes (k,), their current ring areas (k,)) of the
    nodes in contact at a model state."""

    h: float
    mould: Callable[[float], float]
    contact: Callable[[object], tuple[np.ndarray, np.ndarray]]
    curve: Curve | None = None  # the load curve the mould's temperature follows, if any


def lumped_products(xi: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The products of the bilinear shape functions' derivatives at the points xi (q, 2),
    each (q, 4, 4): along xi_1 with the functions of xi_2 lumped, along xi_2 with those of
    xi_1 lumped, and the cross terms (consistent); K_e = sum over the points of
    k dv (G^11 A11 + G^22 A22 + G^12 A12)."""
    _, dN = Q4.shape(xi)
    psi = 0.5 * (1.0 + np.outer(xi[:, 1], _TN))  # (q, 4): the factor along xi_2 of N_i
    phi = 0.5 * (1.0 + np.outer(xi[:, 0], _SN))
    same_t = _TN[:, None] == _TN[None, :]
    same_s = _SN[:, None] == _SN[None, :]
    A11 = same_t * np.outer(_SN, _SN) / 4.0 * psi[:, :, None]
    A22 = same_s * np.outer(_TN, _TN) / 4.0 * phi[:, :, None]
    A12 = np.einsum("qi,qj->qij", dN[..., 0], dN[..., 1])
    return A11, A22, A12 + A12.transpose(0, 2, 1)


def without_positive_couplings(K: sp.csr_matrix) -> sp.csr_matrix:
    """K (n, n) symmetric with every positive entry off the diagonal moved onto it (row sums
    and symmetry kept)."""
    K = sp.csr_matrix(K)
    K.sum_duplicates()
    off = sp.triu(K, k=1, format="coo")
    positive = off.data > 0
    if not positive.any():
        return K
    i, j, v = off.row[positive], off.col[positive], off.data[positive]
    n = K.shape[0]
    moved = sp.coo_matrix((np.concatenate([-v, -v, v, v]), (np.r_[i, j, i, j], np.r_[j, i, i, j])), shape=(n, n))
    return (K + moved).tocsr()


class Conduction:
    """The heat equation of a mesh (module docstring): conductivity k, density rho0 and
    specific heat c as functions of T (`constant(v)` for numbers), films and conductances."""

    def __init__(
        self,
        mesh: Mesh,
        conductivity: Property,
        density: Property,
        specific_heat: Property,
        films: list[Film] | None = None,
        conductances: list[Conductance] | None = None,
    ):
        self.mesh = mesh
        self.k, self.rho, self.c = conductivity, density, specific_heat
        self.films = films or []
        self.conductances = conductances or []
        self.n = mesh.n_nodes
        self.cells = mesh.cells[:, :4]  # the corners of every element (a Q8's first four nodes)
        self.active = np.unique(self.cells)  # the nodes the heat equation is solved for
        self.spread = self._mid_sides(mesh)
        self.xi, self.w = gauss_quad(2)
        self.products = lumped_products(self.xi)
        N, _, detJ, Xq = jacobian(Q4, mesh.points[self.cells], self.xi)
        self.N = N  # (q, 4)
        self.dV0 = 2.0 * np.pi * Xq[..., 0] * detJ * self.w  # (e, q)
        self._rows = np.repeat(self.cells, 4, axis=1).ravel()  # (e 16,) the element blocks' places
        self._cols = np.tile(self.cells, (1, 4)).ravel()

    def curves(self) -> list[Curve]:
        """The load curves of the films' ambient and the moulds' temperatures (their knots
        are times at which the boundary temperatures change their rate)."""
        curves = [f.curve for f in self.films] + [c.curve for c in self.conductances]
        return [c for c in curves if c is not None]

    def _mid_sides(self, mesh: Mesh) -> sp.csr_matrix | None:
        """P (n, n): T_all = P T, the corners' values kept and each mid-side node the mean of
        its edge's corners; None without mid-side nodes."""
        if mesh.cells.shape[1] == 4:
            return None
        mids = mesh.cells[:, 4:8].ravel()
        ends = mesh.cells[:, QUAD_EDGES].reshape(-1, 2)
        mids, first = np.unique(mids, return_index=True)
        ends = ends[first]
        rows = np.r_[self.active, mids, mids]
        cols = np.r_[self.active, ends[:, 0], ends[:, 1]]
        vals = np.r_[np.ones(self.active.size), np.full(2 * mids.size, 0.5)]
        return sp.csr_matrix((vals, (rows, cols)), shape=(self.n, self.n))

    def _to_corners(self, values: np.ndarray) -> np.ndarray:
        """Nodal weights (n,) with each mid-side node's share moved half to each of its corners
        (P^T values; the sum kept)."""
        return values if self.spread is None else self.spread.T @ values

    def _assemble(self, Ke: np.ndarray) -> sp.csr_matrix:
        return sp.csr_matrix((Ke.ravel(), (self._rows, self._cols)), shape=(self.n, self.n))

    def element_values(self, T: np.ndarray) -> np.ndarray:
        """T at the elements' quadrature points (e, q) from the nodes' (n,)."""
        return T[self.cells] @ self.N.T

    def capacity(self, T: np.ndarray) -> sp.csr_matrix:
        """C (n, n), the properties at the points' T: int rho0 c N N^T dV0 lumped to its row
        sums, a diagonal (zero at a Q8's mid-side nodes)."""
        Tq = self.element_values(T)
        weight = self.rho(Tq) * self.c(Tq) * self.dV0  # (e, q)
        diagonal = np.bincount(self.cells.ravel(), (weight @ self.N).ravel(), self.n)
        return sp.diags_array(diagonal, format="csr")

    def conduction(self, x: np.ndarray, T: np.ndarray) -> sp.csr_matrix:
        """K(x) (n, n) on the current positions x (n, 2), lumped across each direction of the
        elements and without positive couplings (module docstring)."""
        X = x[self.cells]
        _, _, detj, xq = jacobian(Q4, X, self.xi)
        _, dN = Q4.shape(self.xi)
        J = np.einsum("ekd,qkx->eqdx", X, dN)  # dx_d / dxi_x
        inv = np.linalg.inv(J)
        G = np.einsum("eqad,eqbd->eqab", inv, inv)  # grad N . grad N = dN/dxi_a G^ab dN/dxi_b
        weight = self.k(self.element_values(T)) * 2.0 * np.pi * xq[..., 0] * detj * self.w  # (e, q)
        A11, A22, A12 = self.products
        Ke = (
            np.einsum("eq,qij->eij", weight * G[..., 0, 0], A11)
            + np.einsum("eq,qij->eij", weight * G[..., 1, 1], A22)
            + np.einsum("eq,qij->eij", weight * G[..., 0, 1], A12)
        )
        return without_positive_couplings(self._assemble(Ke))

    def boundary(self, x: np.ndarray, t: float, state=None) -> tuple[sp.csr_matrix, np.ndarray]:
        """H (n, n), a diagonal, and f (n,) of the films and contact conductances at time t on
        x (n, 2): each edge's h int N dA (lumped) at its nodes, each contact node's h_c area."""
        h = np.zeros(self.n)
        f = np.zeros(self.n)
        edges_all = self.mesh.boundary_edges
        for film in self.films:
            edges = edges_all[film.edges]  # (m, en)
            _, wq, Ne, dNe = edge_rule(edges.shape[1], 3)
            xe = x[edges]  # (m, en, 2)
            xs = np.einsum("pk,mkd->mpd", Ne, xe)
            ds = np.linalg.norm(np.einsum("pk,mkd->mpd", dNe, xe), axis=-1)  # (m, p)
            share = np.bincount(edges.ravel(), (film.h * 2.0 * np.pi * xs[..., 0] * ds * wq @ Ne).ravel(), self.n)
            h += share
            f += film.ambient(t) * share
        for cond in self.conductances:
            nodes, area = cond.contact(state)
            h += np.bincount(nodes, cond.h * area, self.n)
            f += np.bincount(nodes, cond.h * area * cond.mould(t), self.n)
        return sp.diags_array(self._to_corners(h), format="csr"), self._to_corners(f)

    def step(self, T: np.ndarray, dt: float, x: np.ndarray, t: float, state=None) -> np.ndarray:
        """T' (n,) at t after a backward Euler step of dt > 0 from T (n,) on the positions x
        (n, 2) (the step's end): (C/dt + K + H) T' = C/dt T + f on the corners, a Q8's
        mid-side nodes the mean of theirs."""
        from scipy.sparse.linalg import spsolve  # here: with scipy.linalg, 70 ms of a run without heat

        if dt <= 0:
            return T.copy()
        C = self.capacity(T) / dt
        H, f = self.boundary(x, t, state)
        A = (C + self.conduction(x, T) + H).tocsr()[self.active][:, self.active]
        out = np.array(T, float)
        out[self.active] = spsolve(A.tocsc(), (C @ T + f)[self.active])
        return out if self.spread is None else self.spread @ out

    def heat_content(self, T: np.ndarray, T_ref: float = 0.0) -> float:
        """int rho0 c (T - T_ref) dV0 (constant properties: the stored heat)."""
        return float((self.capacity(T) @ (T - T_ref)).sum())
