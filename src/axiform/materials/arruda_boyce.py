"""Arruda-Boyce (eight chain), Abaqus' five-term series:
W_iso = mu sum_{i=1..5} c_i / lambda_m^(2i-2) (I1_bar^i - 3^i),
c = (1/2, 1/20, 11/1050, 19/7000, 519/673750); lambda_m the locking stretch."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .invariant import InvariantLaw
from .registry import FitFamily, Key, LawEntry, positive, register

SERIES = np.array([1.0 / 2.0, 1.0 / 20.0, 11.0 / 1050.0, 19.0 / 7000.0, 519.0 / 673750.0])


@dataclass(frozen=True)
class ArrudaBoyce(InvariantLaw):
    """Arruda-Boyce plus kappa/2 (J - 1)^2; mu is Abaqus' mu (the initial shear modulus is
    mu (1 + 3/(5 lm^2) + 99/(175 lm^4) + 513/(875 lm^6) + 42039/(67375 lm^8)))."""

    mu: float
    lambda_m: float
    kappa: float

    def coefficients(self) -> list:
        """a_i = mu c_i / lambda_m^(2i-2), i = 1..5, so that W_iso = sum a_i (I1_bar^i - 3^i)
        (numbers, or arrays where mu or lambda_m are one per point)."""
        return [self.mu * c / self.lambda_m ** (2.0 * i) for i, c in enumerate(SERIES)]

    @property
    def shear_modulus(self) -> float:
        """Initial shear modulus 2 dW/dI1_bar at I1_bar = 3."""
        return 2.0 * sum(i * a * 3.0 ** (i - 1) for i, a in enumerate(self.coefficients(), 1))

    def psi(self, I1b: np.ndarray, I2b: np.ndarray | None) -> np.ndarray:
        return sum(a * (I1b**i - 3.0**i) for i, a in enumerate(self.coefficients(), 1))

    def psi_derivatives(self, I1b: np.ndarray, I2b: np.ndarray | None, tangent: bool) -> tuple:
        a = self.coefficients()
        W1 = sum(i * ai * I1b ** (i - 1) for i, ai in enumerate(a, 1))
        W11 = sum(i * (i - 1) * ai * I1b ** (i - 2) for i, ai in enumerate(a[1:], 2)) if tangent else None
        return W1, None, W11, None, None


def _from_case(c: dict, kappa, mu0) -> ArrudaBoyce:
    """The law of the case file's constants; Abaqus' mu from the initial shear modulus where
    mu is left out (mu0 / mu depends on lambda_m alone)."""
    mu = c["mu"] if c["mu"] is not None else mu0("mu") / ArrudaBoyce(1.0, c["lambda_m"], kappa).shear_modulus
    return ArrudaBoyce(mu, c["lambda_m"], kappa)


def _fit(terms: int) -> FitFamily:
    """mu linear; lambda_m > 1."""
    return FitFamily(
        ("mu",),
        ("lambda_m",),
        lambda a, b: ArrudaBoyce(a[0], b[0], 1.0),
        ("positive",),
        lambda data: (np.array([1.0 + 1e-9]), np.array([np.inf])),
        lambda data: [np.array([v]) for v in (1.5, 3.0, 6.0, 12.0, 50.0)],
    )


def _locking(v: float) -> bool:
    return v > 1


KEYS = (Key("mu", positive, "must be > 0"), Key("lambda_m", _locking, "must be > 1 (a locking stretch)"))
register(LawEntry("arruda-boyce", ArrudaBoyce, KEYS, _from_case, "mu", _fit))
