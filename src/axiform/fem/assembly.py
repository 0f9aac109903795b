"""Vectorized internal force and consistent tangent over all elements and quadrature points.

f_int,e = sum_q G_q^T P_q dV_q and K_e = sum_q G_q^T A_q G_q dV_q (eqs. 17-30).  G and dV are
computed once in the reference configuration (total Lagrangian).
"""

from __future__ import annotations

import numpy as np

from ..materials import InvertedElementError, deformation_gradient
from ..materials.base import add_volumetric
from ..materials.kinematics import from_rows, to_rows
from ..materials.viscoelastic import Memory
from .elements import gauss_quad, gradient_operator
from .mesh import Mesh


def element_dofs(cells: np.ndarray, dofs_per_node: int) -> np.ndarray:
    """Full dof numbers (e, k * dofs_per_node) of the cells, node by node."""
    return (cells[:, :, None] * dofs_per_node + np.arange(dofs_per_node)).reshape(len(cells), -1)


class SolidAssembly:
    """The solid's contribution: internal forces and material tangent of every element,
    evaluated in chunks of elements so that the temporaries stay in cache."""

    chunk = 2048

    def __init__(self, mesh: Mesh, material):
        self.mesh = mesh
        self.material = material
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
        kind = self.mesh.element
        N = kind.shape(gauss_quad(kind.gauss)[0])[0]  # (q, k)
        return nodal[self.mesh.cells] @ N.T

    def law(self, sl: slice = slice(None), temperature: np.ndarray | None = None):
        """The law at the points of the elements sl: the material, or where its constants are
        tables of T (materials.temperature) the law at the points' temperatures (temperature:
        (e, q) of all elements), one value per point in the order of x[sl].reshape(-1, 5)."""
        if temperature is None or not hasattr(self.material, "at"):
            return self.material
        return self.material.at(temperature[sl])

    def stress(
        self,
        x: np.ndarray,
        sl: slice = slice(None),
        temperature: np.ndarray | None = None,
        memory: Memory | None = None,
    ) -> np.ndarray:
        """First Piola-Kirchhoff stress P (e, q, 5) at the gradients x of the elements sl
        (temperature: (e, q) at the points of all elements, or None; memory: a law's history
        over a step, applied as `evaluate` applies it)."""
        law = self.law(sl, temperature)
        if memory is None:
            return law.stress(x)
        xt, shape = to_rows(x)
        P = law.stress_rows(xt, 0.0, False)[0]
        memory.add_rows(sl, xt, P, None)
        add_volumetric(xt, law.kappa, P, None)
        return from_rows(P, None, shape)[0]

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
        memory: Memory | None = None,
        temperature: np.ndarray | None = None,
    ):
        """Element internal forces fe (e, nd) and, if asked, element tangents Ke (e, nd, nd),
        written into out = (fe, Ke) when given (from `buffers`) and returned.  memory: the
        step of a law with a history per quadrature point (materials.viscoelastic.Memory),
        whose trial arrays are filled here; temperature: (e, q) at the points (the law's
        constants that are tables of T), or None."""
        e, q, _, nd = self.G.shape
        fe, Ke = out if out is not None else self.buffers(tangent)
        for sl, x in self.chunks(u_full):
            m = sl.stop - sl.start
            GdV_T = self._GdV[sl].transpose(0, 2, 1)
            law = self.law(sl, temperature)
            if memory is not None:  # the law's parts apart: the Prony series acts on the isochoric one
                xt, shape = to_rows(x)
                P, A = law.stress_rows(xt, 0.0, tangent)
                memory.add_rows(sl, xt, P, A)
                add_volumetric(xt, law.kappa, P, A)
                P, A = from_rows(P, A, shape)
            elif tangent:
                P, A = law.stress_tangent(x)
            else:
                P, A = law.stress(x), None
            if tangent:
                AG = np.matmul(A, self.G[sl]).reshape(m, q * 5, nd)
                np.matmul(GdV_T, AG, out=Ke[sl])
            np.matmul(GdV_T, P.reshape(m, q * 5, 1), out=fe[sl, :, None])
        return fe, Ke
