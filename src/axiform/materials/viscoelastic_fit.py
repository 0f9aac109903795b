"""Fitting a Prony series to a relaxation modulus or to dynamic (DMA) moduli, and the WLF
constants to shift factors: pure functions, arrays in, arrays out (the command is
app/fit_viscoelastic.py).

The series is the project's (materials.viscoelastic.Prony):
    E(t) = E0 (1 - sum_i g_i (1 - exp(-t / tau_i))) = E_inf + sum_i E_i exp(-t / tau_i),
with E_i = E0 g_i and the long-term modulus E_inf = E0 (1 - sum g_i); in frequency (w = 2 pi f)
    E'(w) = E_inf + sum_i E_i w^2 tau_i^2 / (1 + w^2 tau_i^2),
    E''(w) = sum_i E_i w tau_i / (1 + w^2 tau_i^2).
Both are linear in (E_inf, E_1..E_n) at fixed tau_i.  The fit:
1. tau_i log-spaced over the data's span [t_min, t_max] (DMA: t = 1 / w), one in the middle
   of each of n equal slices of log t: a grid with no guess of the material;
2. the moduli by non-negative least squares (scipy.optimize.nnls) on the relative errors
   (model - data) / data: a convex problem with one answer, every E_i >= 0 by construction;
3. from there, scipy.optimize.least_squares on (E_inf, E_i, log tau_i) with the analytic
   Jacobian, E >= 0 and tau_i within [t_min, t_max] (beyond the data a term cannot be told
   from E0 or E_inf): it only lowers the residual of step 2, and with as many terms as the
   material has it finds their times, which a fixed grid cannot;
4. terms left with g_i < G_MIN (no modulus: the fixed grid put them where the data need
   none) are dropped, as the case file requires g_i > 0.

WLF: log10 a_T = -C1 (T - T_ref) / (C2 + T - T_ref) (+ b, the shift of T_ref in the data's
own convention, when T_ref is not where the data's shift is 0), least squares on log10 a_T
from the linearised solution (T - T_ref) / log10 a_T = -(C2 + T - T_ref) / C1, with C1 >= 0
and C2 + T - T_ref >= 0 over the data and at T_ref (C2 >= 0): the iterates never cross the
pole; a fit that ends on it is the caller's to refuse.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.optimize import least_squares, nnls

from .prony import MAX_TERMS

G_MIN = 1e-8  # a term carrying less than this fraction of E0 is no term


@dataclass(frozen=True)
class PronyFit:
    """Instantaneous modulus E0, g (n,), tau (n,) in increasing tau, the long-term modulus
    E_inf = E0 (1 - sum g), the relative residuals (m,) at the data, the terms dropped."""

    E0: float
    g: np.ndarray
    tau: np.ndarray
    long_term: float
    residual: np.ndarray
    dropped: int


@dataclass(frozen=True)
class WLFFit:
    """C1, C2 at the reference T_ref, the offset b = the data's log10 a_T at T_ref (0 when
    T_ref is the data's own reference), the residuals (m,) of log10 a_T."""

    C1: float
    C2: float
    reference: float
    offset: float
    residual: np.ndarray


def relaxation_modulus(E0: float, g: np.ndarray, tau: np.ndarray, t: np.ndarray) -> np.ndarray:
    """E(t) (m,) of the series at times t (m,)."""
    t = np.asarray(t, float)[:, None]
    return E0 * (1.0 - (np.asarray(g) * (1.0 - np.exp(-t / np.asarray(tau)))).sum(-1))


def dynamic_moduli(E0: float, g: np.ndarray, tau: np.ndarray, f: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Storage E' (m,) and loss E'' (m,) moduli of the series at frequencies f (m,) in Hz."""
    wt = 2.0 * np.pi * np.asarray(f, float)[:, None] * np.asarray(tau)
    Ei = E0 * np.asarray(g)
    storage = E0 * (1.0 - np.sum(g)) + (Ei * wt**2 / (1.0 + wt**2)).sum(-1)
    return storage, (Ei * wt / (1.0 + wt**2)).sum(-1)


def decades(t_min: float, t_max: float) -> int:
    """The default number of terms: one per decade of [t_min, t_max], 1 to MAX_TERMS."""
    return int(np.clip(round(np.log10(t_max / t_min)), 1, MAX_TERMS))


def time_grid(t_min: float, t_max: float, n: int) -> np.ndarray:
    """n times (n,) log-spaced over [t_min, t_max], each in the middle of its slice."""
    return t_min * (t_max / t_min) ** ((np.arange(n) + 0.5) / n)


def relaxation_basis(t: np.ndarray, tau: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Columns (m, 1 + n) of E(t) for E_inf = 1, E_i = 1, and their derivatives (m, n) by
    log tau_i per unit E_i."""
    x = np.asarray(t, float)[:, None] / tau
    e = np.exp(-x)
    return np.hstack([np.ones((len(x), 1)), e]), e * x


def dynamic_basis(f: np.ndarray, tau: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Rows (2m, 1 + n): storage then loss moduli for E_inf = 1, E_i = 1, and their
    derivatives (2m, n) by log tau_i per unit E_i."""
    wt = 2.0 * np.pi * np.asarray(f, float)[:, None] * tau
    d = 1.0 + wt**2
    m = len(wt)
    storage = np.hstack([np.ones((m, 1)), wt**2 / d])
    loss = np.hstack([np.zeros((m, 1)), wt / d])
    return np.vstack([storage, loss]), np.vstack([2.0 * wt**2 / d**2, wt * (1.0 - wt**2) / d**2])


def fit_prony(basis, x: np.ndarray, data: np.ndarray, span: tuple[float, float], n: int) -> PronyFit:
    """The series of n terms nearest the data (m,) in relative error; basis(x, tau) gives
    the model's columns and their log-tau derivatives (relaxation_basis, dynamic_basis),
    span = (t_min, t_max) the times the data resolve."""
    scale = float(np.median(data))
    w = scale / data  # relative errors, the moduli in units of the data's median
    tau0 = time_grid(*span, n)
    A, _ = basis(x, tau0)
    moduli, _ = nnls(A * w[:, None], np.full(len(data), 1.0), maxiter=50 * (n + 1))

    def residual(p):
        A, _ = basis(x, np.exp(p[n + 1 :]))
        return A @ p[: n + 1] * w - 1.0

    def jacobian(p):
        A, dA = basis(x, np.exp(p[n + 1 :]))
        return np.hstack([A, dA * p[1 : n + 1]]) * w[:, None]

    p0 = np.concatenate([moduli, np.log(tau0)])
    lo = np.concatenate([np.zeros(n + 1), np.full(n, np.log(span[0]))])
    hi = np.concatenate([np.full(n + 1, np.inf), np.full(n, np.log(span[1]))])
    sol = least_squares(
        residual,
        p0,
        jac=jacobian,
        bounds=(lo, hi),
        x_scale="jac",
        xtol=1e-15,
        ftol=1e-15,
        gtol=1e-15,
        max_nfev=200 * (n + 1),
    )
    p = sol.x if sol.cost <= 0.5 * np.sum(residual(p0) ** 2) else p0
    E0 = float(p[: n + 1].sum())
    g, tau = p[1 : n + 1] / E0, np.exp(p[n + 1 :])
    keep = g >= G_MIN
    order = np.argsort(tau[keep])
    g, tau = g[keep][order], tau[keep][order]
    long_term = E0 - float((E0 * g).sum())
    A, _ = basis(x, tau)
    r = A @ np.concatenate([[long_term], E0 * g]) * w - 1.0
    return PronyFit(E0 * scale, g, tau, long_term * scale, r, int(n - keep.sum()))


def fit_relaxation(t: np.ndarray, modulus: np.ndarray, n: int) -> PronyFit:
    """n-term series of a relaxation modulus (m,) at times t (m,), t increasing > 0."""
    t = np.asarray(t, float)
    return fit_prony(relaxation_basis, t, np.asarray(modulus, float), (float(t[0]), float(t[-1])), n)


def fit_dynamic(f: np.ndarray, storage: np.ndarray, loss: np.ndarray, n: int) -> PronyFit:
    """n-term series of storage and loss moduli (m,) at frequencies f (m,) in Hz, f
    increasing > 0; tau spans 1 / (2 pi f).  residual: storage's (m) then loss's (m)."""
    f = np.asarray(f, float)
    span = (1.0 / (2.0 * np.pi * f[-1]), 1.0 / (2.0 * np.pi * f[0]))
    return fit_prony(dynamic_basis, f, np.concatenate([storage, loss]).astype(float), span, n)


def wlf_shift(T: np.ndarray, C1: float, C2: float, reference: float) -> np.ndarray:
    """log10 a_T (m,) at temperatures T (m,)."""
    dT = np.asarray(T, float) - reference
    return -C1 * dT / (C2 + dT)


def zero_crossing(T: np.ndarray, log_shift: np.ndarray) -> float | None:
    """The temperature where log10 a_T (m,), decreasing in T (m,) increasing, is 0 by
    linear interpolation; None if the data do not reach 0."""
    if not log_shift[-1] <= 0.0 <= log_shift[0]:
        return None
    return float(np.interp(0.0, log_shift[::-1], T[::-1]))


def fit_wlf(T: np.ndarray, log_shift: np.ndarray, reference: float, offset: bool) -> WLFFit:
    """C1, C2 (and the offset b if `offset`) of log10 a_T = b - C1 dT / (C2 + dT), dT = T -
    reference, by least squares on log10 a_T (m,) at T (m,)."""
    T, y = np.asarray(T, float), np.asarray(log_shift, float)
    dT = T - reference
    b0 = float(np.interp(reference, T, y)) if offset else 0.0
    use = (np.abs(dT) > 1e-9 * (np.ptp(T) + 1.0)) & (y != b0)  # dT / (y - b0) is defined
    C1, C2 = 17.44, 51.6 + max(0.0, -dT.min())  # the universal constants, if the line fails
    if use.sum() >= 2:
        slope, intercept = np.polyfit(dT[use], dT[use] / (y[use] - b0), 1)
        if slope < 0 and -intercept / slope + dT.min() > 0:
            C1, C2 = -1.0 / slope, intercept / slope
    pole = max(-dT.min(), 0.0)  # C2 above it: C2 + dT > 0 over the data and at T_ref

    def residual(p):
        return wlf_shift(T, p[0], p[1], reference) + (p[2] if offset else 0.0) - y

    def jacobian(p):
        d = p[1] + dT
        J = np.stack([-dT / d, p[0] * dT / d**2], axis=1)
        return np.hstack([J, np.ones((len(T), 1))]) if offset else J

    p0 = np.array([C1, C2, b0] if offset else [C1, C2])
    lo = np.array([0.0, pole, -np.inf] if offset else [0.0, pole])
    sol = least_squares(
        residual,
        p0,
        jac=jacobian,
        bounds=(lo, np.full(len(p0), np.inf)),
        x_scale="jac",
        xtol=1e-15,
        ftol=1e-15,
        gtol=1e-15,
        max_nfev=2000,
    )
    p = sol.x
    return WLFFit(float(p[0]), float(p[1]), reference, float(p[2]) if offset else 0.0, residual(p))
