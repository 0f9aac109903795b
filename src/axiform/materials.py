"""Hyperelastic laws written on the five non-zero components of F (eq. 6).

x = (F_rR, F_rZ, F_zR, F_zZ, F_tT) = (1+U,R, U,Z, W,R, 1+W,Z, 1+U/R), matching the ordering
g of the gradient operator.  A law gives the strain energy W, the first Piola-Kirchhoff
stress P = dW/dx (5 components) and the tangent A = dP/dx (5 x 5), batched over any leading
axes (elements, quadrature points).  Invariant-based laws supply W(I1, I2, J) and its first
and second derivatives; the chain rule through I1, I2 and J is shared.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

# x = (a, b, c, d, f) = (F_rR, F_rZ, F_zR, F_zZ, F_tT);  J = f (a d - b c)


class InvertedElementError(ValueError):
    """J = det F <= 0 at some quadrature point; carries the offending element indices."""

    def __init__(self, elements: np.ndarray):
        self.elements = np.asarray(elements)
        super().__init__(f"J <= 0 in element(s) {self.elements[:10].tolist()}")


def deformation_gradient(g: np.ndarray) -> np.ndarray:
    """x = F components from the displacement gradient g (..., 5) (eq. 6)."""
    x = g.copy()
    x[..., 0] += 1.0
    x[..., 3] += 1.0
    x[..., 4] += 1.0
    return x


def invariants(x: np.ndarray):
    """I1, I2, J and their gradients dI1, dI2, dJ with respect to x."""
    a, b, c, d, f = (x[..., i] for i in range(5))
    j2 = a * d - b * c  # det of the meridian 2x2 block
    s = a * a + b * b + c * c + d * d
    J = f * j2
    I1 = s + f * f
    I2 = j2 * j2 + f * f * s  # (I1^2 - C:C)/2 for the block-diagonal F
    dj2 = np.stack([d, -c, -b, a, np.zeros_like(a)], axis=-1)
    ds = 2.0 * x.copy()
    ds[..., 4] = 0.0
    dI1 = 2.0 * x
    dI2 = 2.0 * j2[..., None] * dj2 + (f * f)[..., None] * ds
    dI2[..., 4] += 2.0 * f * s
    dJ = f[..., None] * dj2
    dJ[..., 4] = j2
    return I1, I2, J, dI1, dI2, dJ


@dataclass(frozen=True)
class MooneyRivlin:
    """Quasi-incompressible Mooney-Rivlin (eqs. 11-13, with J = det F):
    W = C1 (J^-2/3 I1 - 3) + C2 (J^-4/3 I2 - 3) + kappa/2 (J - 1)^2.

    Neo-Hooke is C2 = 0.  kappa is the bulk modulus (the paper's penalty).
    """

    C1: float
    C2: float
    kappa: float

    @property
    def shear_modulus(self) -> float:
        """Small-strain shear modulus mu = 2 (C1 + C2)."""
        return 2.0 * (self.C1 + self.C2)

    @classmethod
    def from_E_nu(cls, C1: float, C2: float, E: float, nu: float) -> "MooneyRivlin":
        """kappa = E / (3 (1 - 2 nu)) (eq. 13)."""
        return cls(C1, C2, E / (3.0 * (1.0 - 2.0 * nu)))

    def energy(self, x: np.ndarray) -> np.ndarray:
        """Strain energy per unit reference volume."""
        I1, I2, J, *_ = invariants(x)
        return self._psi(I1, I2, J)

    def _psi(self, I1, I2, J):
        Jm13 = np.cbrt(1.0 / J)
        return (self.C1 * (Jm13**2 * I1 - 3.0) + self.C2 * (Jm13**4 * I2 - 3.0)
                + 0.5 * self.kappa * (J - 1.0) ** 2)

    def _derivatives(self, I1, I2, J):
        """First derivatives of W(I1, I2, J)."""
        Jm13 = np.cbrt(1.0 / J)
        W1 = self.C1 * Jm13 * Jm13
        W2 = self.C2 * Jm13**4
        WJ = (-2.0 / 3.0 * W1 * I1 - 4.0 / 3.0 * W2 * I2) / J + self.kappa * (J - 1.0)
        return W1, W2, WJ

    def stress(self, x: np.ndarray) -> np.ndarray:
        """First Piola-Kirchhoff stress P = dW/dF, the 5 components of x."""
        I1, I2, J, dI1, dI2, dJ = invariants(x)
        W1, W2, WJ = self._derivatives(I1, I2, J)
        return W1[..., None] * dI1 + W2[..., None] * dI2 + WJ[..., None] * dJ

    def iso_stress_tangent(self, x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """P_iso and A_iso of the isochoric part W_iso alone (kappa = 0), for mixed elements."""
        return replace(self, kappa=0.0).stress_tangent(x)

    def stress_tangent(self, x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """P (..., 5) and A = dP/dF (..., 5, 5) in one pass.

        A = 2 W1 I + W2 d2I2 + WJ d2J + W1J (dI1 dJ + dJ dI1) + W2J (dI2 dJ + dJ dI2)
        + WJJ dJ dJ, written as v dJ^T + dJ v^T + 2 W2 dj2 dj2^T (v = W1J dI1 + W2J dI2
        + WJJ/2 dJ) plus the sparse rest.  Computed on component rows (x as (5, n), A as
        (5, 5, n)) so that every NumPy operation runs over n contiguous numbers: on (..., 5)
        arrays most of the time went to loops of length 5 (7x slower; benchmarks/README.md).
        """
        shape = x.shape[:-1]
        xt = np.ascontiguousarray(x.reshape(-1, 5).T)  # (5, n)
        a, b, c, d, f = xt
        n = xt.shape[1]
        C1, C2, k = self.C1, self.C2, self.kappa
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
        W1J = -2.0 / 3.0 * W1 * iJ
        W2J = -4.0 / 3.0 * W2 * iJ
        WJJ = (10.0 / 9.0 * W1I1 + 28.0 / 9.0 * W2I2) * (iJ * iJ) + k
        dj2 = np.empty((5, n))
        dj2[0], dj2[1], dj2[2], dj2[3], dj2[4] = d, -c, -b, a, 0.0
        dJ = f * dj2
        dJ[4] = j2
        dI2 = (2.0 * j2) * dj2  # dI2 = 2 j2 dj2 + f^2 ds, ds = 2 (a, b, c, d, 0); dI2_4 = 2 f s
        dI2[:4] += (2.0 * ff) * xt[:4]
        dI2[4] = 2.0 * f * s
        P = (2.0 * W1) * xt + W2 * dI2 + WJ * dJ  # dI1 = 2 x
        v = (2.0 * W1J) * xt + W2J * dI2 + (0.5 * WJJ) * dJ
        A = v[:, None] * dJ[None]  # (5, 5, n)
        A += A.transpose(1, 0, 2).copy()
        A += (2.0 * W2 * dj2)[:, None] * dj2[None]
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
        return P.T.reshape(*shape, 5), np.ascontiguousarray(A.reshape(25, n).T).reshape(*shape, 5, 5)


def NeoHooke(C1: float, kappa: float) -> MooneyRivlin:
    """Neo-Hooke as Mooney-Rivlin with C2 = 0."""
    return MooneyRivlin(C1, 0.0, kappa)


def cauchy_stress(x: np.ndarray, P: np.ndarray) -> np.ndarray:
    """Cauchy stress sigma = P F^T / J as (rr, zz, tt, rz), from the 5 components."""
    a, b, c, d, f = (x[..., i] for i in range(5))
    J = f * (a * d - b * c)
    Prr, Prz, Pzr, Pzz, Ptt = (P[..., i] for i in range(5))
    # sigma_ij = P_iK F_jK / J with i, j in (r, z)
    s_rr = (Prr * a + Prz * b) / J
    s_zz = (Pzr * c + Pzz * d) / J
    s_rz = (Prr * c + Prz * d) / J
    s_tt = Ptt * f / J
    return np.stack([s_rr, s_zz, s_tt, s_rz], axis=-1)
