"""A network born stress-free as the material cools (freezing), melting as it warms.

G_f(T) (a table [[T, G_f], ...], T increasing, G_f non-increasing in T and >= 0, piecewise
linear, constant outside) is the shear modulus of the frozen network.  Over a step whose
temperature falls from T_n to T (G_f rises by dG = G_f(T) - G_f(T_n) > 0), a neo-Hooke network
of modulus dG is born in the configuration at the end of the step, free of stress.  All of them
are kept as one symmetric tensor per point (reference frame; RR, RZ, ZZ, TT):

    H = sum_k dG_k Cbar_k^-1,   Cbar_k = J_k^(-2/3) C_k,

the energy W_f = 1/2 J^(-2/3) tr(C H) - const (the isochoric neo-Hooke energy of F F_k^-1, each
network at its own modulus), its Kirchhoff stress tau = J^(-2/3) dev(F H F^T) (zero at birth),
P = J^(-2/3) (F H - tr(C H)/3 F^-T).  Where the temperature rises (G_f falls), H scales by
G_f(T)/G_f(T_n): the frozen network melts in proportion.  At fixed H the term is hyperelastic:
its tangent A = dP/dF is exact.

The temperature of the committed state is kept in the state ("freeze_T"), so that a law's
update needs the temperature at the end of the step only.
"""

from __future__ import annotations

import numpy as np

from .protocol import State
from .temperature import Table


class Freeze:
    """The frozen network of modulus G_f(T), from its table rows [[T, G_f], ...] (`modulus`)."""

    def __init__(self, modulus):
        rows = np.asarray(modulus, float)
        if rows.ndim != 2 or rows.shape[1] != 2 or rows.shape[0] < 1:
            raise ValueError("modulus: give a table [[T, G_f], ...] with at least one row")
        T, G = rows.T
        if not np.isfinite(rows).all():
            raise ValueError("modulus: every temperature and modulus must be a finite number")
        if (np.diff(T) <= 0).any():
            raise ValueError("modulus: the temperatures must increase")
        if (G < 0).any():
            raise ValueError("modulus: every G_f must be >= 0")
        if (np.diff(G) > 0).any():
            raise ValueError("modulus: G_f must not increase with the temperature")
        self.table = Table(tuple(T), tuple(G))

    def initial_state(self, shape: tuple[int, ...], T: np.ndarray | None = None) -> State:
        """No frozen network (H = 0, (*shape, 4)); "freeze_T" (shape) the initial temperatures,
        NaN where not given: the first update with a temperature then only records it."""
        T0 = np.full(shape, np.nan) if T is None else np.broadcast_to(np.asarray(T, float), shape).copy()
        return {"freeze_H": np.zeros((*shape, 4)), "freeze_T": T0}

    def evolve(self, xt: np.ndarray, H: np.ndarray, T_n: np.ndarray, T: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """The melted H (4, n) that carries stress over the step and the H at its end (4, n),
        from H (4, n), T_n and T (n), F rows xt (5, n) at the end of the step.  The network born
        over the step is free of stress at every F of the step's end (F Cbar^-1 F^T = J^(2/3) I):
        it adds neither to P nor to A, only to the state."""
        known = np.isfinite(T_n)
        G_n = self.table(np.where(known, T_n, T))
        G = self.table(T)
        born = np.where(known, np.maximum(G - G_n, 0.0), 0.0)
        with np.errstate(divide="ignore", invalid="ignore"):
            melt = np.where((G < G_n) & (G_n > 0), G / G_n, 1.0)
        a, b, c, d, f = xt
        j2 = a * d - b * c
        J23 = np.cbrt(f * j2) ** 2  # J^(2/3): Cbar^-1 = J^(2/3) C^-1
        # C^-1 of the meridian block: adj(C) / det(C), C = M^T M, det(C) = j2^2
        C_RR, C_RZ, C_ZZ = a * a + c * c, a * b + c * d, b * b + d * d
        scale = born * J23 / (j2 * j2)
        birth = np.stack([scale * C_ZZ, -scale * C_RZ, scale * C_RR, born * J23 / (f * f)])
        melted = melt * H
        return melted, melted + birth

    def rows(self, xt: np.ndarray, state_n: State, T: np.ndarray | None, shape: tuple[int, ...]):
        """P (5, n), A (5, 5, n) at rows xt (5, n) and the trial state {"freeze_H", "freeze_T"}."""
        H = np.ascontiguousarray(state_n["freeze_H"].reshape(-1, 4).T)
        T_n = state_n["freeze_T"].reshape(-1)
        if T is not None:
            T_new = np.broadcast_to(np.asarray(T, float), shape).reshape(-1)
            H_stress, H = self.evolve(xt, H, T_n, T_new)
            T_n = T_new
        else:
            H_stress = H
        P, A = frozen_rows(xt, H_stress)
        return P, A, {"freeze_H": H.T.reshape(*shape, 4), "freeze_T": T_n.reshape(shape).copy()}


def frozen_rows(xt: np.ndarray, H: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """P (5, n) and A (5, 5, n) of W = 1/2 J^(-2/3) tr(C H) at fixed H rows (4, n):
    P = K (F H - t/3 F^-T), K = J^(-2/3), t = tr(C H) = F : F H."""
    a, b, c, d, f = xt
    RR, RZ, ZZ, TT = H
    j2 = a * d - b * c
    K = np.cbrt(1.0 / (f * j2)) ** 2
    FH = np.stack([a * RR + b * RZ, a * RZ + b * ZZ, c * RR + d * RZ, c * RZ + d * ZZ, f * TT])
    Ginv = np.stack([d / j2, -c / j2, -b / j2, a / j2, 1.0 / f])  # F^-T; also dJ/dF / J
    t = (xt * FH).sum(0)
    P = K * (FH - t / 3.0 * Ginv)
    # dP = dK (FH - t/3 G) + K (dF H - dt/3 G - t/3 dG), dK = -2/3 K G:dF, dt = 2 FH:dF,
    # dG = -G dF^T G (meridian block), d(1/f) = -df/f^2
    A = (-2.0 / 3.0) * (P[:, None] * Ginv[None]) - (2.0 / 3.0) * K * (Ginv[:, None] * FH[None])
    for row, col in ((0, 0), (2, 2)):  # d(F H)_iR = dF_iR H_RR + dF_iZ H_ZR
        A[row, col] += K * RR
        A[row, col + 1] += K * RZ
    for row, col in ((1, 0), (3, 2)):
        A[row, col] += K * RZ
        A[row, col + 1] += K * ZZ
    A[4, 4] += K * TT + K * t / 3.0 / (f * f)
    Gm = ((Ginv[0], Ginv[1]), (Ginv[2], Ginv[3]))
    kt = K * t / 3.0
    for k in range(4):
        alpha, beta = divmod(k, 2)
        for j in range(2):
            for L in range(2):
                A[2 * j + L, k] += kt * Gm[j][beta] * Gm[alpha][L]
    return P, A
