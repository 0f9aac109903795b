"""The [gravity] table of the case file: the body's own weight (model.gravity.GravityTerm).

    [gravity]
    g = -9810.0                      # the acceleration along z (the axis vertical; negative:
                                     # downwards), in the case's length / time^2 (mm/s^2 here)
    curve = [[0.0, 0.0], [1.0, 1.0]] # x f(t), as every load (absent: f(t) = t)

It needs the material's density, [material] density (mass per unit reference volume).
Errors name the key.
"""

from __future__ import annotations

from ..fem.mesh import Mesh
from ..model.gravity import GravityTerm
from ..model.model import Model
from .base import CaseError, CurveMixin


class GravitySpec(CurveMixin):
    """The [gravity] table (see the module docstring)."""

    g: float


def build_gravity(model: Model, mesh: Mesh, spec: GravitySpec | None, density: float | None) -> None:
    """Give the model the weight of its body; CaseError naming material.density where the
    material has none."""
    if spec is None:
        return
    if density is None:
        raise CaseError("material.density: [gravity] needs the material's density (mass per unit reference volume)")
    model.add(GravityTerm(mesh, spec.g, density, spec.build_curve()))
