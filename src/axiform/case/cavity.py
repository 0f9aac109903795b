"""The [[cavity]] tables of the case file: the gas cavities and their control;
and the model's cavities they make."""

from __future__ import annotations

from typing import Annotated, Literal

from pydantic import Field, model_validator

from ..fem.cavity import Cavity, CavityError
from ..fem.mesh import Mesh
from ..fem.selectors import select_edges
from ..model.model import Model
from .base import CaseError, CurveMixin, PositiveFloat, Selector


class CavitySpec(CurveMixin):
    """A gas cavity: the wall edges that bound the gas, and its control."""

    name: Annotated[str, Field(min_length=1)]
    boundary: Selector
    control: Literal["pressure", "volume", "gas"] = "pressure"
    pressure: float | None = None
    volume: PositiveFloat | None = None
    content: PositiveFloat | None = None
    ambient: PositiveFloat | None = None

    @model_validator(mode="after")
    def _control(self):
        need = {"pressure": ("pressure",), "volume": ("volume",), "gas": ("content", "ambient")}[self.control]
        for key in need:
            if getattr(self, key) is None:
                raise ValueError(f"control = \"{self.control}\" needs '{key}'")
        for key in ("pressure", "volume", "content", "ambient"):
            if key not in need and getattr(self, key) is not None:
                raise ValueError(f"'{key}' does not belong to control = \"{self.control}\"")
        return self

    @property
    def value(self) -> float:
        value = {"pressure": self.pressure, "volume": self.volume, "gas": self.content}[self.control]
        assert value is not None, f"control = {self.control} has its value (_control)"
        return value


def build_cavities(model: Model, mesh: Mesh, specs: list[CavitySpec]) -> dict[str, Cavity]:
    """The model's gas cavities of the [[cavity]] tables, by name (a name used twice is refused)."""
    cavities = {}
    for i, c in enumerate(specs):
        if c.name in cavities:
            raise CaseError(f"cavity[{i}].name: '{c.name}' is used twice")
        edges = select_edges(mesh, c.boundary.model_dump(), f"cavity[{i}].boundary")
        try:
            cavities[c.name] = model.cavity(edges, c.name, c.control, c.value, c.ambient or 0.0, c.build_curve())
        except CavityError as exc:
            raise CaseError(f"cavity[{i}].boundary: {exc}") from None
    return cavities
