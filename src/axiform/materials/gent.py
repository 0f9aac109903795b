"""Gent: W_iso = -mu Jm / 2 ln(1 - (I1_bar - 3) / Jm); mu the initial shear modulus, Jm the
limit of I1_bar - 3 (chain locking).  Beyond the limit W is not defined: P and A are NaN there,
and the solver cuts the step back."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .homogeneous import MODES, Data, kinematics
from .invariant import InvariantLaw
from .registry import FitFamily, Key, LawEntry, positive, register


@dataclass(frozen=True)
class Gent(InvariantLaw):
    """Gent plus kappa/2 (J - 1)^2."""

    mu: float
    Jm: float
    kappa: float

    @property
    def shear_modulus(self) -> float:
        """Initial shear modulus mu."""
        return self.mu

    def _room(self, I1b):
        """1 - (I1_bar - 3) / Jm, NaN where it is not positive."""
        r = 1.0 - (I1b - 3.0) / self.Jm
        return np.where(r > 0.0, r, np.nan)

    def psi(self, I1b: np.ndarray, I2b: np.ndarray | None) -> np.ndarray:
        return -0.5 * self.mu * self.Jm * np.log(self._room(I1b))

    def psi_derivatives(self, I1b: np.ndarray, I2b: np.ndarray | None, tangent: bool) -> tuple:
        W1 = 0.5 * self.mu / self._room(I1b)
        W11 = 2.0 / (self.mu * self.Jm) * W1 * W1 if tangent else None
        return W1, None, W11, None, None


def _from_case(c: dict, kappa, mu0) -> Gent:
    """The law of the case file's constants (mu from E and nu where left out)."""
    return Gent(c["mu"] if c["mu"] is not None else mu0("mu"), c["Jm"], kappa)


def _max_I1(data: Data) -> float:
    """The largest I1 of the data points (incompressible: I1 = sum of squared stretches)."""
    return max(
        float(np.sum(kinematics(m, data.stretch[data.mode == i]) ** 2, axis=-1).max(initial=3.0))
        for i, m in enumerate(MODES)
    )


def _fit(terms: int) -> FitFamily:
    """mu linear; Jm beyond the largest I1 - 3 of the data (W defined at every point)."""
    return FitFamily(
        ("mu",),
        ("Jm",),
        lambda a, b: Gent(a[0], b[0], 1.0),
        ("positive",),
        lambda data: (np.array([(_max_I1(data) - 3.0) * (1 + 1e-9)]), np.array([np.inf])),
        lambda data: [np.array([(_max_I1(data) - 3.0) * f]) for f in (1.05, 1.5, 3.0, 10.0, 100.0)],
    )


register(
    LawEntry(
        "gent", Gent, (Key("mu", positive, "must be > 0"), Key("Jm", positive, "must be > 0")), _from_case, "mu", _fit
    )
)
