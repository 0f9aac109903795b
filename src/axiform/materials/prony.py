"""Quasi-linear finite-strain viscoelasticity: a Prony series on the isochoric stress of any
law (Simo 1987; Abaqus' convention for g_i); the law with its series is viscoelastic.Viscoelastic
(or a parallel.NetworkLaw with `prony`).

With S_iso the isochoric second Piola-Kirchhoff stress of the law (the instantaneous
response), S = S_vol + S_iso - sum_i h_i, dh_i/dt = (g_i S_iso - h_i) / tau_i, h_i(0) = 0: a
step of strain gives the law's stress at once and relaxes as g(t) = 1 - sum g_i (1 -
exp(-t / tau_i)); the long-term response is (1 - sum g_i) times the law's isochoric part.
The volumetric part stays elastic.

Over a step of length dt, with S_iso linear in time (exact then):
    h_i' = e_i h_i + g_i (gamma_i - e_i) S_n + g_i (1 - gamma_i) S',
    e_i = exp(-dt / tau_i), gamma_i = (1 - e_i) tau_i / dt,
so that P = F S = P_law(F) - c P_iso(F) - F H0 with H0 = sum_i (e_i h_i + g_i (gamma_i - e_i)
S_n) and c = sum_i g_i (1 - gamma_i), and the consistent tangent A = A_law - c A_iso - d(F H0)/dF.

Components: F and P as everywhere, x = (F_rR, F_rZ, F_zR, F_zZ, F_tT); the symmetric S and
h_i as (S_RR, S_RZ, S_ZZ, S_TT).  History per quadrature point: h (..., m, 4) for m terms and
the committed S_iso (..., 4).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

MAX_TERMS = 8


@dataclass(frozen=True)
class Prony:
    """g_i (relative moduli, 0 < g_i, sum < 1) and tau_i (relaxation times > 0), m terms."""

    g: tuple[float, ...]
    tau: tuple[float, ...]

    def __post_init__(self):
        g, tau = np.asarray(self.g, float), np.asarray(self.tau, float)
        if not 1 <= g.size <= MAX_TERMS or g.shape != tau.shape:
            raise ValueError(f"give 1 to {MAX_TERMS} terms, as many g as tau")
        if not ((g > 0).all() and g.sum() < 1):
            raise ValueError("g: every g_i > 0 and their sum < 1")
        if not (tau > 0).all():
            raise ValueError("tau: every tau_i > 0")

    def relaxation(self, t: np.ndarray) -> np.ndarray:
        """g(t) = 1 - sum g_i (1 - exp(-t / tau_i)), the relaxation of a step of strain."""
        t = np.asarray(t, float)[..., None]
        return 1.0 - (np.asarray(self.g) * (1.0 - np.exp(-t / np.asarray(self.tau)))).sum(-1)

    def factors(self, dxi: np.ndarray | float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Per term over a step of reduced time dxi >= 0 (a number, or one per point (...)):
        e_i, a_i = g_i (gamma_i - e_i), b_i = g_i (1 - gamma_i), each (..., m)."""
        g, tau = np.asarray(self.g, float), np.asarray(self.tau, float)
        dxi = np.asarray(dxi, float)[..., None]
        e = np.exp(-dxi / tau)
        with np.errstate(divide="ignore", invalid="ignore"):
            gamma = np.where(dxi > 0, -np.expm1(-dxi / tau) * tau / np.where(dxi > 0, dxi, 1.0), 1.0)
        return e, g * (gamma - e), g * (1.0 - gamma)

    def initial(self, points: tuple[int, ...]) -> dict[str, np.ndarray]:
        """The history before the first step at quadrature points of shape `points`: no h, no S."""
        return {"h": np.zeros(points + (len(self.g), 4)), "S": np.zeros(points + (4,))}


def second_piola_rows(xt: np.ndarray, P: np.ndarray) -> np.ndarray:
    """S = F^-1 P as rows (4, n) (S_RR, S_RZ, S_ZZ, S_TT) from the rows of F and P (5, n)."""
    a, b, c, d, f = xt.reshape(5, -1)
    P = P.reshape(5, -1)
    det = a * d - b * c
    # inverse of the meridian block [[a, b], [c, d]] (rows r, z; columns R, Z)
    S = np.empty((4, a.size))
    S[0] = (d * P[0] - b * P[2]) / det
    S[1] = 0.5 * ((d * P[1] - b * P[3]) + (-c * P[0] + a * P[2])) / det
    S[2] = (-c * P[1] + a * P[3]) / det
    S[3] = P[4] / f
    return S


def viscous_rows(
    xt: np.ndarray,
    P: np.ndarray,
    A: np.ndarray | None,
    h: np.ndarray,
    S_n: np.ndarray,
    factors: tuple[np.ndarray, np.ndarray, np.ndarray],
) -> tuple[np.ndarray, np.ndarray]:
    """Add the Prony series to the law's isochoric P rows (5, n) and A rows (5, 5, n), in
    place, at F rows xt (5, n) over a step (`factors` e, a, b: (m, 1) for every point or
    (m, n) one set per point) from the committed history h (m, 4, n) and S_n (4, n); return
    the trial h' (m, 4, n) and S' (4, n) (second_piola_rows of the law's P, taken first).

    P <- (1 - c) P - F H0, A <- (1 - c) A - d(F H0)/dF, H0 = sum_i e_i h_i + (sum_i a_i) S_n,
    c = sum_i b_i (module docstring)."""
    e, a, b = factors
    S = second_piola_rows(xt, P)
    H0 = (e[:, None] * h).sum(0) + a.sum(0) * S_n  # (4, n)
    keep = 1.0 - b.sum(0)  # (n,) or (1,)
    trial = e[:, None] * h + a[:, None] * S_n + b[:, None] * S
    RR, RZ, ZZ, TT = H0
    x0, x1, x2, x3, x4 = xt
    P *= keep
    P[0] -= x0 * RR + x1 * RZ
    P[1] -= x0 * RZ + x1 * ZZ
    P[2] -= x2 * RR + x3 * RZ
    P[3] -= x2 * RZ + x3 * ZZ
    P[4] -= x4 * TT
    if A is not None:
        A *= keep
        for row, col in ((0, 0), (2, 2)):  # (F H)_iR = F_iR H_RR + F_iZ H_ZR
            A[row, col] -= RR
            A[row, col + 1] -= RZ
        for row, col in ((1, 0), (3, 2)):  # (F H)_iZ = F_iR H_RZ + F_iZ H_ZZ
            A[row, col] -= RZ
            A[row, col + 1] -= ZZ
        A[4, 4] -= TT
    return trial, S


def prony_step(
    xt: np.ndarray, P: np.ndarray, A: np.ndarray | None, state_n: dict, factors: tuple[Any, Any, Any]
) -> dict[str, np.ndarray]:
    """Add the series to the law's isochoric P rows (5, n) and A rows (5, 5, n) (or None), in
    place, over a step of factors `factors` (Prony.factors of the step's reduced time: (m,) for
    every point or (..., m) one set per point) from the committed history state_n {"h":
    (..., m, 4), "S": (..., 4)} of the n points of xt (5, n); return the trial history, arrays of
    the same shapes."""
    h = state_n["h"]
    shape, m = h.shape[:-2], h.shape[-2]
    n = xt.shape[1]
    # contiguous (m, 4, n) and (4, n) copies: every operation then runs over n numbers (on a
    # strided view the sums ran loops of length 4 and cost the law's own stress and tangent)
    h_rows = np.ascontiguousarray(h.reshape(n, m, 4).transpose(1, 2, 0))
    S_rows = np.ascontiguousarray(state_n["S"].reshape(n, 4).T)
    if factors[0].ndim == 1:
        e, a, b = (f[:, None] for f in factors)
    else:
        e, a, b = (f.reshape(n, m).T for f in factors)
    trial, S = viscous_rows(xt, P, A, h_rows, S_rows, (e, a, b))
    return {"h": trial.transpose(2, 0, 1).reshape(*shape, m, 4), "S": S.T.reshape(*shape, 4)}
