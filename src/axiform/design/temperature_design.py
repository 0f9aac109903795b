"""Temperature programming (`axiform optimize --vary temperature`, docs/guide.md): the design
is the table of the initial temperature,
`[temperature] initial = { along = "s" | "r" | "z", table = [[x_k, T_k], ...] }`; the T_k
are the design variables, bounded to the table's range +- 30 K (or `--bounds LOW,HIGH`).
The thickness table stays fixed.  The optimizer works on y = T itself (the wall responds to a
temperature through the law's tables and the shift, smoothly and without a natural scale of
its own, unlike a thickness, worked on as ln t).

The fixed-point rule of temperature programming (the plain method to compare with): where
the wall is thicker than wanted, heat the sheet there, by RULE_GAIN kelvin per unit of
ln(achieved / target) at the knot, from the last design.
"""

from __future__ import annotations

import copy
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from ..case.schema import Built, CaseError, build, parse, read
from ..case.temperature import change_values
from ..materials.temperature import WLF, Arrhenius
from .problem import CaseDesign, absolute_paths

MARGIN = 30.0  # K: the default bounds, the table's range widened by this much
RULE_GAIN = 15.0  # K per unit of ln(achieved / target) (the fixed-point rule)


@dataclass
class TemperatureDesign(CaseDesign):
    """The design variables of a case whose [temperature] initial is a table: its T_k.

    tree: the case tree; base: the folder its relative paths start from; along: "s", "r" or
    "z"; knots: the positions x_k of the table (k,); initial: its T_k (k,); built: the case
    built at `initial`; limits: (low, high) bounds of every T_k."""

    tree: dict[str, Any]
    base: Path
    along: str
    knots: np.ndarray
    initial: np.ndarray
    built: Built
    limits: tuple[float, float]

    name = "temperature.initial"

    @classmethod
    def from_case(
        cls, path: str | Path, overrides: Sequence[str] = (), bounds: tuple[float, float] | None = None
    ) -> TemperatureDesign:
        """Read a case for temperature programming: a [temperature] whose initial field is a
        table, load control, a wall with thickness stations.  CaseError names the key."""
        path = Path(path)
        tree = read(path, list(overrides))
        case = parse(tree)
        heat = case.temperature
        if heat is None or isinstance(heat.initial, float):
            raise CaseError(
                "temperature.initial: optimize --vary temperature needs the initial temperature as a "
                'table, initial = { along = "s" | "r" | "z", table = [[x, T], ...] }: its T are the '
                "design variables"
            )
        if case.solver.control != "load":
            raise CaseError(
                f'solver.control: optimize follows the load path under load control, not "{case.solver.control}"'
            )
        built = build(case, path.parent)
        if built.model.mesh.fibres is None:
            raise CaseError("mesh: optimize needs a wall whose thickness is measured (a layered or rectangle mesh)")
        table = np.asarray(heat.initial.table, float)
        limits = (
            bounds if bounds is not None else (float(table[:, 1].min()) - MARGIN, float(table[:, 1].max()) + MARGIN)
        )
        if not limits[0] < limits[1]:
            raise CaseError(f"--bounds: the low bound {limits[0]:g} must be below the high one {limits[1]:g}")
        return cls(
            absolute_paths(tree, path.parent), path.parent, heat.initial.along, table[:, 0], table[:, 1], built, limits
        )

    def case_tree(self, values: np.ndarray) -> dict[str, Any]:
        """The case tree with the temperature table's T replaced by `values`."""
        tree = copy.deepcopy(self.tree)
        tree["temperature"]["initial"] = {
            "along": self.along,
            "table": [[float(x), float(T)] for x, T in zip(self.knots, values, strict=False)],
        }
        return tree

    def outside(self, values: np.ndarray) -> str | None:
        """Why the temperatures `values` (k,) lie outside the shift's domain (at or below the
        WLF pole T_ref - C2, or not a positive absolute temperature), or None, also once lowered
        by the most the prescribed change ([temperature] change) lowers them.  The table's
        field lies between its smallest and largest knot value, so the knots tell."""
        shift = self.built.model.shift
        if not isinstance(shift, (WLF, Arrhenius)):  # no shift: every temperature will do
            return None
        lowest = min([0.0, *(dT for dT, _ in change_values(self.built.case))])
        try:
            shift.check(np.asarray(values, float) + lowest)
        except ValueError as exc:
            return str(exc)
        return None

    def bounds(self) -> tuple[np.ndarray, np.ndarray]:
        k = self.knots.size
        return np.full(k, self.limits[0]), np.full(k, self.limits[1])

    @staticmethod
    def to_y(x: np.ndarray) -> np.ndarray:
        """The optimizer's variables y of the design x: y = T."""
        return np.asarray(x, float)

    @staticmethod
    def from_y(y: np.ndarray) -> np.ndarray:
        return np.asarray(y, float)

    @staticmethod
    def dx_dy(x: np.ndarray) -> np.ndarray:
        return np.ones_like(x)

    @staticmethod
    def rule(x: np.ndarray, ratio: np.ndarray) -> np.ndarray:
        """The fixed-point update of the design x with ratio = target / achieved at its knots:
        T_k + RULE_GAIN ln(1 / ratio) (heat where the wall is too thick)."""
        return x - RULE_GAIN * np.log(ratio)
