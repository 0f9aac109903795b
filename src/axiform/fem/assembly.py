"""Vectorized internal force and consistent tangent over all elements and quadrature points.

f_int,e = sum_q G_q^T P_q dV_q and K_e = sum_q G_q^T A_q G_q dV_q (eqs. 17-30).  G and dV are
computed once in the reference configuration (total Lagrangian).
"""

from __future__ import annotations

import numpy as np

from ..materials import InvertedElementError, deformation_gradient
from ..materials.protocol import State, as_law
from .elements import gauss_quad, gradient_operator
from .mesh import Mesh


def point_values(mesh: Mesh, nodal: np.ndarray) -> np.ndarray:
    """A nodal field (n,) at the quadrature points (e, q), by the element's shape functions
    (SFR: its Q4 ones; a Q8's quadratic ones may leave the range of the nodes' values)."""
    kind = mesh.element
    N = kind.shape(gauss_quad(kind.gauss)[0])[0]  # (q, k)
    return nodal[mesh.cells] @ N.T


def element_dofs(cells: np.ndarray, dofs_per_node: int) -> np.ndarray:
    """Full dof numbers (e, k * dofs_per_node) of the cells, node by node."""
    return (cells[:, :, None] * dofs_per_node + np.arange(dofs_per_node)).reshape(len(cells), -1)


class SolidAssembly:
    """The solid's contribution: internal forces and material tangent of every element,
    evaluated in chunks of elements so that the temporaries stay in cache.  The material (any
    law; shift: the shift a_T of its rates, or None) is asked through materials.protocol alone."""

    chunk = 2048

    def __init__(self, mesh: Mesh, material, shift=None):
        self.mesh = mesh
        self.law = as_law(material, shift)  # materials.protocol: the one call for P, A and the state
        self.G, self.dV = gradient_operator(mesh.element, mesh.points[mesh.cells])
        self.dofs = element_dofs(mesh.cells, mesh.element.dofs_per_node)
        e, q, _, nd = self.G.shape
        self._G2 = self.G.reshape(e, q * 5, nd)  # g = G2 u_e, all points at once
        self._identity = np.tile(deformation_gradient(np.zeros(5)), q)[:, None]  # (5q, 1)
        # G dV stored (e, 5q, nd) and used transposed: matmul runs G^T (A G) faster on it
        self._GdV = np.ascontiguousarray((self.G * self.dV[..., None, None]).reshape(e, q * 5, nd))

    def gradient(self, u_full: np.ndarray) -> np.ndarray:
        """Deformation gradient components x = F (e, q, 5) (eq. 6)."""
        e, q, _, nd = self.G.shape
        ue = u_full[self.dofs]
        return deformation_gradient(np.matmul(self._G2, ue[:, :, None]).reshape(e, q, 5))

    def point_values(self, nodal: np.ndarray) -> np.ndarray:
        """A nodal field (n,) at the quadrature points (e, q), by the element's shape
        functions (SFR: its Q4 ones)."""
        return point_values(self.mesh, nodal)

    def stress(
        self,
        x: np.ndarray,
        sl: slice = slice(None),
        temperature: np.ndarray | None = None,
        state: State | None = None,
    ) -> np.ndarray:
        """First Piola-Kirchhoff stress P (e, q, 5) at the gradients x of the elements sl at the
        committed state `state` (arrays (e, q, ...) of all elements; None: the initial one): the
        law's update over a step of no length (temperature: (e, q) at the points of all
        elements, or None)."""
        held = self.initial_state(temperature) if state is None else state
        T = None if temperature is None else temperature[sl]
        return self.law.update(x, {k: v[sl] for k, v in held.items()}, 0.0, T, tangent=False)[0]

    def initial_state(self, temperature: np.ndarray | None = None) -> State:
        """The law's state before the first step at every quadrature point, arrays (e, q, ...);
        temperature: (e, q) the points' initial temperatures, or None."""
        return self.law.initial_state(self.dV.shape, temperature)

    @staticmethod
    def check_inverted(x: np.ndarray, offset: int = 0) -> None:
        J = x[..., 4] * (x[..., 0] * x[..., 3] - x[..., 1] * x[..., 2])
        if (J > 0).all():
            return
        raise InvertedElementError(np.flatnonzero(~(J > 0).all(axis=1)) + offset)

    def chunks(self, u_full: np.ndarray):
        """The elements in chunks: (slice of the elements, their gradients x (m, q, 5)), each
        checked for inverted quadrature points (InvertedElementError names the elements)."""
        e, q, _, _ = self.G.shape
        for start in range(0, e, self.chunk):
            sl = slice(start, min(start + self.chunk, e))
            ue = u_full[self.dofs[sl]]
            x = np.matmul(self._G2[sl], ue[:, :, None])  # the displacement gradient g (m, 5q, 1)
            x += self._identity  # F = I + g (eq. 6)
            x = x.reshape(sl.stop - start, q, 5)
            self.check_inverted(x, start)
            yield sl, x

    def buffers(self, tangent: bool = True) -> tuple[np.ndarray, np.ndarray | None]:
        """Arrays fe (e, nd) and Ke (e, nd, nd) to pass as `out` to evaluate, again and again:
        a Ke allocated afresh on every call is mapped and faulted in anew by the kernel (at
        1e5 Q8 elements 205 MB, 0.1 s a call; benchmarks/README.md § 1)."""
        e, _, _, nd = self.G.shape
        return np.empty((e, nd)), np.empty((e, nd, nd)) if tangent else None

    def evaluate(
        self,
        u_full: np.ndarray,
        tangent: bool = True,
        out: tuple | None = None,
        state: State | None = None,
        dt: float = 0.0,
        temperature: np.ndarray | None = None,
    ) -> tuple[np.ndarray, np.ndarray | None]:
        """Element internal forces fe (e, nd) and, if asked, element tangents Ke (e, nd, nd) of a
        step (update, whose trial state is left out)."""
        fe, Ke, _ = self.update(u_full, tangent, out, state, dt, temperature)
        return fe, Ke

    def update(
        self,
        u_full: np.ndarray,
        tangent: bool = True,
        out: tuple | None = None,
        state: State | None = None,
        dt: float = 0.0,
        temperature: np.ndarray | None = None,
    ) -> tuple[np.ndarray, np.ndarray | None, State]:
        """Element internal forces fe (e, nd), if asked element tangents Ke (e, nd, nd), written
        into out = (fe, Ke) when given (from `buffers`) and returned, and the law's trial state
        (arrays (e, q, ...)) after a step dt from the committed state `state` (arrays (e, q, ...);
        None: the initial one), at the points' temperatures `temperature` (e, q) or None: the
        law's update (materials.protocol) chunk by chunk of elements."""
        e, q, _, nd = self.G.shape
        fe, Ke = out if out is not None else self.buffers(tangent)
        held = self.initial_state(temperature) if state is None else state
        trial: State = {}
        for sl, x in self.chunks(u_full):
            m = sl.stop - sl.start
            T = None if temperature is None else temperature[sl]
            P, A, part = self.law.update(x, {k: v[sl] for k, v in held.items()}, dt, T, tangent=tangent)
            gather(trial, part, sl, e)
            GdV_T = self._GdV[sl].transpose(0, 2, 1)
            if tangent:
                AG = np.matmul(A, self.G[sl]).reshape(m, q * 5, nd)
                np.matmul(GdV_T, AG, out=Ke[sl])
            np.matmul(GdV_T, P.reshape(m, q * 5, 1), out=fe[sl, :, None])
        return fe, Ke, trial


def gather(trial: State, part: State, sl: slice, e: int) -> None:
    """Place a chunk's trial state `part` (arrays (m, q, ...) of the elements sl) into `trial`
    (arrays (e, q, ...) of all e elements, made at the first chunk)."""
    for k, v in part.items():
        if k not in trial:
            trial[k] = np.empty((e, *v.shape[1:]), v.dtype)
        trial[k][sl] = v
