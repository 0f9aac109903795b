"""The [solver] table of the case file: the path-following control (load, displacement or arc
length) and Newton's options; and the control it makes."""

from __future__ import annotations

from typing import Annotated, Literal

from pydantic import Field, model_validator

from ..fem.mesh import Mesh
from ..materials.protocol import as_law
from ..model.model import Model
from ..solve.solver import ArcLengthControl, DisplacementControl, LoadControl
from .base import CaseError, DofName, PositiveFloat, Selector, Strict, one_node


class DofRef(Strict):
    at: Selector
    dof: DofName


class StopSpec(Strict):
    at: Selector
    dof: Literal["ur", "uz"]
    value: float


MAX_STEPS = 1_000_000
MAX_ITERATIONS = 1000


class SolverSpec(Strict):
    control: Literal["load", "displacement", "arc-length"] = "load"
    dof: DofRef | None = None
    target: float | None = None
    # the counts are bounded so that every run ends: a million steps of the smallest model take
    # hours, a step of more Newton iterations than MAX_ITERATIONS is not converging
    steps: Annotated[int, Field(ge=1, le=MAX_STEPS)] = 10
    arc_length: PositiveFloat | None = None
    stop: StopSpec | None = None
    max_steps: Annotated[int, Field(ge=1, le=MAX_STEPS)] = 1000
    max_iterations: Annotated[int, Field(ge=1, le=MAX_ITERATIONS)] = 20
    tolerance: Annotated[float, Field(gt=0, lt=1)] = 1e-8
    min_step: Annotated[float, Field(gt=0, le=1)] = 1e-4
    growth: Annotated[float, Field(ge=1)] = 1.5
    max_dt: PositiveFloat | None = None  # load control: no step longer than this (process time)
    # load control: load factors every step lands on besides the curves' knots
    stops: Annotated[list[PositiveFloat], Field(max_length=MAX_STEPS)] | None = None

    @model_validator(mode="after")
    def _control(self):
        if self.control == "displacement":
            if self.dof is None or self.target is None:
                raise ValueError("displacement control needs 'dof' and 'target'")
        elif self.dof is not None:
            raise ValueError("'dof' belongs to control = \"displacement\"")
        if self.control != "arc-length":
            for key in ("arc_length", "stop"):
                if getattr(self, key) is not None:
                    raise ValueError(f"'{key}' belongs to control = \"arc-length\"")
        for key in ("max_dt", "stops"):
            if getattr(self, key) is not None and self.control != "load":
                raise ValueError(f"'{key}' belongs to control = \"load\"")
        if self.target is not None and self.target == 0:
            raise ValueError("target must not be 0")
        return self


def build_control(model: Model, mesh: Mesh, spec: SolverSpec) -> LoadControl | DisplacementControl | ArcLengthControl:
    """The path-following control of the [solver] table, on the model with its [[fix]] tables
    prescribed (a driven or stop dof that is also fixed is refused).  A law with memory makes
    the load factor the process time: only load control advances it."""
    timed = (
        "a viscoelastic material (a Prony series or viscous networks)"
        if as_law(model.material).timed
        else "heat conduction ([thermal])"
        if model.conduction is not None
        else "a prescribed change of temperature ([temperature] change)"
        if model.change is not None
        else None
    )
    if spec.control != "load" and timed:
        raise CaseError(
            f'solver.control: "{spec.control}" does not work with {timed}: the load '
            'factor is the process time there, and time must advance; use control = "load" with a '
            "cavity under volume or gas control, or a prescribed motion with its curve"
        )
    if spec.control == "displacement":
        driven, target = spec.dof, spec.target
        if driven is None or target is None:  # SolverSpec refuses it: for the type checker
            raise CaseError("solver: displacement control needs 'dof' and 'target'")
        if driven.dof == "rot":
            raise CaseError("solver.dof.dof: drive a displacement (ur or uz), not a fibre rotation")
        node = one_node(mesh, driven.at, "solver.dof.at")
        dof = int(model.dof(node, driven.dof))
        if dof in model.fixed:
            raise CaseError("solver.dof: the driven dof is also fixed by a [[fix]] table")
        return DisplacementControl(dof, target, spec.steps)
    if spec.control == "arc-length":
        stop_dof = stop_value = None
        if spec.stop is not None:
            stop_dof = int(model.dof(one_node(mesh, spec.stop.at, "solver.stop.at"), spec.stop.dof))
            if stop_dof in model.fixed:
                raise CaseError("solver.stop: that dof is fixed by a [[fix]] table")
            stop_value = spec.stop.value
        return ArcLengthControl(
            1.0 if spec.target is None else spec.target,
            spec.steps,
            spec.arc_length,
            stop_dof,
            stop_value,
            spec.max_steps,
        )
    target = 1.0 if spec.target is None else spec.target
    if target < 0:
        raise CaseError(
            f"solver.target: {target:g} is before the start: under load control the load factor (the "
            "process time) goes from 0 up to the target; reverse the loads' values instead"
        )
    if spec.max_dt is not None and target / spec.max_dt > MAX_STEPS:
        raise CaseError(
            f"solver.max_dt: {spec.max_dt:g} makes at least {target / spec.max_dt:.3g} steps from 0 to the "
            f"target {target:g}, more than {MAX_STEPS:,}: give a longer max_dt (or a shorter target)"
        )
    stops = tuple(spec.stops or ())
    beyond = [t for t in stops if t > target]
    if beyond:
        raise CaseError(f"solver.stops: {beyond[0]:g} lies beyond the target {target:g}")
    return LoadControl(target, spec.steps, spec.max_dt, stops)


def check_resumed_target(spec: SolverSpec, reached: float) -> None:
    """CaseError unless the target of a resumed load-controlled run lies beyond the load factor
    (the process time) its checkpoint reached: a run goes forward only.  The steps max_dt makes
    from there are bounded by build_control's check from 0."""
    target = 1.0 if spec.target is None else spec.target
    if spec.control == "load" and target <= reached * (1 + 1e-12):
        raise CaseError(
            f"solver.target: {target:g} is not beyond the load factor {reached:g} the run being resumed "
            "has reached: give a later target"
        )
