"""Gravity: the body's own weight as a term of the residual (model.protocol.Term).

A body force rho g e_z per unit reference volume, g = value x f(t) the acceleration along z
(the axis vertical; negative: downwards), rho the mass per unit reference volume: a dead
load (the mass of each piece of the body is that of its reference volume, wherever it
goes).  Its consistent nodal forces on the revolved element, on the uz dof of node i,

    F_i = sum_e sum_q rho g N_i(xi_q) dV_q,    dV_q = 2 pi R_q detJ_q w_q,

with N the element's shape functions (SFR: its Q4 ones; the fibre rotations get nothing),
and R = -f(t) F, dR/dt = -f'(t) F; no stiffness, no history.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from ..fem.curves import PROPORTIONAL, Curve
from ..fem.elements import gauss_quad, jacobian
from ..fem.mesh import Mesh
from .protocol import Contribution, EvaluationContext, assemble, stateless


class GravityTerm:
    """The weight of the body of `mesh` under the acceleration g x f(t) along z (f = `curve`,
    f(t) = t without one), density rho (mass per unit reference volume).  `force`: F, the
    nodal forces at f = 1 (n_full,)."""

    blocks: tuple[np.ndarray, ...] = ()
    border: tuple[tuple[np.ndarray, bool], ...] = ()

    def __init__(self, mesh: Mesh, g: float, density: float, curve: Curve = PROPORTIONAL):
        kind = mesh.element
        xi, w = gauss_quad(kind.gauss)
        N, _, detJ, Xq = jacobian(kind, mesh.points[mesh.cells], xi)  # N (q, k); detJ, R (e, q)
        dV = 2.0 * np.pi * Xq[..., 0] * detJ * w  # (e, q)
        nodal = float(density) * float(g) * (dV @ N)  # (e, k): sum_q rho g N_k dV_q
        dpn = kind.dofs_per_node
        self.n_full = mesh.n_nodes * dpn
        self.force = assemble(mesh.cells * dpn + 1, nodal, self.n_full)
        self.curve = curve

    def initial_state(self) -> None:
        return None

    def restore(self, saved: Any) -> None:
        stateless(saved, "gravity")

    def curves(self) -> tuple[Curve, ...]:
        return (self.curve,)

    def evaluate(self, u: np.ndarray, t: float, state: None, context: EvaluationContext) -> Contribution:
        f, df = self.curve(t), self.curve.slope(t)
        if f == 0.0 and df == 0.0:
            return Contribution()
        load = f * self.force
        return Contribution(-load, -df * self.force, load=load)
