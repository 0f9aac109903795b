"""Temperature in the law: constants as tables of T, and the shift of the relaxation times.

- `Table`: a constant as a piecewise-linear function of the temperature T, constant outside
  its knots (which increase strictly).
- `WLF` and `Arrhenius`: the shift factor a_T of the relaxation times (time-temperature
  superposition): log10 a_T = -C1 (T - T_ref) / (C2 + T - T_ref) (Williams-Landel-Ferry), or
  ln a_T = activation (1/T - 1/T_ref) with T absolute (kelvin); the reduced time of a material
  point advances by dxi = dt / a_T(T).  Each is defined above its `pole` (T_ref - C2; absolute
  zero): `shift` raises TemperatureDomainError at or below it, naming the place (the run
  stops there rather than relax a wall at a_T = 1e-47).
- `TemperatureDependent`: a law whose constants are tables, evaluated at the temperatures of
  a batch of material points (`at(T)`: a law with one value per point, the points in the order
  of the batch's rows); its scalar properties (kappa, shear_modulus: the scales of the
  solver) are those of the law at the reference temperature.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np


@dataclass(frozen=True)
class Table:
    """A constant as a function of T: knots T (k,) increasing strictly, values (k,);
    piecewise linear between the knots and constant outside."""

    T: tuple[float, ...]
    values: tuple[float, ...]

    def __post_init__(self):
        T = np.asarray(self.T, float)
        if T.size < 1 or T.shape != np.shape(self.values):
            raise ValueError("a table needs one value per temperature")
        if (np.diff(T) <= 0).any():
            raise ValueError("the temperatures of a table must increase")

    @classmethod
    def of(cls, rows) -> Table:
        """A table from its rows [[T, value], ...]."""
        rows = np.asarray(rows, float)
        return cls(tuple(rows[:, 0]), tuple(rows[:, 1]))

    def __call__(self, T: np.ndarray | float) -> np.ndarray:
        """The value at T (any shape)."""
        return np.asarray(np.interp(T, self.T, self.values))


class TemperatureDomainError(ValueError):
    """A temperature beyond the domain of a shift (at or below the WLF pole, at or below
    absolute zero for Arrhenius): a_T is not defined there."""


def _place(T: np.ndarray, index: int) -> str:
    """Where the value at the flat index of T lies: a node of a field (n,), an element of a
    field per quadrature point (e, q)."""
    if T.ndim == 2:
        return f" at element {index // T.shape[1]}"
    if T.ndim == 1 and T.size > 1:
        return f" at node {index}"
    return ""


@dataclass(frozen=True)
class WLF:
    """log10 a_T = -C1 (T - reference) / (C2 + T - reference); defined while C2 + T - T_ref > 0,
    above the pole T_ref - C2."""

    C1: float
    C2: float
    reference: float

    @property
    def pole(self) -> float:
        """The lowest temperature excluded: T_ref - C2."""
        return self.reference - self.C2

    def describe(self) -> str:
        return f"the WLF pole T_ref - C2 = {self.pole:.6g}"

    def check(self, T: np.ndarray | float) -> None:
        """TemperatureDomainError where T (any shape; a node's field (n,) or the points' (e, q)
        for the place in the message) lies at or below the pole T = T_ref - C2."""
        T = np.asarray(T, float)
        if T.size and not (self.C2 + T - self.reference > 0).all():
            k = int(np.argmin(T))
            raise TemperatureDomainError(
                f"a temperature of {float(T.flat[k]):.6g}{_place(T, k)} is at or below {self.describe()} "
                f"(C2 + T - T_ref must be > 0)"
            )

    def shift(self, T: np.ndarray | float) -> np.ndarray:
        """a_T (same shape as T); TemperatureDomainError at or below the pole."""
        self.check(T)
        dT = np.asarray(T, float) - self.reference
        return 10.0 ** (-self.C1 * dT / (self.C2 + dT))


@dataclass(frozen=True)
class Arrhenius:
    """ln a_T = activation (1/T_abs - 1/reference_abs), activation = E/R (K); T_abs = T + offset
    the absolute temperature (offset 0 for temperatures in kelvin, 273.15 in degrees Celsius)."""

    activation: float
    reference: float
    offset: float = 0.0

    def __post_init__(self):
        if not self.reference + self.offset > 0:
            raise TemperatureDomainError(
                f"the reference temperature {self.reference:.6g} is {self.reference + self.offset:.6g} K: an "
                f"Arrhenius shift needs an absolute temperature > 0"
            )

    @property
    def pole(self) -> float:
        """The lowest temperature excluded: absolute zero in the case's unit."""
        return 0.0 - self.offset  # 0.0 -: 0 K is 0, not -0, where the case is in kelvin

    def describe(self) -> str:
        return f"absolute zero ({self.pole:.6g}; an Arrhenius shift needs T > 0 K)"

    def check(self, T: np.ndarray | float) -> None:
        """TemperatureDomainError where T (any shape) is not above absolute zero."""
        T = np.asarray(T, float)
        if T.size and not (T + self.offset > 0).all():
            k = int(np.argmin(T))
            raise TemperatureDomainError(
                f"a temperature of {float(T.flat[k]):.6g}{_place(T, k)} is at or below {self.describe()}: is it "
                f"in kelvin?"
            )

    def shift(self, T: np.ndarray | float) -> np.ndarray:
        """a_T (same shape as T); TemperatureDomainError at or below absolute zero."""
        self.check(T)
        return np.exp(
            self.activation * (1.0 / (np.asarray(T, float) + self.offset) - 1.0 / (self.reference + self.offset))
        )


Shift = WLF | Arrhenius


class TemperatureDependent:
    """A law whose constants are tables of T (`tables`: name -> Table; `fixed`: name ->
    number), built by `make(constants)` from one value (or one array of values) per name."""

    def __init__(
        self, make: Callable[[dict], object], tables: dict[str, Table], fixed: dict[str, float], reference: float
    ):
        self.make = make
        self.tables = tables
        self.fixed = fixed
        self.reference = reference
        self.reference_law = self.at(np.asarray(reference, float))

    def at(self, T: np.ndarray):
        """The law at the temperatures T of a batch of points: every table evaluated at
        T.ravel() (one value per point, the batch's rows in order)."""
        values: dict[str, Any] = {name: table(np.ravel(T)) for name, table in self.tables.items()}
        if np.ndim(T) == 0:
            values = {name: float(v[0]) for name, v in values.items()}
        return self.make(self.fixed | values)

    def __getattr__(self, name: str):
        if name in ("make", "tables", "fixed", "reference", "reference_law"):
            raise AttributeError(name)
        return getattr(self.reference_law, name)
