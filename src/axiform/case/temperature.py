"""The [temperature] table of the case file: the material's initial temperature and the shift
of its relaxation times.

    [temperature]
    initial = 150.0                                      # a constant, or a table along the wall:
    # initial = { along = "s", table = [[0.0, 150.0], [40.0, 135.0]] }  # s: reference arc length (layered mesh)
    # initial = { along = "r", table = [[0.0, 150.0], [7.5, 140.0]] }   # or "z": by reference coordinate
    reference = 150.0                                    # T_ref of the shift
    shift = { wlf = { C1 = 17.44, C2 = 51.6 } }          # or { arrhenius = { activation = 8.0e3 } } (E/R, K)

Without a heat equation the temperature of a material point stays its initial value (piecewise
linear in the table, constant outside).  The law's constants may be tables [[T, value], ...]
of it ([material]).  Errors name the key (temperature.KEY).
"""

from __future__ import annotations

from typing import Any, Literal

import numpy as np
from pydantic import ValidationError, field_validator, model_validator

from ..fem.mesh import Mesh
from ..materials.temperature import WLF, Arrhenius, Shift, Table
from .base import CaseError, PositiveFloat, Strict


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

    def build_shift(self) -> Shift | None:
        """The shift of the relaxation times, or None."""
        if self.shift is None:
            return None
        if self.shift.wlf is not None:
            return WLF(self.shift.wlf.C1, self.shift.wlf.C2, self.reference)
        return Arrhenius(self.shift.arrhenius.activation, self.reference)

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
