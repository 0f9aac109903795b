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

from ..materials.kinematics import from_rows, to_rows
from .assembly import SolidAssembly

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


def add_pressure_hessian(A: np.ndarray, xt: np.ndarray, p: np.ndarray) -> None:
    """A += p d2J/dF2 in place on rows A (5, 5, n), xt (5, n), p (n,): J = f (a d - b c) is
    quadratic in each pair."""
    a, b, c, d, f = xt
    pf = p * f
    A[0, 3] += pf
    A[3, 0] += pf
    A[1, 2] -= pf
    A[2, 1] -= pf
    for i, v in ((0, d), (3, a)):
        pv = p * v
        A[4, i] += pv
        A[i, 4] += pv
    for i, v in ((1, c), (2, b)):
        pv = p * v
        A[4, i] -= pv
        A[i, 4] -= pv


class MixedAssembly(SolidAssembly):
    """Internal forces and tangents of the mixed elements (module docstring), same interface
    and dof layout as SolidAssembly.  The law must give the isochoric part alone:
    `material.iso_stress_tangent(x)` -> (P_iso, A_iso), and its bulk modulus `kappa`."""

    chunk = 1024

    def __init__(self, mesh, material, pressure_space: str):
        super().__init__(mesh, material)
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

    def _pressure(self, xt: np.ndarray, sl: slice, kappa: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """p = kappa (J_bar - 1) (n,) and dJ (5, n) at the rows xt (5, n) of the elements sl,
        kappa (m,) theirs (bulk_modulus)."""
        J, dJ = volumetric_rows(xt)
        m, q = self.Np[sl].shape[:2]
        h = np.matmul(self._NpdV_T[sl], J.reshape(m, q, 1))  # int N_p J dV (m, np, 1)
        Jbar = np.matmul(self.Np[sl], np.matmul(self.Minv[sl], h))  # (m, q, 1)
        return (kappa[:, None] * (Jbar[..., 0] - 1.0)).reshape(-1), dJ

    @staticmethod
    def bulk_modulus(law, m: int) -> np.ndarray:
        """kappa (m,) of m elements from their law (SolidAssembly.law): the law's, or where it
        is a table of T the mean of each element's points (one pressure field per element
        needs one kappa)."""
        kappa = np.asarray(law.kappa, float)
        return np.broadcast_to(kappa, (m,)) if kappa.ndim == 0 else kappa.reshape(m, -1).mean(1)

    def stress(
        self, x: np.ndarray, sl: slice = slice(None), temperature: np.ndarray | None = None, memory=None
    ) -> np.ndarray:
        """P = P_iso + p dJ/dF (e, q, 5) with the element pressure p (memory: a law's history
        over a step on the isochoric part, applied as `evaluate` applies it)."""
        xt, shape = to_rows(x)
        law = self.law(sl, temperature)
        p, dJ = self._pressure(xt, sl, self.bulk_modulus(law, shape[0]))
        P = law.stress_rows(xt, 0.0, False)[0]
        if memory is not None:
            memory.add_rows(sl, xt, P, None)
        P += p * dJ
        return from_rows(P, None, shape)[0]

    def evaluate(
        self,
        u_full: np.ndarray,
        tangent: bool = True,
        out: tuple | None = None,
        memory=None,
        temperature: np.ndarray | None = None,
    ):
        """Element internal forces fe (e, nd) and, if asked, element tangents Ke (e, nd, nd),
        written into out = (fe, Ke) when given (from `buffers`) and returned (memory,
        temperature: as for SolidAssembly.evaluate).  The law's
        isochoric part (`stress_rows` with kappa = 0) and the pressure terms are computed on the
        contiguous component rows (5, n), then brought to (m, q, 5, 5) once."""
        e, q, _, nd = self.G.shape
        fe, Ke = out if out is not None else self.buffers(tangent)
        for sl, x in self.chunks(u_full):
            m = sl.stop - sl.start
            xt, shape = to_rows(x)
            law = self.law(sl, temperature)  # built once per chunk (a tabled law: one value per point)
            kappa = self.bulk_modulus(law, m)
            p, dJ = self._pressure(xt, sl, kappa)
            P, A = law.stress_rows(xt, 0.0, tangent)
            if memory is not None:  # the Prony series on the isochoric part
                memory.add_rows(sl, xt, P, A)
            P += p * dJ
            if tangent:
                add_pressure_hessian(A, xt, p)
            P, A = from_rows(P, A, shape)
            GdV_T = self._GdV[sl].transpose(0, 2, 1)
            np.matmul(GdV_T, P.reshape(m, q * 5, 1), out=fe[sl, :, None])
            if tangent:
                AG = np.matmul(A, self.G[sl]).reshape(m, q * 5, nd)
                np.matmul(GdV_T, AG, out=Ke[sl])
                # B = int N_p dJ^T G dV (m, np, nd) as one product with the stacked G (m, 5q, nd);
                # K += kappa B^T M^-1 B
                W = self._NpdV_T[sl][:, :, :, None] * dJ.T.reshape(m, 1, q, 5)  # (m, np, q, 5)
                B = np.matmul(W.reshape(m, -1, q * 5), self._G2[sl])
                Ke[sl] += np.matmul(B.transpose(0, 2, 1), kappa[:, None, None] * np.matmul(self.Minv[sl], B))
        return fe, Ke
