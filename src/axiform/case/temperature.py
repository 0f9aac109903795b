"""The [temperature] table of the case file: the material's initial temperature and the shift
of its relaxation times.

    [temperature]
    initial = 150.0                                      # a constant, or a table along the wall:
    # initial = { along = "s", table = [[0.0, 150.0], [40.0, 135.0]] }  # s: reference arc length (layered mesh)
    # initial = { along = "r", table = [[0.0, 150.0], [7.5, 140.0]] }   # or "z": by reference coordinate
    reference = 150.0                                    # T_ref of the shift
    shift = { wlf = { C1 = 17.44, C2 = 51.6 } }          # or { arrhenius = { activation = 8.0e3 } } (E/R, K)
    change = [[0.0, 0.0], [5.0, -30.0]]                  # optional: dT(t) added everywhere (an oven program)

Without a heat equation the temperature of a material point stays its initial value (piecewise
linear in the table, constant outside), plus the prescribed `change` dT(t) (linear between its
knots, times increasing, held after the last; refused with [thermal], where conduction computes
the temperature).  The law's constants may be tables [[T, value], ...]
of it ([material]).  Errors name the key (temperature.KEY).
"""

from __future__ import annotations

from typing import Any, Literal

import numpy as np
from pydantic import ValidationError, field_validator, model_validator

from ..fem.assembly import point_values
from ..fem.curves import Curve
from ..fem.mesh import Mesh
from ..materials.temperature import WLF, Arrhenius, Shift, Table, TemperatureDomainError
from ..model.model import Model
from .base import CaseError, PositiveFloat, Strict

# [units] temperature: the spellings of degrees Celsius and of kelvin (an Arrhenius shift needs
# the absolute temperature T + 273.15 of a case in Celsius; without the key, kelvin)
CELSIUS = ("C", "°C", "degC", "deg C", "celsius", "Celsius")
KELVIN = ("K", "kelvin", "Kelvin")


def absolute_zero(unit: str | None) -> float | None:
    """The kelvin of the unit's zero: 273.15 for degrees Celsius, 0 for kelvin and for no
    unit (the temperatures are then taken as kelvin); None for any other unit."""
    if unit is None or unit in KELVIN:
        return 0.0
    return 273.15 if unit in CELSIUS else None


def _increasing_table(rows: list[tuple[float, float]], what: str) -> list[tuple[float, float]]:
    """The rows [[x, value], ...] of a table, its abscissae increasing strictly."""
    if not rows:
        raise ValueError(f"a table needs at least one row [{what}, value]")
    x = [r[0] for r in rows]
    if any(b <= a for a, b in zip(x, x[1:], strict=False)):
        raise ValueError(f"the {what} of the table must increase from row to row")
    return rows


class InitialTable(Strict):
    """A table of the initial temperature along s (reference arc length of a layered mesh), r
    or z (reference coordinates)."""

    along: Literal["s", "r", "z"]
    table: list[tuple[float, float]]

    @field_validator("table")
    @classmethod
    def _table(cls, rows):
        return _increasing_table(rows, "positions")


class WLFSpec(Strict):
    """log10 a_T = -C1 (T - T_ref) / (C2 + T - T_ref)."""

    C1: PositiveFloat
    C2: PositiveFloat


class ArrheniusSpec(Strict):
    """ln a_T = activation (1/T - 1/T_ref), T in kelvin; activation = E/R in kelvin."""

    activation: PositiveFloat


class ShiftSpec(Strict):
    """One of wlf, arrhenius."""

    wlf: WLFSpec | None = None
    arrhenius: ArrheniusSpec | None = None

    @model_validator(mode="after")
    def _one(self):
        if (self.wlf is None) == (self.arrhenius is None):
            raise ValueError("give one of wlf = { C1, C2 } or arrhenius = { activation }")
        return self


class TemperatureSpec(Strict):
    """The [temperature] table (see the module docstring)."""

    initial: Any
    reference: float | None = None
    shift: ShiftSpec | None = None
    change: list[tuple[float, float]] | None = None

    @field_validator("change")
    @classmethod
    def _change(cls, rows):
        return None if rows is None else _increasing_table(rows, "times")

    @field_validator("initial", mode="before")
    @classmethod
    def _initial(cls, value: Any) -> float | InitialTable:
        if isinstance(value, dict):
            try:
                return InitialTable.model_validate(value)
            except ValidationError as exc:
                err = exc.errors()[0]
                where = ".".join(str(p) for p in err["loc"])
                raise ValueError(
                    f"{where}: {err['msg'].removeprefix('Value error, ')}" if where else err["msg"]
                ) from None
        if isinstance(value, bool) or not isinstance(value, int | float):
            raise ValueError(
                f'a temperature (a number) or {{ along = "s" | "r" | "z", table = [[x, T], ...] }}, got {value!r}'
            )
        return float(value)

    @model_validator(mode="after")
    def _reference(self):
        if self.shift is not None and self.reference is None:
            raise ValueError("reference: the shift needs its reference temperature T_ref")
        return self

    def build_shift(self, unit: str | None = None) -> Shift | None:
        """The shift of the relaxation times, or None; `unit`: [units] temperature, which
        makes the temperatures of an Arrhenius shift absolute (CaseError naming the key)."""
        if self.shift is None:
            return None
        assert self.reference is not None  # the validator's
        if self.shift.wlf is not None:
            return WLF(self.shift.wlf.C1, self.shift.wlf.C2, self.reference)
        assert self.shift.arrhenius is not None
        offset = absolute_zero(unit)
        if offset is None:
            raise CaseError(
                f'units.temperature: an Arrhenius shift needs absolute temperatures: give "C" (degrees Celsius) '
                f'or "K" (kelvin), not {unit!r}'
            )
        try:
            return Arrhenius(self.shift.arrhenius.activation, self.reference, offset)
        except TemperatureDomainError as exc:
            raise CaseError(f"temperature.reference: {exc}") from None

    def nodal(self, mesh: Mesh) -> np.ndarray:
        """The initial temperature of every node (n_nodes,)."""
        if not isinstance(self.initial, InitialTable):
            return np.full(mesh.n_nodes, float(self.initial))
        along = self.initial.along
        if along == "s":
            if mesh.node_s is None:
                raise CaseError(
                    'temperature.initial: along = "s" needs a layered mesh (its reference arc '
                    'length); use along = "r" or "z"'
                )
            x = mesh.node_s
        else:
            x = mesh.points[:, 0 if along == "r" else 1]
        table = Table.of(self.initial.table)
        return table(x)

    def representative(self) -> float:
        """The temperature the solver's scales are taken at: the reference, else the initial
        temperature (its largest value for a table)."""
        if self.reference is not None:
            return float(self.reference)
        if isinstance(self.initial, InitialTable):
            return float(max(v for _, v in self.initial.table))
        return float(self.initial)


def _times(knots, end: float | None) -> list[float]:
    """The times at which a curve of these knots can take its extremes within the run: t = 0,
    the end time and the knots between (all knots where the end is not known); the curve is
    piecewise linear and constant outside its knots."""
    times = [float(t) for t, _ in knots]
    if end is None:
        return times
    low, high = min(0.0, end), max(0.0, end)
    return [0.0, *(t for t in times if low <= t <= high), end]


def _scaled(value: float, knots, end: float | None) -> list[tuple[float, str]]:
    """(value x f(t), how) at every time a temperature x curve can take its extremes within
    the run (_times)."""
    if knots is None:
        return [(float(value), "")]
    curve = Curve(knots)
    return [(float(value) * curve(t), f" ({float(value):g} x its curve at t = {t:g})") for t in _times(knots, end)]


def boundary_temperatures(case) -> list[tuple[str, float, str]]:
    """(key, temperature, how) of every temperature besides the initial field that the case
    can bring into the wall: each mould's temperature x its curve, each film's ambient x its
    curve, over the run ([solver] target under load control, else every knot)."""
    end = _end_time(case)
    out = []
    for k, c in enumerate(case.contact):
        if c.temperature is not None:
            out += [
                (f"contact[{k}].temperature", v, how) for v, how in _scaled(c.temperature, c.temperature_curve, end)
            ]
    for i, c in enumerate(case.convection):
        out += [(f"convection[{i}].ambient", v, how) for v, how in _scaled(c.ambient, c.curve, end)]
    return out


def check_boundary_temperatures(case, shift: Shift | None) -> None:
    """CaseError naming the key of the coldest mould or film temperature at or below the
    shift's pole: heat conduction would carry the wall there (the maximum principle bounds
    it by the boundary temperatures, not above them), where a_T is not defined (past the WLF
    pole the coldest material would relax the fastest)."""
    if shift is None:
        return
    for key, value, how in sorted(boundary_temperatures(case), key=lambda item: item[1]):
        try:
            shift.check(np.array(value))
        except TemperatureDomainError:
            raise CaseError(
                f"{key}: {value:g}{how} is at or below {shift.describe()} of temperature.shift: heat "
                f"conduction would cool the wall there, where the shift is not defined; give a temperature "
                f"above it, or a shift whose domain holds it"
            ) from None


def _end_time(case) -> float | None:
    """The run's end time under load control ([solver] target, 1 by default), None where not
    known (the load factor an unknown)."""
    if case.solver.control != "load":
        return None
    return 1.0 if case.solver.target is None else float(case.solver.target)


def change_values(case) -> list[tuple[float, str]]:
    """(dT, how) at every time the prescribed change can take its extremes within the run
    (_times); empty without a change."""
    change = case.temperature.change if case.temperature is not None else None
    if not change:
        return []
    curve = Curve(change)
    return [(curve(t), f" (its value at t = {t:g})") for t in _times(change, _end_time(case))]


def check_change(case, initial: np.ndarray, shift: Shift | None) -> None:
    """CaseError naming temperature.change where it is given with [thermal], or where it brings
    the coldest initial temperature to or below the shift's pole within the run."""
    if case.temperature.change is None:
        return
    if case.thermal is not None:
        raise CaseError(
            "temperature.change: a prescribed change of temperature cannot be combined with [thermal]: heat "
            "conduction computes the temperature there; program the films' ambients ([[convection]] ambient "
            "with a curve) or the moulds' temperatures instead"
        )
    if shift is None:
        return
    for dT, how in sorted(change_values(case)):
        try:
            shift.check(initial + dT)
        except TemperatureDomainError:
            raise CaseError(
                f"temperature.change: {dT:g}{how} brings the coldest initial temperature {initial.min():g} to "
                f"{initial.min() + dT:g}, at or below {shift.describe()} of temperature.shift, where the shift is "
                "not defined; give a smaller change, or a shift whose domain holds it"
            ) from None


def give_temperature(model: Model, mesh: Mesh, case) -> None:
    """Give the model the initial temperature field, the shift and the prescribed change of
    [temperature] (case.temperature, not None), and check every other temperature the case can
    reach against the shift's domain; CaseError naming the key."""
    heat = case.temperature
    shift = heat.build_shift(case.units.temperature)
    try:
        initial = heat.nodal(mesh)
        model.heat(initial, shift)
    except ValueError as exc:
        if shift is None:
            raise CaseError(f"temperature.initial: {exc}") from None
        key = "wlf.C2" if heat.shift.wlf is not None else "arrhenius"
        raise CaseError(f"temperature.shift.{key}: {exc} (temperature.initial)") from None
    # the coldest of the nodes and of the points between them (a Q8's shape functions may dip below its nodes)
    check_change(case, np.concatenate([initial, point_values(mesh, initial).ravel()]), shift)
    model.program(None if heat.change is None else Curve(heat.change))
    check_boundary_temperatures(case, shift)
