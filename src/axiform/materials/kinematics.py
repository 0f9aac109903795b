"""Kinematics on the five non-zero components of F (eq. 6).

x = (F_rR, F_rZ, F_zR, F_zZ, F_tT) = (1+U,R, U,Z, W,R, 1+W,Z, 1+U/R), matching the ordering
g of the gradient operator, batched over any leading axes (elements, quadrature points).
F is block diagonal: the meridian block M = [[a, b], [c, d]] and the hoop stretch f.  The laws
use the reduced variables s = tr(M^T M) = a^2 + b^2 + c^2 + d^2 and j2 = det M = a d - b c,
with I1 = s + f^2, I2 = j2^2 + f^2 s and J = det F = f j2.
"""

from __future__ import annotations

from typing import overload

import numpy as np

# x = (a, b, c, d, f) = (F_rR, F_rZ, F_zR, F_zZ, F_tT);  J = f (a d - b c)


class InvertedElementError(ValueError):
    """J = det F <= 0 at some quadrature point; carries the offending element indices."""

    def __init__(self, elements: np.ndarray):
        self.elements = np.asarray(elements)
        super().__init__(f"J <= 0 in element(s) {self.elements[:10].tolist()}")


def deformation_gradient(g: np.ndarray) -> np.ndarray:
    """x = F components (..., 5) from the displacement gradient g (..., 5) (eq. 6)."""
    x = g.copy()
    x[..., 0] += 1.0
    x[..., 3] += 1.0
    x[..., 4] += 1.0
    return x


def invariants(x: np.ndarray):
    """I1, I2, J (...) and their gradients dI1, dI2, dJ (..., 5) with respect to x (..., 5)."""
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


def cauchy_stress(x: np.ndarray, P: np.ndarray) -> np.ndarray:
    """Cauchy stress sigma = P F^T / J as (rr, zz, tt, rz) (..., 4), from x and P (..., 5)."""
    a, b, c, d, f = (x[..., i] for i in range(5))
    J = f * (a * d - b * c)
    Prr, Prz, Pzr, Pzz, Ptt = (P[..., i] for i in range(5))
    # sigma_ij = P_iK F_jK / J with i, j in (r, z)
    s_rr = (Prr * a + Prz * b) / J
    s_zz = (Pzr * c + Pzz * d) / J
    s_rz = (Prr * c + Prz * d) / J
    s_tt = Ptt * f / J
    return np.stack([s_rr, s_zz, s_tt, s_rz], axis=-1)


def to_rows(x: np.ndarray) -> tuple[np.ndarray, tuple[int, ...]]:
    """x (..., 5) as contiguous component rows (5, n), and the leading shape."""
    return np.ascontiguousarray(x.reshape(-1, 5).T), x.shape[:-1]


@overload
def from_rows(P: np.ndarray, A: np.ndarray, shape: tuple[int, ...]) -> tuple[np.ndarray, np.ndarray]: ...
@overload
def from_rows(P: np.ndarray, A: None, shape: tuple[int, ...]) -> tuple[np.ndarray, None]: ...
@overload
def from_rows(P: np.ndarray, A: np.ndarray | None, shape: tuple[int, ...]) -> tuple[np.ndarray, np.ndarray | None]: ...


def from_rows(P: np.ndarray, A: np.ndarray | None, shape: tuple[int, ...]) -> tuple[np.ndarray, np.ndarray | None]:
    """P rows (5, n) and A rows (5, 5, n) back to (..., 5) and (..., 5, 5)."""
    P = P.T.reshape(*shape, 5)
    if A is None:
        return P, None
    return P, np.ascontiguousarray(A.reshape(25, -1).T).reshape(*shape, 5, 5)
