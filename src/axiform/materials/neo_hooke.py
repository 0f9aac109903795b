"""Neo-Hooke: W = C1 (I1_bar - 3) + kappa/2 (J - 1)^2, Mooney-Rivlin with C2 = 0."""

from __future__ import annotations

from .mooney_rivlin import MooneyRivlin


def NeoHooke(C1: float, kappa: float) -> MooneyRivlin:
    """Neo-Hooke as Mooney-Rivlin with C2 = 0 (its hand-written P and A); mu = 2 C1."""
    return MooneyRivlin(C1, 0.0, kappa)
