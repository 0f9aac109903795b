"""The isochoric part of a law on the deviatoric plane of the principal logarithmic strains:
what the local update of a viscous network (network.py) evaluates a few times per point.

An isochoric law depends on the principal log strains e (3) through their deviatoric part
only, and its principal Kirchhoff stresses t (3) are deviatoric.  Both live in the plane
sum(e) = 0, written in the orthonormal basis u_y = (1, -1, 0)/sqrt 2, u_z = (1, 1, -2)/sqrt 6:
e' = y u_y + z u_z, t = t_y u_y + t_z u_z, and K = dt/de = U k U^T (U = [u_y u_z], k the
symmetric 2 x 2 (k_yy, k_yz, k_zz)).  With a diagonal v (3) written D(v) = U^T diag(v) U
= ((v1 + v2)/2, (v1 - v2)/(2 sqrt 3), (v1 + v2 + 4 v3)/6):
- a law of the isochoric invariants (invariant.InvariantLaw, W_iso = Psi(I1bar, I2bar)), with
  bbar_i = exp(2 e'_i): t = Psi_1 d1 + Psi_2 d2, d1 = U^T 2 bbar, d2 = I1bar d1 - U^T 2 bbar^2,
  k = Psi_1 4 D(bbar) + Psi_2 (d1 d1^T + I1bar 4 D(bbar) - 8 D(bbar^2)) + Psi_11 d1 d1^T
  + Psi_12 (d1 d2^T + d2 d1^T) + Psi_22 d2 d2^T (the terms along (1, 1, 1) drop out);
- Ogden, W_iso = sum_p 2 mu_p / alpha_p^2 (sum_i lbar_i^alpha_p - 3), L_pi = exp(alpha_p e'_i):
  t = sum_p 2 mu_p / alpha_p U^T L_p, k = sum_p 2 mu_p D(L_p);
- any other law: its stress_rows at the diagonal F = diag(exp(e')) (5 x 5 work per point),
  projected on the plane (generic_principal gives t (3) and K (3, 3)).
All three give the same numbers (a test); the first two on (n) arrays only.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from .base import Hyperelastic
from .invariant import InvariantLaw
from .ogden import Ogden

Plane = tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]
PRINCIPAL = (0, 3, 4)  # components of x holding the principal stretches of a diagonal F
SQRT2, SQRT3, SQRT6 = np.sqrt(2.0), np.sqrt(3.0), np.sqrt(6.0)
BASIS = np.array([[1.0 / SQRT2, 1.0 / SQRT6], [-1.0 / SQRT2, 1.0 / SQRT6], [0.0, -2.0 / SQRT6]])  # U (3, 2)


def plane_function(law: Hyperelastic, scale: float = 1.0) -> Callable[[np.ndarray, np.ndarray], Plane]:
    """(y, z) (n each) -> (t_y, t_z, k_yy, k_yz, k_zz) (n each) of `scale` times the law's
    isochoric part (module docstring)."""
    if isinstance(law, InvariantLaw):
        return lambda y, z: invariant_plane(law, y, z, scale)
    if isinstance(law, Ogden):
        return lambda y, z: ogden_plane(law, y, z, scale)
    return lambda y, z: generic_plane(law, y, z, scale)


def plane_strains(y: np.ndarray, z: np.ndarray) -> np.ndarray:
    """The principal log strains e' = y u_y + z u_z (3, n) of the plane coordinates (n)."""
    return BASIS[:, 0, None] * y + BASIS[:, 1, None] * z


def exponentials(alpha: float, y: np.ndarray, z: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """exp(alpha e'_i) (three arrays (n)) of e' = y u_y + z u_z, with two exponentials."""
    zeta = np.exp((alpha / SQRT6) * z)
    eps = np.exp((alpha / SQRT2) * y)
    return zeta * eps, zeta / eps, 1.0 / (zeta * zeta)


def diagonal(v1: np.ndarray, v2: np.ndarray, v3: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """D(v) = U^T diag(v) U as (yy, yz, zz) (n each)."""
    s = v1 + v2
    return 0.5 * s, (0.5 / SQRT3) * (v1 - v2), (s + 4.0 * v3) / 6.0


def generic_principal(law: Hyperelastic, e: np.ndarray, scale: float) -> tuple[np.ndarray, np.ndarray]:
    """t (3, n) and K (3, 3, n) of the law's isochoric part at principal log strains e (3, n):
    t_i = l_i P_i, K_ij = delta_ij t_i + l_i l_j A_ij from the law's P and A at diag(l)."""
    lam = np.exp(e)
    xe = np.zeros((5, e.shape[1]))
    xe[0], xe[3], xe[4] = lam
    P, A = law.stress_rows(xe, 0.0, True)
    assert A is not None, "stress_rows gives A when the tangent is asked for"
    t = scale * lam * P[PRINCIPAL,]
    K = (scale * lam[:, None] * lam[None]) * A[np.ix_(PRINCIPAL, PRINCIPAL)]
    for i in range(3):
        K[i, i] += t[i]
    return t, K


def generic_plane(law: Hyperelastic, y: np.ndarray, z: np.ndarray, scale: float) -> Plane:
    """t and k of any law: generic_principal projected on the plane (U^T t, U^T K U)."""
    t, K = generic_principal(law, plane_strains(y, z), scale)
    ty, tz = np.einsum("ia,in->an", BASIS, t)
    k = np.einsum("ia,ijn,jb->abn", BASIS, K, BASIS)
    return ty, tz, k[0, 0], 0.5 * (k[0, 1] + k[1, 0]), k[1, 1]


def invariant_plane(law: InvariantLaw, y: np.ndarray, z: np.ndarray, scale: float) -> Plane:
    """t and k of W_iso = Psi(I1bar, I2bar) (module docstring), with b1 b2 b3 = 1 written out:
    d1 = (sqrt 2 (b1 - b2), 2/sqrt 6 (b1 + b2 - 2 b3)), d2 = (sqrt 2 (b1 - b2) b3,
    2/sqrt 6 (2 b1 b2 - (b1 + b2) b3)), 4 D(bbar) = (2 s, 2/sqrt 3 d, 2/3 (s + 4 b3)) and
    I1bar 4 D(bbar) + d1 d1^T - 8 D(bbar^2) = (2 s b3, -2/sqrt 3 d b3, 2/3 (4 b1 b2 + s b3))
    (s = b1 + b2, d = b1 - b2)."""
    zeta = np.exp((2.0 / SQRT6) * z)
    eps = np.exp(SQRT2 * y)
    b1, b2 = zeta * eps, zeta / eps
    p12 = zeta * zeta  # b1 b2
    b3 = 1.0 / p12
    s, d = b1 + b2, b1 - b2
    I2 = p12 + b3 * s if law.uses_I2 else None
    P1, P2, P11, P12, P22 = law.psi_derivatives(s + b3, I2, True)
    if scale != 1.0:
        P1, P2, P11, P12, P22 = (None if v is None else scale * v for v in (P1, P2, P11, P12, P22))
    sd = SQRT2 * d
    s2 = s - 2.0 * b3
    if P2 is None:
        ty, tz = P1 * sd, (2.0 / SQRT6) * P1 * s2
        kyy, kyz, kzz = (2.0 * P1) * s, (2.0 / SQRT3) * P1 * d, (2.0 / 3.0) * P1 * (s + 4.0 * b3)
    else:  # Psi_1 d1 + Psi_2 d2 and its moduli, gathered
        P2b3 = P2 * b3
        up, down = P1 + P2b3, P1 - P2b3
        sb = s * b3
        c = 2.0 * p12
        ty, kyy, kyz = up * sd, 2.0 * up * s, (2.0 / SQRT3) * down * d
        tz = (2.0 / SQRT6) * (P1 * s2 + P2 * (c - sb))
        kzz = (2.0 / 3.0) * (P1 * (s + 4.0 * b3) + P2 * (2.0 * c + sb))
    if P11 is None and P12 is None and P22 is None:
        return ty, tz, kyy, kyz, kzz
    d1y, d1z = sd, (2.0 / SQRT6) * s2
    d2y, d2z = sd * b3, (2.0 / SQRT6) * (2.0 * p12 - s * b3)
    if P11 is not None:
        kyy, kyz, kzz = kyy + P11 * (d1y * d1y), kyz + P11 * (d1y * d1z), kzz + P11 * (d1z * d1z)
    if P12 is not None:
        kyy, kyz, kzz = (
            kyy + P12 * (2.0 * d1y * d2y),
            kyz + P12 * (d1y * d2z + d2y * d1z),
            kzz + P12 * (2.0 * d1z * d2z),
        )
    if P22 is not None:
        kyy, kyz, kzz = kyy + P22 * (d2y * d2y), kyz + P22 * (d2y * d2z), kzz + P22 * (d2z * d2z)
    return ty, tz, kyy, kyz, kzz


def ogden_plane(law: Ogden, y: np.ndarray, z: np.ndarray, scale: float) -> Plane:
    """t and k of Ogden's W_iso (module docstring)."""
    ty = tz = kyy = kyz = kzz = np.zeros_like(y)
    for mu_p, alpha_p in zip(law.mu, law.alpha, strict=True):
        L1, L2, L3 = exponentials(alpha_p, y, z)
        s12, d12 = L1 + L2, L1 - L2
        c = 2.0 * scale * mu_p / alpha_p
        ty = ty + (c / SQRT2) * d12
        tz = tz + (c / SQRT6) * (s12 - 2.0 * L3)
        Dyy, Dyz, Dzz = diagonal(L1, L2, L3)
        w = 2.0 * scale * mu_p
        kyy, kyz, kzz = kyy + w * Dyy, kyz + w * Dyz, kzz + w * Dzz
    return ty, tz, kyy, kyz, kzz
