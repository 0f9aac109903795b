"""Yeoh: W_iso = C10 (I1_bar - 3) + C20 (I1_bar - 3)^2 + C30 (I1_bar - 3)^3."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .invariant import InvariantLaw
from .registry import FitFamily, Key, LawEntry, positive, register


@dataclass(frozen=True)
class Yeoh(InvariantLaw):
    """Yeoh (Abaqus reduced polynomial, N = 3) plus kappa/2 (J - 1)^2; mu = 2 C10."""

    C10: float
    C20: float
    C30: float
    kappa: float

    @property
    def shear_modulus(self) -> float:
        """Initial shear modulus mu = 2 C10."""
        return 2.0 * self.C10

    def psi(self, I1b: np.ndarray, I2b: np.ndarray | None) -> np.ndarray:
        e = I1b - 3.0
        return e * (self.C10 + e * (self.C20 + e * self.C30))

    def psi_derivatives(self, I1b: np.ndarray, I2b: np.ndarray | None, tangent: bool) -> tuple:
        e = I1b - 3.0
        W1 = self.C10 + e * (2.0 * self.C20 + 3.0 * self.C30 * e)
        W11 = 2.0 * self.C20 + 6.0 * self.C30 * e if tangent else None
        return W1, None, W11, None, None


def _from_case(c: dict, kappa, mu0) -> Yeoh:
    """The law of the case file's constants (C10 from E and nu where left out: mu = 2 C10)."""
    return Yeoh(c["C10"] if c["C10"] is not None else mu0("C10") / 2.0, c["C20"], c["C30"], kappa)


def _fit(terms: int) -> FitFamily:
    """C10, C20, C30 linear; C10 > 0."""
    return FitFamily(("C10", "C20", "C30"), (), lambda a, b: Yeoh(a[0], a[1], a[2], 1.0), ("positive", "free", "free"))


register(LawEntry("yeoh", Yeoh, (Key("C10", positive, "must be > 0"), Key("C20"), Key("C30")), _from_case, "C10", _fit))
