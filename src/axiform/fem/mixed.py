"""Mixed (u-p-J_bar) elements: the three-field variation of Simo, Taylor and Pister with the
pressure and the dilatation condensed on each element.

The strain energy is split W = W_iso(F_bar) + U(J), U(J) = kappa/2 (J - 1)^2 (eqs. 11-12).
In the mixed element the volumetric part is evaluated with an element-wise dilatation
J_bar instead of J:

    Pi(u) = int W_iso(F) dV + int U(J_bar) dV,     J_bar = the L2 projection of J = det F
                                                  on the element's pressure space.

With the pressure space spanned by N_p (np functions per element, constant included),
M = int N_p N_p^T dV and h = int N_p J dV give J_bar = N_p . M^-1 h, and the pressure
p = U'(J_bar) = kappa (J_bar - 1) (the condensed Lagrange multiplier, positive in tension).
Then (dJ = dJ/dF, H_J = d2J/dF2, B = int N_p dJ^T G dV  of shape (np, nd)):

    f_e = sum_q G^T (P_iso + p dJ) dV
    K_e = sum_q G^T (A_iso + p H_J) G dV + kappa B^T M^-1 B

which is the exact derivative of f_e (quadratic Newton), symmetric, and of the size and
pattern of the displacement element: nothing is added to the global system.

Pressure spaces: P0 (np = 1: the mean dilatation of Q4) and discontinuous P1 = (1, R, Z)
(np = 3) in the reference coordinates of the element, centred and scaled by its size.
"""

from __future__ import annotations

import numpy as np

from ..materials.kinematics import to_rows
from ..materials.protocol import State
from .assembly import SolidAssembly, gather

PRESSURE_SPACES = ("p0", "p1")


def pressure_basis(space: str, Xq: np.ndarray, dV: np.ndarray) -> np.ndarray:
    """N_p at the quadrature points (e, q, np) of the reference points Xq (e, q, 2)."""
    e, q = dV.shape
    if space == "p0":
        return np.ones((e, q, 1))
    if space != "p1":
        raise ValueError(f"pressure space must be one of {PRESSURE_SPACES}, not {space!r}")
    V = dV.sum(axis=1)
    centre = np.einsum("eq,eqd->ed", dV, Xq) / V[:, None]
    size = np.sqrt(np.ptp(Xq[..., 0], axis=1) ** 2 + np.ptp(Xq[..., 1], axis=1) ** 2)
    d = (Xq - centre[:, None, :]) / size[:, None, None]
    return np.concatenate([np.ones((e, q, 1)), d], axis=2)


def volumetric_rows(xt: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """J = det F (n,) and dJ = dJ/dF (5, n) at x rows xt (5, n) = (F_rR, F_rZ, F_zR, F_zZ, F_tT)."""
    a, b, c, d, f = xt
    j2 = a * d - b * c
    dJ = np.empty_like(xt)
    dJ[0], dJ[1], dJ[2], dJ[3], dJ[4] = f * d, -f * c, -f * b, f * a, j2
    return f * j2, dJ


def add_pressure_hessian(A: np.ndarray, x: np.ndarray, p: np.ndarray) -> None:
    """A += p d2J/dF2 in place on A (..., 5, 5), x (..., 5), p (...): J = f (a d - b c) is
    quadratic in each pair."""
    a, b, c, d, f = (x[..., k] for k in range(5))
    pf = p * f
    A[..., 0, 3] += pf
    A[..., 3, 0] += pf
    A[..., 1, 2] -= pf
    A[..., 2, 1] -= pf
    for i, v in ((0, d), (3, a)):
        pv = p * v
        A[..., 4, i] += pv
        A[..., i, 4] += pv
    for i, v in ((1, c), (2, b)):
        pv = p * v
        A[..., 4, i] -= pv
        A[..., i, 4] -= pv


class MixedAssembly(SolidAssembly):
    """Internal forces and tangents of the mixed elements (module docstring), same interface
    and dof layout as SolidAssembly.  The law (materials.protocol) gives its isochoric part
    (update with volumetric=False), its bulk modulus and its volumetric energy U(J)."""

    chunk = 1024

    def __init__(self, mesh, material, pressure_space: str, shift=None):
        super().__init__(mesh, material, shift)
        from .elements import gauss_quad, jacobian

        self.pressure_space = pressure_space
        xi, _ = gauss_quad(mesh.element.gauss)
        Xq = jacobian(mesh.element, mesh.points[mesh.cells], xi)[3]
        self.Np = pressure_basis(pressure_space, Xq, self.dV)  # (e, q, np)
        NpdV = self.Np * self.dV[..., None]
        M = np.einsum("eqi,eqj->eij", NpdV, self.Np)
        self.Minv = np.linalg.inv(M)  # (e, np, np)
        self.NpdV = NpdV
        self._NpdV_T = np.ascontiguousarray(NpdV.transpose(0, 2, 1))  # (e, np, q)

    def _pressure(self, xt: np.ndarray, sl: slice, kappa: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """p = U'(J_bar) (n,), U'' (m,) per element (the mean of its points' where U is not
        quadratic in J) and dJ (5, n) at the rows xt (5, n) of the elements sl, kappa (m,) theirs
        (bulk_modulus); U the law's volumetric energy."""
        J, dJ = volumetric_rows(xt)
        m, q = self.Np[sl].shape[:2]
        h = np.matmul(self._NpdV_T[sl], J.reshape(m, q, 1))  # int N_p J dV (m, np, 1)
        Jbar = np.matmul(self.Np[sl], np.matmul(self.Minv[sl], h))  # (m, q, 1)
        dU, d2U = self.law.volumetric(Jbar[..., 0], kappa[:, None])
        d2U = np.asarray(d2U)
        return dU.reshape(-1), d2U[:, 0] if d2U.shape[1] == 1 else d2U.mean(1), dJ

    def bulk_modulus(self, temperature: np.ndarray | None, sl: slice, m: int) -> np.ndarray:
        """kappa (m,) of the m elements sl from the law at their points' temperatures
        (temperature (e, q) of all elements, or None): the law's, or where it is a table of T the
        mean of each element's points (one pressure field per element needs one kappa)."""
        kappa = np.asarray(self.law.bulk_modulus(None if temperature is None else temperature[sl]), float)
        return np.broadcast_to(kappa, (m,)) if kappa.ndim == 0 else kappa.reshape(m, -1).mean(1)

    def stress(
        self,
        x: np.ndarray,
        sl: slice = slice(None),
        temperature: np.ndarray | None = None,
        state: State | None = None,
    ) -> np.ndarray:
        """P = P_iso + p dJ/dF (e, q, 5) with the element pressure p, the law's isochoric part
        at the committed state `state` (as SolidAssembly.stress)."""
        xt, shape = to_rows(x)
        p, _, dJ = self._pressure(xt, sl, self.bulk_modulus(temperature, sl, shape[0]))
        held = self.initial_state(temperature) if state is None else state
        T = None if temperature is None else temperature[sl]
        P = self.law.update(x, {k: v[sl] for k, v in held.items()}, 0.0, T, volumetric=False, tangent=False)[0]
        return P + (p * dJ).T.reshape(P.shape)

    def update(
        self,
        u_full: np.ndarray,
        tangent: bool = True,
        out: tuple | None = None,
        state: State | None = None,
        dt: float = 0.0,
        temperature: np.ndarray | None = None,
    ) -> tuple[np.ndarray, np.ndarray | None, State]:
        """Element internal forces fe (e, nd), if asked element tangents Ke (e, nd, nd), and the
        law's trial state, as SolidAssembly.update: the law's isochoric part (update with
        volumetric=False) and the pressure terms at the element's dilatation."""
        e, q, _, nd = self.G.shape
        fe, Ke = out if out is not None else self.buffers(tangent)
        held = self.initial_state(temperature) if state is None else state
        trial: State = {}
        for sl, x in self.chunks(u_full):
            m = sl.stop - sl.start
            xt, shape = to_rows(x)
            T = None if temperature is None else temperature[sl]
            p, d2U, dJ = self._pressure(xt, sl, self.bulk_modulus(temperature, sl, m))
            P, A, part = self.law.update(x, {k: v[sl] for k, v in held.items()}, dt, T, False, tangent)
            gather(trial, part, sl, e)
            P += (p * dJ).T.reshape(P.shape)
            GdV_T = self._GdV[sl].transpose(0, 2, 1)
            np.matmul(GdV_T, P.reshape(m, q * 5, 1), out=fe[sl, :, None])
            if tangent:
                add_pressure_hessian(A, x, p.reshape(m, q))
                AG = np.matmul(A, self.G[sl]).reshape(m, q * 5, nd)
                np.matmul(GdV_T, AG, out=Ke[sl])
                # B = int N_p dJ^T G dV (m, np, nd) as one product with the stacked G (m, 5q, nd);
                # K += U'' B^T M^-1 B (U'' per element: exact where U is quadratic in J)
                W = self._NpdV_T[sl][:, :, :, None] * dJ.T.reshape(m, 1, q, 5)  # (m, np, q, 5)
                B = np.matmul(W.reshape(m, -1, q * 5), self._G2[sl])
                Ke[sl] += np.matmul(B.transpose(0, 2, 1), d2U[:, None, None] * np.matmul(self.Minv[sl], B))
        return fe, Ke, trial
