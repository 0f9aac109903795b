"""The [[fix]], [[pressure]] and [[point_load]] tables of the case file, each with its load
curve; and what they prescribe and apply to the model."""

from __future__ import annotations

from typing import Annotated, Literal

import numpy as np
from pydantic import Field

from ..fem.mesh import Mesh
from ..fem.selectors import select_edges, select_nodes
from ..model.model import Model
from .base import CaseError, CurveMixin, DofName, Selector


class FixSpec(CurveMixin):
    at: Selector
    dofs: Annotated[list[DofName], Field(min_length=1)]
    value: float = 0.0


class PressureSpec(CurveMixin):
    on: Selector
    value: float


class PointLoadSpec(CurveMixin):
    at: Selector
    dof: Literal["ur", "uz"]
    value: float


def prescribe_fixes(model: Model, mesh: Mesh, fixes: list[FixSpec]) -> None:
    """Prescribe the [[fix]] tables; two tables giving one dof different values are refused."""
    owner = np.full(model.n_full, -1)
    value = np.zeros(model.n_full)
    for i, f in enumerate(fixes):
        nodes = select_nodes(mesh, f.at.model_dump(), f"fix[{i}].at")
        for name in f.dofs:
            if name == "rot" and model.dpn == 2:
                continue
            d = model.dof(nodes, name)
            clash = (owner[d] >= 0) & (value[d] != f.value)
            if clash.any():
                k = int(np.argmax(clash))
                raise CaseError(
                    f"fix[{i}].value: {name} of node {int(nodes[k])} is also prescribed by "
                    f"fix[{owner[d][k]}], with value {float(value[d][k])!r}, not {f.value!r}"
                )
            owner[d], value[d] = i, f.value
        model.prescribe(nodes, f.dofs, f.value, f.build_curve())


def apply_loads(model: Model, mesh: Mesh, pressures: list[PressureSpec], point_loads: list[PointLoadSpec]) -> None:
    """Apply the [[pressure]] tables (follower pressures on the selected edges) and the
    [[point_load]] tables to the model."""
    for i, p in enumerate(pressures):
        model.pressure(select_edges(mesh, p.on.model_dump(), f"pressure[{i}].on"), p.value, p.build_curve())
    for i, pl in enumerate(point_loads):
        model.point_load(
            select_nodes(mesh, pl.at.model_dump(), f"point_load[{i}].at"), pl.dof, pl.value, pl.build_curve()
        )
