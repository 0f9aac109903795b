"""The decoupled hyperelastic law W(F) = W_iso(F_bar) + kappa/2 (J - 1)^2, F_bar = J^(-1/3) F.

Every law works on the five components x of F (kinematics.py) batched over leading axes, and
gives the strain energy W, the first Piola-Kirchhoff stress P = dW/dF (..., 5) and the tangent
A = dP/dF (..., 5, 5); `iso_*` are the same for W_iso(F_bar(F)) alone, the volumetric kappa
terms left out (a mixed element adds its own).  The volumetric part is written once, here.

Laws other than Mooney-Rivlin are written in the reduced variables (s, j2, f) of kinematics.py:
a law gives W_iso and its gradient and Hessian in (s, j2, f), and `ReducedLaw` applies the one
chain rule to x (ds = 2 (a, b, c, d, 0), d2s = 2 on the meridian block, dj2 = (d, -c, -b, a, 0),
d2j2 constant, df = e_5).  All arrays run on component rows (5, n): every NumPy operation then
works on n contiguous numbers (benchmarks/README.md).
"""

from __future__ import annotations

from abc import ABC, abstractmethod

import numpy as np

from .kinematics import from_rows, to_rows

# pairs (k, l) of the 6 Hessian entries in (s, j2, f): ss, sj, sf, jj, jf, ff
PAIR_K = np.array([0, 0, 0, 1, 1, 2])
PAIR_L = np.array([0, 1, 2, 1, 2, 2])


def sym_outer(u: np.ndarray, v: np.ndarray) -> np.ndarray:
    """The 6 entries (ss, sj, sf, jj, jf, ff) (6, n) of u v^T + v u^T for u, v (3, n)."""
    return u[PAIR_K] * v[PAIR_L] + v[PAIR_K] * u[PAIR_L]


class Hyperelastic(ABC):
    """Decoupled law W = W_iso(F_bar) + kappa/2 (J - 1)^2; kappa the bulk modulus.

    Subclasses give `stress_rows(xt, kappa, tangent)` (the mixed elements call it with kappa
    = 0): P rows (5, n) and, if asked, A rows (5, 5, n) of W_iso + kappa/2 (J - 1)^2 at x rows xt (5, n) (kappa =
    0: the isochoric part alone),
    `iso_energy` and `shear_modulus`.
    """

    kappa: float

    @property
    @abstractmethod
    def shear_modulus(self) -> float:
        """Initial (small-strain) shear modulus mu."""

    @abstractmethod
    def iso_energy(self, x: np.ndarray) -> np.ndarray:
        """W_iso(F_bar(F)) (...) per unit reference volume at x (..., 5)."""

    @abstractmethod
    def stress_rows(self, xt: np.ndarray, kappa: float, tangent: bool) -> tuple[np.ndarray, np.ndarray | None]:
        """P (5, n) and A (5, 5, n) or None of W_iso + kappa/2 (J - 1)^2 at rows xt (5, n)."""

    def energy(self, x: np.ndarray) -> np.ndarray:
        """Strain energy W (...) per unit reference volume at x (..., 5)."""
        J = x[..., 4] * (x[..., 0] * x[..., 3] - x[..., 1] * x[..., 2])
        return self.iso_energy(x) + 0.5 * self.kappa * (J - 1.0) ** 2

    def stress(self, x: np.ndarray) -> np.ndarray:
        """First Piola-Kirchhoff stress P = dW/dF (..., 5)."""
        xt, shape = to_rows(x)
        return from_rows(self.stress_rows(xt, self.kappa, False)[0], None, shape)[0]

    def stress_tangent(self, x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """P (..., 5) and A = dP/dF (..., 5, 5) of the whole W."""
        xt, shape = to_rows(x)
        P, A = self.stress_rows(xt, self.kappa, True)
        assert A is not None, "stress_rows gives A when the tangent is asked for"
        return from_rows(P, A, shape)

    def iso_stress(self, x: np.ndarray) -> np.ndarray:
        """P_iso = dW_iso(F_bar(F))/dF (..., 5)."""
        xt, shape = to_rows(x)
        return from_rows(self.stress_rows(xt, 0.0, False)[0], None, shape)[0]

    def iso_stress_tangent(self, x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """P_iso (..., 5) and A_iso = dP_iso/dF (..., 5, 5) of W_iso(F_bar(F)) alone."""
        xt, shape = to_rows(x)
        P, A = self.stress_rows(xt, 0.0, True)
        assert A is not None, "stress_rows gives A when the tangent is asked for"
        return from_rows(P, A, shape)

    def volumetric_stress_tangent(self, x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """P_vol = kappa (J - 1) dJ (..., 5) and A_vol = kappa (dJ dJ^T + (J - 1) d2J)
        (..., 5, 5): stress_tangent = iso_stress_tangent + volumetric_stress_tangent."""
        xt, shape = to_rows(x)
        n = xt.shape[1]
        P, A = np.zeros((5, n)), np.zeros((5, 5, n))
        add_volumetric(xt, self.kappa, P, A)
        return from_rows(P, A, shape)


def add_volumetric(xt: np.ndarray, kappa: float, P: np.ndarray, A: np.ndarray | None) -> None:
    """Add the derivatives of kappa/2 (J - 1)^2 to P rows (5, n) and A rows (5, 5, n), in
    place: P += U' dJ, A += U'' dJ dJ^T + U' d2J, U' = kappa (J - 1), U'' = kappa."""
    a, b, c, d, f = xt
    j2 = a * d - b * c
    dJ = np.empty_like(xt)
    dJ[0], dJ[1], dJ[2], dJ[3], dJ[4] = f * d, -f * c, -f * b, f * a, j2
    dU = kappa * (f * j2 - 1.0)
    P += dU * dJ
    if A is None:
        return
    A += (kappa * dJ)[:, None] * dJ[None]
    dUf = dU * f  # d2J: f on (0, 3), -f on (1, 2), dj2 on the hoop row and column
    A[0, 3] += dUf
    A[3, 0] += dUf
    A[1, 2] -= dUf
    A[2, 1] -= dUf
    w = dU * np.stack([d, -c, -b, a])
    A[4, :4] += w
    A[:4, 4] += w


class ReducedLaw(Hyperelastic):
    """A law whose W_iso is written in the reduced variables (s, j2, f) of kinematics.py.

    Subclasses give `_reduced(xt, s, j2, tangent)`: the gradient g = (W_s, W_j2, W_f) (3, n)
    and, if asked, the Hessian entries H = (W_ss, W_sj, W_sf, W_jj, W_jf, W_ff) (6, n).
    """

    @abstractmethod
    def _reduced(
        self, xt: np.ndarray, s: np.ndarray, j2: np.ndarray, tangent: bool
    ) -> tuple[np.ndarray, np.ndarray | None]:
        """g (3, n) and H (6, n) or None of W_iso in (s, j2, f)."""

    def stress_rows(self, xt: np.ndarray, kappa: float, tangent: bool) -> tuple[np.ndarray, np.ndarray | None]:
        a, b, c, d, f = xt
        s = a * a + b * b + c * c + d * d
        j2 = a * d - b * c
        g, H = self._reduced(xt, s, j2, tangent)
        dj = np.stack([d, -c, -b, a])  # dj2 on the meridian block; ds = 2 x there
        P = np.empty_like(xt)
        P[:4] = (2.0 * g[0]) * xt[:4] + g[1] * dj
        P[4] = g[2]
        A = None
        if tangent:
            assert H is not None, "_reduced gives H when the tangent is asked for"
            ds = 2.0 * xt[:4]
            A = np.empty((5, 5, xt.shape[1]))
            v = H[0] * ds + H[1] * dj
            w = H[1] * ds + H[3] * dj
            A[:4, :4] = v[:, None] * ds[None] + w[:, None] * dj[None]
            for i in range(4):
                A[i, i] += 2.0 * g[0]  # W_s d2s
            A[0, 3] += g[1]  # W_j2 d2j2
            A[3, 0] += g[1]
            A[1, 2] -= g[1]
            A[2, 1] -= g[1]
            u = H[2] * ds + H[4] * dj
            A[4, :4] = u
            A[:4, 4] = u
            A[4, 4] = H[5]
        if np.any(kappa):  # a number, or one per point
            add_volumetric(xt, kappa, P, A)
        return P, A
