"""The isochoric part of a law in principal logarithmic strains: the principal Kirchhoff
stresses t_i = dW_iso/de_i and K_ij = dt_i/de_j at e_i = ln(lambda_i) (3, n), what the local
update of a viscous network (network.py) evaluates a few times per point.

With bbar_i = J^(-2/3) lambda_i^2 (dbbar_i/de_j = 2 bbar_i (delta_ij - 1/3)):
- a law of the isochoric invariants (invariant.InvariantLaw, W_iso = Psi(I1bar, I2bar)):
  t = Psi_1 d1 + Psi_2 d2 with d1_j = dI1bar/de_j = 2 bbar_j - 2/3 I1bar and d2_j = dI2bar/de_j
  = I1bar d1_j - 2 bbar_j^2 + 2/3 sum bbar_i^2, K from Psi's second derivatives;
- Ogden, W_iso = sum_p 2 mu_p / alpha_p^2 (sum_i lbar_i^alpha_p - 3): t_j = sum_p 2 mu_p /
  alpha_p (lbar_j^alpha_p - 1/3 sum_i lbar_i^alpha_p);
- any other law: its stress_rows at the diagonal F = diag(lambda) (5 x 5 work per point).
All three give the same numbers (a test); the first two on (3, n) arrays only.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from .base import Hyperelastic
from .invariant import InvariantLaw
from .ogden import Ogden

Rows = tuple[np.ndarray, np.ndarray]
PRINCIPAL = (0, 3, 4)  # components of x holding the principal stretches of a diagonal F
THIRD = 1.0 / 3.0


def principal_function(law: Hyperelastic, scale: float = 1.0) -> Callable[[np.ndarray], Rows]:
    """e (3, n) -> (t (3, n), K (3, 3, n)) of `scale` times the law's isochoric part."""
    if isinstance(law, InvariantLaw):
        return lambda e: invariant_principal(law, e, scale)
    if isinstance(law, Ogden):
        return lambda e: ogden_principal(law, e, scale)
    return lambda e: generic_principal(law, e, scale)


def generic_principal(law: Hyperelastic, e: np.ndarray, scale: float) -> Rows:
    """t_i = l_i P_i, K_ij = delta_ij t_i + l_i l_j A_ij from the law's P and A at diag(l)."""
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


def invariant_principal(law: InvariantLaw, e: np.ndarray, scale: float) -> Rows:
    """t and K of W_iso = Psi(I1bar, I2bar) (module docstring)."""
    eb = e - e.mean(0)
    b = np.exp(2.0 * eb)  # bbar_i
    I1 = b.sum(0)
    bb = b * b
    S2 = bb.sum(0)
    I2 = 0.5 * (I1 * I1 - S2) if law.uses_I2 else None
    P1, P2, P11, P12, P22 = law.psi_derivatives(I1, I2, True)
    d1 = 2.0 * b - 2.0 * THIRD * I1
    t = P1 * d1
    # dd1_j/de_k = 4 b_j (delta_jk - 1/3) - 2/3 d1_k
    dd1 = -4.0 * THIRD * b[:, None] - 2.0 * THIRD * d1[None]
    for j in range(3):
        dd1[j, j] += 4.0 * b[j]
    K = P1 * dd1
    if P11 is not None:
        K += P11 * (d1[:, None] * d1[None])
    if P2 is not None:
        d2 = I1 * d1 - 2.0 * bb + 2.0 * THIRD * S2
        t += P2 * d2
        # dd2_j/de_k = d1_j d1_k + I1 dd1_jk - 8 b_j^2 (delta_jk - 1/3) + 8/3 b_k^2 - 8/9 sum b^2
        dd2 = d1[:, None] * d1[None] + I1 * dd1 + 8.0 * THIRD * (bb[:, None] + bb[None]) - 8.0 / 9.0 * S2
        for j in range(3):
            dd2[j, j] -= 8.0 * bb[j]
        K += P2 * dd2
        if P12 is not None:
            K += P12 * (d1[:, None] * d2[None] + d2[:, None] * d1[None])
        if P22 is not None:
            K += P22 * (d2[:, None] * d2[None])
    return scale * t, scale * K


def ogden_principal(law: Ogden, e: np.ndarray, scale: float) -> Rows:
    """t and K of Ogden's W_iso: t_j = sum_p 2 mu_p/alpha_p (L_pj - S_p/3), L_pj = lbar_j^alpha_p,
    S_p = sum_j L_pj; K_jk = sum_p 2 mu_p (L_pj (delta_jk - 1/3) - L_pk/3 + S_p/9)."""
    eb = e - e.mean(0)
    t = np.zeros_like(e)
    K = np.zeros((3, 3, e.shape[1]))
    for mu_p, alpha_p in zip(law.mu, law.alpha, strict=True):
        L = np.exp(alpha_p * eb)
        S = L.sum(0)
        t += 2.0 * mu_p / alpha_p * (L - THIRD * S)
        Kp = -THIRD * (L[:, None] + L[None]) + S / 9.0
        for j in range(3):
            Kp[j, j] += L[j]
        K += 2.0 * mu_p * Kp
    return scale * t, scale * K
