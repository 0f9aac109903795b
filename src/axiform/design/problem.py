"""The problem of parison and preform programming (the methods are in
optimize.py): the design, the thickness table of a layered case (`ThicknessDesign`), the
target final wall (`read_target`) and the least-squares misfit to it (`Objective`).

Design: the thicknesses t_k of the case's `mesh.thickness` table [[s_k, t_k], ...], bounded
to 0.2 to 5 times their initial values.  Objective: the mean squared relative misfit of the
final thickness to the target over the reference arc length, int ln(t / T)^2 ds / L over the
stations inside the target's range, plus a small smoothness term on the design.
"""

from __future__ import annotations

import copy
import csv
import io
from abc import ABC, abstractmethod
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from ..case.schema import MAX_MAGNITUDE, MIN_MAGNITUDE, Built, CaseError, build, parse, read
from ..io.text import read_text
from ..model.system import System
from ..solve.solver import LoadControl

BOUNDS = (0.2, 5.0)  # design bounds, times the initial thickness
SMOOTHNESS = 1e-4


class TargetError(ValueError):
    """A target file that cannot be used: the message names the file and the line."""


def read_target(path: str | Path) -> tuple[np.ndarray, np.ndarray]:
    """TARGET.csv: the header `s,thickness`, then rows of the reference arc length s
    (increasing) and the wanted final thickness (> 0).  Returns s, thickness (k,)."""
    path = Path(path)
    try:
        text = read_text(path)
    except (OSError, UnicodeDecodeError) as exc:
        raise TargetError(f"{path}: cannot read it ({getattr(exc, 'strerror', None) or exc})") from None
    try:
        reader = csv.reader(io.StringIO(text))
        rows = [(reader.line_num, cells) for cells in reader if "".join(cells).strip() and not cells[0].startswith("#")]
    except csv.Error as exc:
        raise TargetError(f"{path}: not a CSV file ({exc})") from None
    if not rows or [c.strip() for c in rows[0][1]] != ["s", "thickness"]:
        raise TargetError(f"{path}: the first row must be the header 's,thickness'")
    s: list[float] = []
    t: list[float] = []
    for n, cells in rows[1:]:
        try:
            a, b = (float(c) for c in cells)
        except ValueError:
            line = ",".join(cells).strip()
            raise TargetError(f"{path}: line {n}: expected two numbers s,thickness, got {line!r}") from None
        if not (np.isfinite(a) and np.isfinite(b)) or b <= 0:
            raise TargetError(f"{path}: line {n}: s must be finite and the thickness finite and > 0")
        for name, value in (("s", a), ("thickness", b)):
            if abs(value) > MAX_MAGNITUDE or 0 < abs(value) < MIN_MAGNITUDE:
                raise TargetError(
                    f"{path}: line {n}: {name} {value:g} is beyond the magnitude of a case's numbers "
                    f"(at most {MAX_MAGNITUDE:g}, and nonzero at least {MIN_MAGNITUDE:g})"
                )
        if s and a <= s[-1]:
            raise TargetError(f"{path}: line {n}: s must increase")
        s.append(a)
        t.append(b)
    if not s:
        raise TargetError(f"{path}: no rows after the header")
    return np.array(s), np.array(t)


class CaseDesign(ABC):
    """What the designs of a case share (ThicknessDesign, temperature_design.TemperatureDesign):
    the model and the control of the case tree with the design's values (`case_tree`), the
    case read from `tree`, its relative files from `base`, built once as `built`."""

    tree: dict[str, Any]
    base: Path
    built: Built

    @abstractmethod
    def case_tree(self, values: np.ndarray) -> dict[str, Any]:
        """The case tree with the design's values in it."""

    def model(self, values: np.ndarray) -> System:
        """The finalized model of the case with the design's values."""
        return build(parse(self.case_tree(values)), self.base).model

    @property
    def control(self) -> LoadControl:
        """The case's load control (the designs refuse any other: from_case)."""
        control = self.built.control
        if not isinstance(control, LoadControl):
            raise CaseError("solver.control: a design follows the load path under load control")
        return control

    @property
    def stations(self) -> np.ndarray:
        """The reference arc length of the wall's stations (n,), where its thickness is measured."""
        s = self.built.model.mesh.fibre_s
        if s is None:
            raise CaseError("mesh: a design needs a wall whose thickness is measured (a layered or rectangle mesh)")
        return s

    def outside(self, values: np.ndarray) -> str | None:
        """Why the design `values` (k,) lies outside the case's domain (not to be solved), or
        None: every thickness within the bounds is a wall."""
        return None


@dataclass
class ThicknessDesign(CaseDesign):
    """The design variables of a layered case: the t of its `mesh.thickness` table.

    tree: the case tree (validated); base: the folder its relative paths start from;
    knots: the s of the table (k,); initial: its t (k,); built: the case built at `initial`."""

    tree: dict[str, Any]
    base: Path
    knots: np.ndarray
    initial: np.ndarray
    built: Built

    name = "mesh.thickness"  # the table that holds the design

    @classmethod
    def from_case(cls, path: str | Path, overrides: Sequence[str] = ()) -> ThicknessDesign:
        """Read a case for optimization: a layered mesh with a thickness table, load control.
        CaseError names the key at fault."""
        path = Path(path)
        tree = read(path, list(overrides))
        case = parse(tree)
        if case.mesh.kind != "layered" or not isinstance(case.mesh.thickness, list):
            raise CaseError(
                "mesh.thickness: optimize needs a layered mesh whose thickness is a table "
                "[[s, t], ...]: its t are the design variables"
            )
        if case.solver.control != "load":
            raise CaseError(
                f'solver.control: optimize follows the load path under load control, not "{case.solver.control}"'
            )
        built = build(case, path.parent)
        table = np.asarray(case.mesh.thickness, float)
        return cls(absolute_paths(tree, path.parent), path.parent, table[:, 0], table[:, 1], built)

    def case_tree(self, values: np.ndarray) -> dict[str, Any]:
        """The case tree with the thickness table's t replaced by `values`."""
        tree = copy.deepcopy(self.tree)
        tree["mesh"]["thickness"] = [[float(s), float(t)] for s, t in zip(self.knots, values, strict=False)]
        return tree

    def bounds(self) -> tuple[np.ndarray, np.ndarray]:
        return BOUNDS[0] * self.initial, BOUNDS[1] * self.initial

    @staticmethod
    def to_y(x: np.ndarray) -> np.ndarray:
        """The optimizer's variables y of the design x: y = ln t (a wall scales with its
        parison, so that ln of the final wall is nearly linear in y)."""
        return np.log(x)

    @staticmethod
    def from_y(y: np.ndarray) -> np.ndarray:
        return np.exp(y)

    @staticmethod
    def dx_dy(x: np.ndarray) -> np.ndarray:
        return np.asarray(x, float)

    @staticmethod
    def rule(x: np.ndarray, ratio: np.ndarray) -> np.ndarray:
        """The fixed-point update of the design x with ratio = target / achieved at its
        knots: each t_k scaled by it."""
        return x * ratio


def absolute_paths(tree: dict[str, Any], base: Path) -> dict[str, Any]:
    """The case tree with relative file names (mesh.file, contact surfaces' file and dxf)
    made absolute, so that the written case runs from any folder."""
    tree = copy.deepcopy(tree)
    tables = [tree.get("mesh", {})] + [c.get("surface", {}) for c in tree.get("contact", [])]
    for table in tables:
        for k in ("file", "dxf"):
            if isinstance(table, dict) and isinstance(table.get(k), str) and not Path(table[k]).is_absolute():
                table[k] = str((base / table[k]).resolve())
    return tree


@dataclass
class Objective:
    """Least-squares misfit of the final thickness to a target, plus a smoothness term.

    stations: reference arc length of the wall's stations (n,); the target (s, thickness) is
    interpolated linearly at the stations inside its range; weights w (n,): the trapezoid
    weights of those stations over the length they cover (zero outside), so that
    sum w e^2 is the mean of e^2 = ln(t / T)^2 over the reference arc length.
    Smoothness: `smoothness` sum (second difference of the design / mean initial design)^2."""

    stations: np.ndarray
    target_s: np.ndarray
    target_t: np.ndarray
    scale: float
    smoothness: float = SMOOTHNESS
    inside: np.ndarray = field(init=False)
    target: np.ndarray = field(init=False)
    weights: np.ndarray = field(init=False)

    def __post_init__(self):
        s = self.stations
        tol = 1e-9 * max(1.0, float(np.abs(s).max()))
        self.inside = (s >= self.target_s[0] - tol) & (s <= self.target_s[-1] + tol)
        if self.inside.sum() < 1:
            raise TargetError(
                f"the target's s range [{self.target_s[0]:g}, {self.target_s[-1]:g}] holds no "
                f"station of the wall (s from {s[0]:g} to {s[-1]:g})"
            )
        self.target = np.interp(s, self.target_s, self.target_t)
        si = s[self.inside]
        w = np.zeros(len(si))
        if len(si) > 1:
            d = np.diff(si)
            w[:-1] += d / 2
            w[1:] += d / 2
            w /= si[-1] - si[0]
        else:
            w[:] = 1.0
        self.weights = np.zeros(len(s))
        self.weights[self.inside] = w

    def deviation(self, thickness: np.ndarray) -> np.ndarray:
        """Relative deviation (t - T) / T at the stations inside the target (n_inside,)."""
        return (thickness[self.inside] - self.target[self.inside]) / self.target[self.inside]

    def max_rel_deviation(self, thickness: np.ndarray) -> float:
        return float(np.abs(self.deviation(thickness)).max())

    def _second(self, m: int) -> np.ndarray:
        """The second-difference operator (m - 2, m) over the design, relative to its scale."""
        D = np.zeros((max(m - 2, 0), m))
        for i in range(m - 2):
            D[i, i : i + 3] = (1.0, -2.0, 1.0)
        return D / self.scale

    def residuals(self, thickness: np.ndarray, design: np.ndarray) -> np.ndarray:
        """r with objective = r . r: sqrt(w) e at the stations, then sqrt(smoothness) D s."""
        i = self.inside
        misfit = np.sqrt(self.weights[i]) * np.log(thickness[i] / self.target[i])
        return np.concatenate([misfit, np.sqrt(self.smoothness) * self._second(len(design)) @ design])

    def jacobian(self, thickness: np.ndarray, dthickness_ds: np.ndarray) -> np.ndarray:
        """dr/ds (len(r), m) from the final thickness (n,) and d thickness / ds (n, m)."""
        i = self.inside
        rows = (np.sqrt(self.weights[i]) / thickness[i])[:, None] * dthickness_ds[i]
        return np.vstack([rows, np.sqrt(self.smoothness) * self._second(dthickness_ds.shape[1])])
