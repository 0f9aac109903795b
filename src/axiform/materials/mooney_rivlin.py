"""Mooney-Rivlin (eqs. 11-13, with J = det F):
W = C1 (I1_bar - 3) + C2 (I2_bar - 3) + kappa/2 (J - 1)^2 (Abaqus C10 = C1, C01 = C2, D1 = 2/kappa).

The hot path of the program: P and A written out by hand on component rows, the volumetric
terms folded into the J derivatives; the shared invariant chain rule (InvariantLaw) gives the
same numbers more slowly and checks this one in the tests.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .invariant import InvariantLaw
from .registry import FitFamily, Key, LawEntry, positive, register


@dataclass(frozen=True)
class MooneyRivlin(InvariantLaw):
    """Quasi-incompressible Mooney-Rivlin:
    W = C1 (J^-2/3 I1 - 3) + C2 (J^-4/3 I2 - 3) + kappa/2 (J - 1)^2.

    Neo-Hooke is C2 = 0.  kappa is the bulk modulus (the paper's penalty).
    """

    C1: float
    C2: float
    kappa: float

    uses_I2 = True

    @property
    def shear_modulus(self) -> float:
        """Small-strain shear modulus mu = 2 (C1 + C2)."""
        return 2.0 * (self.C1 + self.C2)

    @classmethod
    def from_E_nu(cls, C1: float, C2: float, E: float, nu: float) -> MooneyRivlin:
        """kappa = E / (3 (1 - 2 nu)) (eq. 13)."""
        return cls(C1, C2, E / (3.0 * (1.0 - 2.0 * nu)))

    def psi(self, I1b: np.ndarray, I2b: np.ndarray | None) -> np.ndarray:
        assert I2b is not None, "Mooney-Rivlin uses I2_bar (uses_I2)"
        return self.C1 * (I1b - 3.0) + self.C2 * (I2b - 3.0)

    def psi_derivatives(self, I1b: np.ndarray, I2b: np.ndarray | None, tangent: bool) -> tuple:
        return np.full_like(I1b, self.C1), np.full_like(I1b, self.C2), None, None, None

    def stress_rows(self, xt: np.ndarray, kappa: float, tangent: bool) -> tuple[np.ndarray, np.ndarray | None]:
        """P (5, n) and A = dP/dF (5, 5, n) at x rows xt (5, n), volumetric kappa included.

        A = 2 W1 I + W2 d2I2 + WJ d2J + W1J (dI1 dJ + dJ dI1) + W2J (dI2 dJ + dJ dI2)
        + WJJ dJ dJ, written as v dJ^T + dJ v^T + 2 W2 dj2 dj2^T (v = W1J dI1 + W2J dI2
        + WJJ/2 dJ) plus the sparse rest, W(I1, I2, J) the energy in the plain invariants.
        Computed on component rows so that every NumPy operation runs over n contiguous
        numbers: on (..., 5) arrays most of the time went to loops of length 5 (7x slower;
        benchmarks/README.md).
        """
        a, b, c, d, f = xt
        n = xt.shape[1]
        C1, C2, k = self.C1, self.C2, kappa
        j2 = a * d - b * c
        s = a * a + b * b + c * c + d * d
        ff = f * f
        J = f * j2
        I1 = s + ff
        I2 = j2 * j2 + ff * s
        iJ = 1.0 / J
        Jm23 = np.cbrt(iJ)
        Jm23 *= Jm23
        W1 = C1 * Jm23
        W2 = C2 * (Jm23 * Jm23)
        W1I1, W2I2 = W1 * I1, W2 * I2
        WJ = (-2.0 / 3.0 * W1I1 - 4.0 / 3.0 * W2I2) * iJ + k * (J - 1.0)
        dj2 = np.empty((5, n))
        dj2[0], dj2[1], dj2[2], dj2[3], dj2[4] = d, -c, -b, a, 0.0
        dJ = f * dj2
        dJ[4] = j2
        dI2 = (2.0 * j2) * dj2  # dI2 = 2 j2 dj2 + f^2 ds, ds = 2 (a, b, c, d, 0); dI2_4 = 2 f s
        dI2[:4] += (2.0 * ff) * xt[:4]
        dI2[4] = 2.0 * f * s
        P = (2.0 * W1) * xt + W2 * dI2 + WJ * dJ  # dI1 = 2 x
        if not tangent:
            return P, None
        W1J = -2.0 / 3.0 * W1 * iJ
        W2J = -4.0 / 3.0 * W2 * iJ
        WJJ = (10.0 / 9.0 * W1I1 + 28.0 / 9.0 * W2I2) * (iJ * iJ) + k
        v = (2.0 * W1J) * xt + W2J * dI2 + (0.5 * WJJ) * dJ
        T = v[:, None] * dJ[None]  # (5, 5, n); dj2 is zero in the hoop row
        T[:4, :4] += (W2 * dj2[:4])[:, None] * dj2[None, :4]
        A = T + T.transpose(1, 0, 2)  # T + T^T, without a copy of T^T
        diag = 2.0 * W1 + 2.0 * W2 * ff  # 2 W1 I + W2 f^2 d2s on the meridian block
        for i in range(4):
            A[i, i] += diag
        A[4, 4] += 2.0 * W1 + 2.0 * W2 * s
        cD = 2.0 * W2 * j2 + WJ * f  # times d2(ad - bc)
        A[0, 3] += cD
        A[3, 0] += cD
        A[1, 2] -= cD
        A[2, 1] -= cD
        w = (4.0 * W2 * f) * xt[:4] + WJ * dj2[:4]  # e_f w^T + w e_f^T
        A[4, :4] += w
        A[:4, 4] += w
        return P, A


def _from_case(c: dict, kappa, mu0) -> MooneyRivlin:
    """The law of the case file's constants (C2 = 0 where left out)."""
    return MooneyRivlin(
        c["C1"] if c["C1"] is not None else mu0("C1") / 2.0, c["C2"] if c["C2"] is not None else 0.0, kappa
    )


def _fit(terms: int) -> FitFamily:
    """C1 > 0 and C2 >= 0, both linear."""
    return FitFamily(("C1", "C2"), (), lambda a, b: MooneyRivlin(a[0], a[1], 1.0), ("positive", "nonnegative"))


def _nonnegative(v: float) -> bool:
    return v >= 0


KEYS = (Key("C1", positive, "must be > 0"), Key("C2", _nonnegative, "must be >= 0"))
register(LawEntry("mooney-rivlin", MooneyRivlin, KEYS, _from_case, None, _fit))
