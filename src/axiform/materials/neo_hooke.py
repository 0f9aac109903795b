"""Neo-Hooke: W = C1 (I1_bar - 3) + kappa/2 (J - 1)^2, Mooney-Rivlin with C2 = 0."""

from __future__ import annotations

from typing import TYPE_CHECKING

from .registry import FitFamily, Key, LawEntry, positive, register

if TYPE_CHECKING:
    from .mooney_rivlin import MooneyRivlin


def NeoHooke(C1: float, kappa: float) -> MooneyRivlin:
    """Neo-Hooke as Mooney-Rivlin with C2 = 0 (its hand-written P and A); mu = 2 C1.  The law
    module is imported here, not above, so that neo-Hooke registers first (the case file's
    order of the laws)."""
    from .mooney_rivlin import MooneyRivlin

    return MooneyRivlin(C1, 0.0, kappa)


def _from_case(c: dict, kappa, mu0) -> MooneyRivlin:
    """The law of the case file's C1 (from E and nu where left out: mu = 2 C1)."""
    return NeoHooke(c["C1"] if c["C1"] is not None else mu0("C1") / 2.0, kappa)


def _fit(terms: int) -> FitFamily:
    """C1 > 0, linear."""
    return FitFamily(("C1",), (), lambda a, b: NeoHooke(a[0], 1.0), ("positive",))


register(LawEntry("neo-hooke", NeoHooke, (Key("C1", positive, "must be > 0"),), _from_case, "C1", _fit))
