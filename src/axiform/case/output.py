"""The [output], [units] and [restart] tables of the case file: what is written and how often,
the labels of the units, the checkpoints for `axiform run --resume`."""

from __future__ import annotations

from typing import Annotated

from pydantic import Field

from .base import Strict

# output.revolved: at most this many sectors (a tenth of a degree each), and at most
# MAX_REVOLVED_POINTS points in the 3D copy (checked against the mesh when the case is built)
MAX_SECTORS = 3600
MAX_REVOLVED_POINTS = 20_000_000


class OutputSpec(Strict):
    every: Annotated[int, Field(ge=1)] = 1  # field output every k-th converged step (and the last)
    vtu: bool = True
    gid: bool = False
    plots: bool = True
    revolved: Annotated[int, Field(ge=0, le=MAX_SECTORS)] = 0  # sectors of a 3D revolved copy of the last step
    thickness_every: Annotated[int, Field(ge=1)] | None = None  # thickness/step_NNNN.csv every k-th step


Unit = Annotated[str, Field(min_length=1)]


class UnitsSpec(Strict):
    """The units the case's numbers are in: labels for plots and summary.json, no conversion."""

    length: Unit | None = None
    pressure: Unit | None = None
    force: Unit | None = None
    time: Unit | None = None
    temperature: Unit | None = None


class RestartSpec(Strict):
    """Checkpoints for `axiform run --resume`: every k converged steps and at any stop (0: none)."""

    every: Annotated[int, Field(ge=0)] = 10
