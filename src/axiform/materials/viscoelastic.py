"""A hyperelastic law with a Prony series on its isochoric part (prony.py): the law of
networks in parallel (parallel.NetworkLaw) with the series and no network."""

from __future__ import annotations

from .base import Hyperelastic
from .parallel import NetworkLaw
from .prony import Prony
from .temperature import Shift, TemperatureDependent

__all__ = ["Prony", "Viscoelastic"]


class Viscoelastic(NetworkLaw):
    """`law` (materials.Hyperelastic, or one whose constants are tables of T) as the
    instantaneous response, with the Prony series `prony` on its isochoric part; `shift` the
    shift of its relaxation times (or None: the model's, System)."""

    def __init__(self, law: Hyperelastic | TemperatureDependent, prony: Prony, shift: Shift | None = None):
        super().__init__(law, prony=prony, shift=shift)

    @property
    def law(self) -> Hyperelastic | TemperatureDependent:
        """The instantaneous law."""
        return self.equilibrium
