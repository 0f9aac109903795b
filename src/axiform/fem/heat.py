"""Transient heat conduction in the body of revolution (docs/internals.md, Time, temperature and heat):

    rho c dT/dt = div(k grad T)   in the current configuration,
    -k dT/dn = h (T - T_inf)      on convected edges (a film),
    -k dT/dn = h_c (T - T_mould)  at slave nodes in contact with a mould (a conductance),
    insulated elsewhere.

Nodal temperatures T (n,) with the element's shape functions (SFR: its Q4 ones).  Backward
Euler over a step dt, on the geometry x = X + u at the step's end:

    (C / dt + K(x) + H(x)) T' = C / dt T + f(x),

C the heat capacity of the reference configuration (mass is conserved, rho dv = rho0 dV0),
int rho0 c N N^T dV0, lumped (row sums) for the four-node elements: a consistent C under
backward Euler with steps much shorter than an element's diffusion time h^2 / alpha (a
mould touching a hot sheet for a tenth of a second) overshoots, the temperature beyond its
initial and boundary values, while the lumped one keeps it between them.  Q8 keeps the
consistent C: its lumped one (HRZ; row sums are negative at the corners) left an error of
0.8 % of T0 - T_inf on the slab that did not fall with the mesh (12 to 40 elements), against
0.1 % for Q4 lumped and 0.05 % for Q8 consistent, K(x) = int k grad_x N . grad_x N^T dv the conduction of
the current configuration, H and f from the films and contact conductances.  dv = 2 pi r da.
The properties k, rho c are numbers (or, for tables of T, taken at the step's start
temperature per element: lagged, first order in dt like the time integration itself).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp

from .elements import edge_rule, gauss_quad, jacobian
from .mesh import Mesh

Property = Callable[[np.ndarray], np.ndarray]  # T (...) -> value (...)


def constant(value: float) -> Property:
    """A property that does not depend on T."""
    return lambda T: np.full(np.shape(T), float(value))


@dataclass
class Film:
    """Convection on boundary edges (indices into mesh.boundary_edges): film coefficient h,
    ambient temperature `ambient(t)` (a function of the time)."""

    edges: np.ndarray
    h: float
    ambient: Callable[[float], float]


@dataclass
class Conductance:
    """Heat flow to a mould through nodes in contact: h_c (T - T_mould(t)) per unit current
    contact area; `contact(state)` gives (nodes (k,), their current ring areas (k,)) of the
    nodes in contact at a model state."""

    h: float
    mould: Callable[[float], float]
    contact: Callable[[object], tuple[np.ndarray, np.ndarray]]


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
        kind = mesh.element
        self.cells = mesh.cells
        self.xi, self.w = gauss_quad(kind.gauss)
        N, _, detJ, Xq = jacobian(kind, mesh.points[mesh.cells], self.xi)
        self.N = N  # (q, k)
        self.dV0 = 2.0 * np.pi * Xq[..., 0] * detJ * self.w  # (e, q)
        e, k = mesh.cells.shape
        self._rows = np.repeat(mesh.cells, k, axis=1).ravel()  # (e k k,) the element blocks' places
        self._cols = np.tile(mesh.cells, (1, k)).ravel()
        self.n = mesh.n_nodes

    def _assemble(self, Ke: np.ndarray) -> sp.csr_matrix:
        return sp.csr_matrix((Ke.ravel(), (self._rows, self._cols)), shape=(self.n, self.n))

    def element_values(self, T: np.ndarray) -> np.ndarray:
        """T at the elements' quadrature points (e, q) from the nodes' (n,)."""
        return T[self.cells] @ self.N.T

    def capacity(self, T: np.ndarray) -> sp.csr_matrix:
        """C (n, n), the properties at the points' T: int rho0 c N N^T dV0, lumped to its row
        sums (a diagonal) for the four-node elements (module docstring)."""
        Tq = self.element_values(T)
        weight = self.rho(Tq) * self.c(Tq) * self.dV0  # (e, q)
        if self.N.shape[1] == 4:  # row sums of N N^T: N, the shape functions summing to 1
            diagonal = np.bincount(self.cells.ravel(), (weight @ self.N).ravel(), self.n)
            return sp.diags_array(diagonal, format="csr")
        return self._assemble(np.einsum("eq,qi,qj->eij", weight, self.N, self.N))

    def conduction(self, x: np.ndarray, T: np.ndarray) -> sp.csr_matrix:
        """K(x) = int k grad_x N . grad_x N^T dv (n, n) on the current positions x (n, 2)."""
        _, dNdx, detj, xq = jacobian(self.mesh.element, x[self.cells], self.xi)
        dv = 2.0 * np.pi * xq[..., 0] * detj * self.w  # (e, q)
        weight = self.k(self.element_values(T)) * dv
        Ke = np.einsum("eq,eqid,eqjd->eij", weight, dNdx, dNdx)
        return self._assemble(Ke)

    def boundary(self, x: np.ndarray, t: float, state=None) -> tuple[sp.csr_matrix, np.ndarray]:
        """H (n, n) and f (n,) of the films and contact conductances at time t on x (n, 2)."""
        rows, cols, vals = [], [], []
        f = np.zeros(self.n)
        edges_all = self.mesh.boundary_edges
        for film in self.films:
            edges = edges_all[film.edges]  # (m, en)
            _, wq, Ne, dNe = edge_rule(edges.shape[1], 3)
            xe = x[edges]  # (m, en, 2)
            xs = np.einsum("pk,mkd->mpd", Ne, xe)
            ds = np.linalg.norm(np.einsum("pk,mkd->mpd", dNe, xe), axis=-1)  # (m, p)
            da = film.h * 2.0 * np.pi * xs[..., 0] * ds * wq  # (m, p)
            He = np.einsum("mp,pi,pj->mij", da, Ne, Ne)
            k = edges.shape[1]
            rows.append(np.repeat(edges, k, axis=1).ravel())
            cols.append(np.tile(edges, (1, k)).ravel())
            vals.append(He.ravel())
            f += np.bincount(edges.ravel(), (film.ambient(t) * da @ Ne).ravel(), self.n)
        for cond in self.conductances:
            nodes, area = cond.contact(state)
            rows.append(nodes)
            cols.append(nodes)
            vals.append(cond.h * area)
            f += np.bincount(nodes, cond.h * area * cond.mould(t), self.n)
        if not rows:
            return sp.csr_matrix((self.n, self.n)), f
        H = sp.csr_matrix((np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))), shape=(self.n, self.n))
        return H, f

    def step(self, T: np.ndarray, dt: float, x: np.ndarray, t: float, state=None) -> np.ndarray:
        """T' (n,) at t after a backward Euler step of dt > 0 from T (n,) on the positions x
        (n, 2) (the step's end): (C/dt + K + H) T' = C/dt T + f."""
        from scipy.sparse.linalg import spsolve  # here: with scipy.linalg, 70 ms of a run without heat

        if dt <= 0:
            return T.copy()
        C = self.capacity(T) / dt
        H, f = self.boundary(x, t, state)
        A = (C + self.conduction(x, T) + H).tocsc()
        return spsolve(A, C @ T + f)

    def heat_content(self, T: np.ndarray, T_ref: float = 0.0) -> float:
        """int rho0 c (T - T_ref) dV0 (constant properties: the stored heat)."""
        return float((self.capacity(T) @ (T - T_ref)).sum())
