"""Vectorized internal force and consistent tangent over all elements and quadrature points.

f_int,e = sum_q G_q^T P_q dV_q and K_e = sum_q G_q^T A_q G_q dV_q (eqs. 17-30).  G and dV are
computed once in the reference configuration (total Lagrangian).
"""

from __future__ import annotations

import numpy as np

from .elements import gradient_operator
from .materials import InvertedElementError, deformation_gradient
from .mesh import Mesh


def element_dofs(cells: np.ndarray, dofs_per_node: int) -> np.ndarray:
    """Full dof numbers (e, k * dofs_per_node) of the cells, node by node."""
    return (cells[:, :, None] * dofs_per_node + np.arange(dofs_per_node)).reshape(len(cells), -1)


class SolidAssembly:
    """The solid's contribution: internal forces and material tangent of every element."""

    def __init__(self, mesh: Mesh, material):
        self.mesh = mesh
        self.material = material
        self.G, self.dV = gradient_operator(mesh.element, mesh.points[mesh.cells])
        self.dofs = element_dofs(mesh.cells, mesh.element.dofs_per_node)
        e, q, _, nd = self.G.shape
        self._GdV_T = np.ascontiguousarray(
            (self.G * self.dV[..., None, None]).transpose(0, 3, 1, 2).reshape(e, nd, q * 5))

    def gradient(self, u_full: np.ndarray) -> np.ndarray:
        """Deformation gradient components x = F (e, q, 5) (eq. 6)."""
        ue = u_full[self.dofs]
        return deformation_gradient(np.einsum("eqik,ek->eqi", self.G, ue))

    def check_inverted(self, x: np.ndarray) -> None:
        J = x[..., 4] * (x[..., 0] * x[..., 3] - x[..., 1] * x[..., 2])
        bad = ~(J > 0).all(axis=1)
        if bad.any():
            raise InvertedElementError(np.flatnonzero(bad))

    def evaluate(self, u_full: np.ndarray, tangent: bool = True):
        """Element internal forces fe (e, nd) and, if asked, element tangents Ke (e, nd, nd)."""
        x = self.gradient(u_full)
        self.check_inverted(x)
        e, q, _, nd = self.G.shape
        if not tangent:
            P = self.material.stress(x)
            return np.einsum("ekp,ep->ek", self._GdV_T, P.reshape(e, q * 5)), None
        P, A = self.material.stress_tangent(x)
        fe = np.einsum("ekp,ep->ek", self._GdV_T, P.reshape(e, q * 5))
        AG = np.matmul(A, self.G).reshape(e, q * 5, nd)
        Ke = np.matmul(self._GdV_T, AG)
        return fe, Ke
