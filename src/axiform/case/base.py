"""What every table of the case file shares: CaseError, the strict base of the tables, the
node selector, the load curve a table may carry, and the one-node selector."""

from __future__ import annotations

from typing import Annotated, Literal

from pydantic import AfterValidator, BaseModel, ConfigDict, Field, model_validator

from ..fem.curves import PROPORTIONAL, Curve
from ..fem.mesh import Mesh
from ..fem.selectors import select_nodes

DofName = Literal["ur", "uz", "rot"]
PositiveFloat = Annotated[float, Field(gt=0)]


def _increasing_times(knots: list[tuple[float, float]]) -> list[tuple[float, float]]:
    """The knots of a curve, whose times must increase from row to row (ValueError otherwise)."""
    t = [k[0] for k in knots]
    if any(b <= a for a, b in zip(t, t[1:], strict=False)):
        raise ValueError("the times (first column) must increase from row to row")
    return knots


# a load curve [[t0, f0], [t1, f1], ...]: t increasing, the applied value is value x f(t)
CurveKnots = Annotated[list[tuple[float, float]], Field(min_length=1), AfterValidator(_increasing_times)]


class CaseError(ValueError):
    """An invalid case: the message names the key path and the reason."""


class Strict(BaseModel):
    model_config = ConfigDict(extra="forbid", strict=False)


class Selector(Strict):
    """Nodes matching all given criteria: r / z (within tol), box [[r0, z0], [r1, z1]], set."""

    r: float | None = None
    z: float | None = None
    box: tuple[tuple[float, float], tuple[float, float]] | None = None
    set: str | None = None
    tol: PositiveFloat | None = None

    @model_validator(mode="after")
    def _some(self):
        if self.r is None and self.z is None and self.box is None and self.set is None:
            raise ValueError("a selector needs at least one of r, z, box, set")
        return self


class CurveMixin(Strict):
    curve: CurveKnots | None = None

    @model_validator(mode="after")
    def _curve(self):
        if self.curve is not None:
            t = [k[0] for k in self.curve]
            if any(b <= a for a, b in zip(t, t[1:], strict=False)):
                raise ValueError("curve: the times must increase")
        return self

    def build_curve(self) -> Curve:
        return PROPORTIONAL if self.curve is None else Curve(self.curve)


def one_node(mesh: Mesh, sel: Selector, where: str) -> int:
    """The one node a selector matches (`where`: its key path); CaseError if it matches another number."""
    nodes = select_nodes(mesh, sel.model_dump(), where)
    if len(nodes) != 1:
        raise CaseError(f"{where}: selector must match exactly one node, it matches {len(nodes)}")
    return int(nodes[0])
