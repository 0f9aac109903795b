"""Ogden, Abaqus convention:
W_iso = sum_p 2 mu_p / alpha_p^2 (lb1^alpha_p + lb2^alpha_p + lb3^alpha_p - 3), lb_i = J^(-1/3) l_i.

The principal stretches of the axisymmetric F: the hoop stretch f, and l1, l2 of the meridian
block M (l1^2, l2^2 the eigenvalues of M^T M).  No eigenvalues are computed: with
l1 = m e^(t), l2 = m e^(-t), m^2 = l1 l2 = j2 and cosh(2 t) = w = s / (2 j2),

    l1^alpha + l2^alpha = 2 j2^beta T(w),   T(w) = cosh(beta theta),  w = cosh(theta),  beta = alpha/2,

a smooth function of (s, j2) also where l1 = l2 (theta = 0, F = I included): T'(w) =
beta sinh(beta theta) / sinh(theta) and T''(w) are taken from their Taylor series in theta
for small theta and from the closed forms elsewhere, so that no 0/0 arises.  w - 1 =
((a - d)^2 + (b + c)^2) / (2 j2) is evaluated without cancellation.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .base import ReducedLaw
from .registry import FitFamily, Key, LawEntry, register

# Taylor coefficients in theta^2 of R1 = sinh(beta theta) / sinh(theta) / beta and of
# R2 = (beta cosh(beta theta) sinh(theta) - sinh(beta theta) cosh(theta)) / sinh(theta)^3 / beta,
# as polynomials in b = beta^2 (terms theta^0 .. theta^8).
_R1_SERIES = (
    lambda b: 1.0,
    lambda b: (b - 1.0) / 6.0,
    lambda b: (b - 1.0) * (3.0 * b - 7.0) / 360.0,
    lambda b: (b - 1.0) * (3.0 * b * b - 18.0 * b + 31.0) / 15120.0,
    lambda b: (b - 1.0) * (5.0 * b**3 - 55.0 * b * b + 239.0 * b - 381.0) / 1814400.0,
)
_R2_SERIES = (
    lambda b: (b - 1.0) / 3.0,
    lambda b: (b - 1.0) * (b - 4.0) / 30.0,
    lambda b: (b - 1.0) * (b - 4.0) * (3.0 * b - 20.0) / 2520.0,
    lambda b: (b - 1.0) * (b - 4.0) * (5.0 * b * b - 80.0 * b + 336.0) / 226800.0,
    lambda b: (b - 1.0) * (b - 4.0) * (5.0 * b**3 - 140.0 * b * b + 1392.0 * b - 4800.0) / 19958400.0,
)
# below theta |beta| = 0.1 (and theta = 0.1) the series (truncation ~1e-15 relative) replaces
# the closed form of R2 (whose cancellation costs ~eps / theta^2)
_SERIES_LIMIT = 0.1


def _power_sums(beta: np.ndarray, delta: np.ndarray, tangent: bool):
    """T = cosh(beta theta), T' / beta and T'' / beta at w = 1 + delta = cosh(theta), for
    beta (m, 1) and delta (n) >= 0: arrays (m, n); T'' None unless tangent."""
    sh = np.sqrt(delta * (delta + 2.0))  # sinh(theta)
    theta = np.log1p(delta + sh)
    bt = beta * theta
    small = theta * np.maximum(np.abs(beta), 1.0) < _SERIES_LIMIT
    T = np.cosh(bt)
    t2 = theta * theta
    b = beta * beta
    series1 = sum(c(b) * t2**k for k, c in enumerate(_R1_SERIES))
    safe_sh = np.where(small, 1.0, sh)
    safe_bt = np.where(small, 1.0, bt)
    # sinh(beta theta)/(beta sinh(theta)) = (sinh(bt)/bt) (theta / sinh(theta)): no 0/0 for beta, theta != 0
    R1 = np.where(small, series1, np.sinh(safe_bt) / safe_bt * (np.where(small, 1.0, theta) / safe_sh))
    if not tangent:
        return T, R1, None
    series2 = sum(c(b) * t2**k for k, c in enumerate(_R2_SERIES))
    closed2 = (T - R1 * (1.0 + delta)) / safe_sh**2  # (cosh(beta theta) - R1 cosh(theta)) / sinh^2
    R2 = np.where(small, series2, closed2)
    return T, R1, R2


@dataclass(frozen=True)
class Ogden(ReducedLaw):
    """Ogden (1 to 6 terms, Abaqus convention) plus kappa/2 (J - 1)^2; mu = sum mu_p.

    Needs f > 0 and det M > 0 (true whenever J > 0 and the hoop stretch is positive).
    """

    mu: tuple[float, ...]
    alpha: tuple[float, ...]
    kappa: float

    def __post_init__(self):
        object.__setattr__(self, "mu", tuple(float(v) for v in np.atleast_1d(self.mu)))
        object.__setattr__(self, "alpha", tuple(float(v) for v in np.atleast_1d(self.alpha)))
        if len(self.mu) != len(self.alpha) or not 1 <= len(self.mu) <= 6:
            raise ValueError("Ogden: mu and alpha need the same number of terms, 1 to 6")
        if 0.0 in self.alpha:
            raise ValueError("Ogden: every alpha must be non-zero")

    @property
    def shear_modulus(self) -> float:
        """Initial shear modulus mu = sum mu_p."""
        return float(sum(self.mu))

    def _terms(self):
        """alpha (m, 1) and the weights 2 mu_p / alpha_p^2 (m, 1)."""
        al = np.array(self.alpha)[:, None]
        return al, 2.0 * np.array(self.mu)[:, None] / al**2

    def iso_energy(self, x: np.ndarray) -> np.ndarray:
        xt = np.moveaxis(x, -1, 0)
        a, b, c, d, f = xt
        j2 = a * d - b * c
        delta = ((a - d) ** 2 + (b + c) ** 2) / (2.0 * j2)
        al, cw = self._terms()
        al = al.reshape(-1, *([1] * j2.ndim))
        cw = cw.reshape(al.shape)
        T, _, _ = _power_sums(0.5 * al, delta, False)
        G = 2.0 * f ** (-al / 3.0) * j2 ** (al / 6.0) * T + f ** (2.0 * al / 3.0) * j2 ** (-al / 3.0)
        return (cw * (G - 3.0)).sum(axis=0)

    def _reduced(self, xt, s, j2, tangent):
        a, b, c, d, f = xt
        i_j, i_f = 1.0 / j2, 1.0 / f
        w = 0.5 * s * i_j
        delta = ((a - d) ** 2 + (b + c) ** 2) * (0.5 * i_j)  # w - 1
        al, cw = self._terms()
        beta = 0.5 * al
        T, R1, R2 = _power_sums(beta, delta, tangent)
        T1 = beta * beta * R1  # T'(w)
        # G = A1 T(w) + t2, A1 = 2 f^(-alpha/3) j2^(alpha/6), t2 = f^(2 alpha/3) j2^(-alpha/3)
        lf, lj = np.log(f), np.log(j2)
        A1 = 2.0 * np.exp(al * (lj / 6.0 - lf / 3.0))
        t2 = np.exp(al * (2.0 * lf - lj) / 3.0)
        t1 = A1 * T
        a6, a3 = al / 6.0, al / 3.0
        Gj1 = A1 * i_j * (a6 * T - w * T1)  # d(A1 T)/dj2
        g = np.stack(
            [
                (cw * A1 * T1).sum(axis=0) * (0.5 * i_j),
                (cw * (Gj1 - a3 * t2 * i_j)).sum(axis=0),
                (cw * (-a3 * t1 + 2.0 * a3 * t2)).sum(axis=0) * i_f,
            ]
        )
        if not tangent:
            return g, None
        T2 = beta * beta * R2  # T''(w)
        Gs = A1 * T1 * (0.5 * i_j)
        q, p = -a3, 2.0 * a3  # powers of j2 and f in t2
        H = np.stack(
            [
                (cw * A1 * T2).sum(axis=0) * (0.25 * i_j * i_j),
                (cw * A1 * ((a6 - 1.0) * T1 - w * T2)).sum(axis=0) * (0.5 * i_j * i_j),
                (cw * (-a3 * Gs)).sum(axis=0) * i_f,
                (cw * (A1 * (a6 * (a6 - 1.0) * T + (2.0 - 2.0 * a6) * w * T1 + w * w * T2) + q * (q - 1.0) * t2)).sum(
                    axis=0
                )
                * (i_j * i_j),
                (cw * (-a3 * Gj1 + p * q * t2 * i_j)).sum(axis=0) * i_f,
                (cw * (a3 * (a3 + 1.0) * t1 + p * (p - 1.0) * t2)).sum(axis=0) * (i_f * i_f),
            ]
        )
        return g, H


ALPHA_BOUND = 25.0  # |alpha_i| of the fit, so that lambda^alpha stays finite
ALPHA_STARTS = (
    (2.0, -2.0, 4.0, -1.0, 6.0, 1.0),
    (1.3, 5.0, -2.0, 3.0, -4.0, 8.0),
    (1.0, 3.0, 6.0, -2.0, -4.0, 9.0),
    (3.0, -1.0, 8.0, 1.5, -3.0, 5.0),
    (0.5, 4.0, -3.0, 2.0, 7.0, -1.0),
    (6.0, -4.0, 1.0, 3.0, -2.0, 10.0),
)


def _from_case(c: dict, kappa, mu0) -> Ogden:
    """The law of the case file's lists mu and alpha."""
    return Ogden(tuple(c["mu"]), tuple(c["alpha"]), kappa)


def _increasing_alpha(p: np.ndarray) -> np.ndarray:
    """The fitted constants (mu_1.., alpha_1..) with the terms in increasing alpha."""
    n = len(p) // 2
    order = np.argsort(p[n:])
    return np.concatenate([p[:n][order], p[n:][order]])


def _fit(terms: int) -> FitFamily:
    """mu_i linear (any sign), |alpha_i| <= ALPHA_BOUND, started from ALPHA_STARTS."""
    n = terms
    return FitFamily(
        tuple(f"mu_{i + 1}" for i in range(n)),
        tuple(f"alpha_{i + 1}" for i in range(n)),
        lambda a, b: Ogden(tuple(a), tuple(b), 1.0),
        ("free",) * n,
        lambda data: (np.full(n, -ALPHA_BOUND), np.full(n, ALPHA_BOUND)),
        lambda data: [np.array(s[:n]) for s in ALPHA_STARTS],
        _increasing_alpha,
    )


register(LawEntry("ogden", Ogden, (Key("mu", kind="list"), Key("alpha", kind="list")), _from_case, None, _fit, True))
