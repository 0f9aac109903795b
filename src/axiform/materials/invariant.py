"""Laws of the isochoric invariants: W_iso = Psi(I1_bar, I2_bar), I1_bar = J^(-2/3) I1,
I2_bar = J^(-4/3) I2.  The chain rule through (I1_bar, I2_bar) to the reduced variables
(s, j2, f) is shared here; a law gives Psi and its derivatives only.
"""

from __future__ import annotations

from abc import abstractmethod

import numpy as np

from .base import PAIR_K, PAIR_L, ReducedLaw, sym_outer


class InvariantLaw(ReducedLaw):
    """W_iso = Psi(I1_bar, I2_bar).

    Subclasses give `psi(I1b, I2b)` and `psi_derivatives(I1b, I2b, tangent)` ->
    (Psi_1, Psi_2, Psi_11, Psi_12, Psi_22); a derivative that is identically zero is None
    (Psi_2 None: the law does not depend on I2_bar, which is then not computed).
    """

    @abstractmethod
    def psi(self, I1b: np.ndarray, I2b: np.ndarray | None) -> np.ndarray:
        """Psi(I1_bar, I2_bar) (...)."""

    @abstractmethod
    def psi_derivatives(self, I1b: np.ndarray, I2b: np.ndarray | None, tangent: bool) -> tuple:
        """(Psi_1, Psi_2, Psi_11, Psi_12, Psi_22), arrays (n) or None where identically zero."""

    uses_I2 = False

    def iso_energy(self, x: np.ndarray) -> np.ndarray:
        a, b, c, d, f = (x[..., i] for i in range(5))
        s = a * a + b * b + c * c + d * d
        j2 = a * d - b * c
        K = np.cbrt(1.0 / (f * j2)) ** 2  # J^(-2/3)
        I1b = (s + f * f) * K
        I2b = (j2 * j2 + f * f * s) * K * K if self.uses_I2 else None
        return self.psi(I1b, I2b)

    def _reduced(self, xt, s, j2, tangent):
        f = xt[4]
        ff = f * f
        i_j, i_f = 1.0 / j2, 1.0 / f
        K = np.cbrt(i_j * i_f)
        K *= K  # J^(-2/3)
        I1b = (s + ff) * K
        d1 = np.stack([K, -2.0 / 3.0 * I1b * i_j, 2.0 * f * K - 2.0 / 3.0 * I1b * i_f])
        I2b = d2 = None
        if self.uses_I2:
            L = K * K  # J^(-4/3)
            I2b = (j2 * j2 + ff * s) * L
            d2 = np.stack([ff * L, 2.0 * j2 * L - 4.0 / 3.0 * I2b * i_j, 2.0 * f * s * L - 4.0 / 3.0 * I2b * i_f])
        W1, W2, W11, W12, W22 = self.psi_derivatives(I1b, I2b, tangent)
        g = W1 * d1 if W2 is None else W1 * d1 + W2 * d2
        if not tangent:
            return g, None
        # Hessians of I1_bar and I2_bar in (s, j2, f), entries ss, sj, sf, jj, jf, ff
        zero = np.zeros_like(K)
        h1 = np.stack(
            [
                zero,
                -2.0 / 3.0 * K * i_j,
                -2.0 / 3.0 * K * i_f,
                10.0 / 9.0 * I1b * i_j**2,
                -2.0 / 3.0 * d1[2] * i_j,
                -2.0 / 3.0 * K + 10.0 / 9.0 * I1b * i_f**2,
            ]
        )
        H = W1 * h1
        if W11 is not None:
            H += W11 * (d1[PAIR_K] * d1[PAIR_L])
        if W2 is not None:
            h2 = np.stack(
                [
                    zero,
                    -4.0 / 3.0 * ff * L * i_j,
                    2.0 / 3.0 * f * L,
                    -10.0 / 3.0 * L + 28.0 / 9.0 * I2b * i_j**2,
                    -8.0 / 3.0 * j2 * L * i_f - 4.0 / 3.0 * d2[2] * i_j,
                    -10.0 / 3.0 * s * L + 28.0 / 9.0 * I2b * i_f**2,
                ]
            )
            H += W2 * h2
        if W12 is not None:
            H += W12 * sym_outer(d1, d2)
        if W22 is not None:
            H += W22 * (d2[PAIR_K] * d2[PAIR_L])
        return g, H
