"""The [thermal] and [[convection]] tables of the case file: heat conduction in the wall
(fem.heat), and the films on its faces.

    [thermal]
    conductivity = 0.2            # k (a number > 0, or a table [[T, value], ...])
    density = 1.0e-9              # rho, of the reference configuration (absent: [material] density)
    specific_heat = 1.9e9         # c (k / (rho c) is the diffusivity)
    [[convection]]
    on = { set = "outer" }        # boundary edges (as [[pressure]] on)
    h = 1.0e-5                    # film coefficient
    ambient = 25.0                # x curve (absent: constant)
    curve = [[0.0, 1.0], [2.0, 0.8]]

With [[contact]] `temperature` (the mould's) and `conductance` h_c, heat flows h_c (T -
T_mould) through every slave node in contact.  Insulated where nothing is said.  Needs
[temperature] (the initial field).  Errors name the key.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

from pydantic import field_validator

from ..fem.curves import Curve
from ..fem.heat import Conductance, Conduction, Film, Property, constant
from ..fem.mesh import Mesh
from ..fem.selectors import select_edges
from ..materials.temperature import Table
from ..model.model import Model, contact_conductance
from .base import CaseError, CurveMixin, PositiveFloat, Selector, Strict


def _property(value: Any) -> Any:
    """A number > 0, or a table [[T, value], ...] (T increasing, values > 0)."""
    if isinstance(value, bool):
        raise ValueError(f"must be a number or a table [[T, value], ...], got {value!r}")
    if isinstance(value, int | float):
        if not value > 0:
            raise ValueError(f"must be > 0, got {value}")
        return float(value)
    if not isinstance(value, list) or not value or not all(isinstance(r, list) and len(r) == 2 for r in value):
        raise ValueError(f"must be a number or a table [[T, value], ...] with no holes, got {value!r}")
    if not all(isinstance(x, int | float) and not isinstance(x, bool) for row in value for x in row):
        raise ValueError(f"every temperature and value of the table must be a number, got {value!r}")
    T = [r[0] for r in value]
    if any(b <= a for a, b in zip(T, T[1:], strict=False)):
        raise ValueError("a table of the temperature: T must increase from row to row")
    if not all(v > 0 for _, v in value):
        raise ValueError("every value of the table must be a number > 0")
    return [[float(t), float(v)] for t, v in value]


def _scaled(value: float, knots) -> Callable[[float], float]:
    """t -> value x f(t) (f = 1 without knots)."""
    curve = None if knots is None else Curve(knots)
    return (lambda t: value) if curve is None else (lambda t: value * curve(t))


def _as_property(value: float | list) -> Property:
    return constant(value) if isinstance(value, float) else Table.of(value)


class ThermalSpec(Strict):
    """The [thermal] table (see the module docstring)."""

    conductivity: Any
    density: Any = None  # absent: the material's ([material] density)
    specific_heat: Any

    @field_validator("conductivity", "density", "specific_heat", mode="before")
    @classmethod
    def _positive(cls, value: Any) -> Any:
        return _property(value)


class ConvectionSpec(CurveMixin):
    """A [[convection]] table: a film h (T - ambient x f(t)) on boundary edges."""

    on: Selector
    h: PositiveFloat
    ambient: float

    def ambient_of_time(self):
        """ambient x f(t), f = 1 without a curve."""
        return _scaled(self.ambient, self.curve)


def build_conduction(
    model: Model,
    mesh: Mesh,
    thermal: ThermalSpec | None,
    convection: list[ConvectionSpec],
    contacts: list,
    density: float | None = None,
) -> None:
    """Give the model its heat conduction ([thermal], the films, the contact conductances of
    the [[contact]] tables `contacts`; `density`: the material's, for a [thermal] without
    one); CaseError naming the key where one is missing."""
    if thermal is None:
        if convection:
            raise CaseError("convection: a film needs the case's [thermal] (conductivity, density, specific_heat)")
        for k, c in enumerate(contacts):
            if c.conductance is not None:
                raise CaseError(f"contact[{k}].conductance: needs the case's [thermal]")
        return
    if model.temperature is None:
        raise CaseError("thermal: heat conduction needs the initial temperature: add [temperature] initial = ...")
    rho = thermal.density if thermal.density is not None else density
    if rho is None:
        raise CaseError("thermal.density: missing (give it here, or the material's: [material] density)")
    films = [
        Film(
            select_edges(mesh, c.on.model_dump(), f"convection[{i}].on"),
            c.h,
            c.ambient_of_time(),
            None if c.curve is None else Curve(c.curve),
        )
        for i, c in enumerate(convection)
    ]
    conductances = []
    for k, c in enumerate(contacts):
        if c.conductance is not None:
            depth = model.contacts[k].depth
            if c.conductance_gap > depth:
                raise CaseError(
                    f"contact[{k}].conductance_gap: {c.conductance_gap:g} is beyond the contact search "
                    f"depth {depth:g} (the nodes farther from the surface are not seen): give depth = "
                    f"{c.conductance_gap:g} or more, or a smaller gap"
                )
            mould = _scaled(c.temperature, c.temperature_curve)
            curve = None if c.temperature_curve is None else Curve(c.temperature_curve)
            conductances.append(Conductance(c.conductance, mould, contact_conductance(k, c.conductance_gap), curve))
    conductivity, heat = _as_property(thermal.conductivity), _as_property(thermal.specific_heat)
    model.conduct(Conduction(mesh, conductivity, _as_property(rho), heat, films, conductances))
