"""The [[contact]] tables of the case file: a rigid mould surface (circle, polyline, CSV file,
profile of lines and arcs, DXF drawing), its motion and the contact law; and the contact pair
each makes."""

from __future__ import annotations

import io
import warnings
from pathlib import Path
from typing import Annotated, Literal

import numpy as np
from pydantic import Field, model_validator

from ..contact.dxf import DxfError, read_dxf
from ..contact.pair import ContactPair
from ..contact.surfaces import Circle, Polyline
from ..fem.mesh import Mesh
from ..fem.profile import Arc, Line, Profile, ProfileError
from ..fem.selectors import select_nodes
from ..io.text import read_text
from ..materials import Hyperelastic
from ..materials.temperature import TemperatureDependent
from ..materials.viscoelastic import Viscoelastic
from ..model.guards import chain_crossing
from ..model.model import Model
from .base import CaseError, CurveKnots, CurveMixin, PositiveFloat, Selector, Strict


class CircleSpec(Strict):
    center: tuple[float, float]
    radius: PositiveFloat
    inside: bool = False


class SurfaceLine(Strict):
    to: tuple[float, float]


class SurfaceArc(Strict):
    center: tuple[float, float]
    to: tuple[float, float]
    ccw: bool = True


class SurfacePiece(Strict):
    """{ line = { to } } or { arc = { center, to, ccw } }: exact, no divisions needed."""

    line: SurfaceLine | None = None
    arc: SurfaceArc | None = None

    @model_validator(mode="after")
    def _one(self):
        if (self.line is None) == (self.arc is None):
            raise ValueError("a surface piece is either { line = ... } or { arc = ... }")
        return self

    def build(self) -> Line | Arc:
        """The piece, of one division (a mould's lines and arcs are exact, not sampled)."""
        if self.line is not None:
            return Line(self.line.to, 1)
        assert self.arc is not None, "a piece is a line or an arc (_one)"
        return Arc(self.arc.center, self.arc.to, 1, self.arc.ccw)


class ProfileSurfaceSpec(Strict):
    start: tuple[float, float]
    pieces: Annotated[list[SurfacePiece], Field(min_length=1)]


class SurfaceSpec(Strict):
    """A rigid surface: a circle, a polyline (points in order: the body on their left), the
    points of a CSV file (r, z per line), a profile of lines and arcs, or the lines and arcs
    of a DXF drawing (on `layer`, ends joined within `tolerance`); `reverse` walks the
    path the other way (the body on its other side)."""

    circle: CircleSpec | None = None
    polyline: Annotated[list[tuple[float, float]], Field(min_length=2)] | None = None
    file: str | None = None
    profile: ProfileSurfaceSpec | None = None
    dxf: str | None = None
    layer: str | None = None
    tolerance: PositiveFloat | None = None
    reverse: bool = False

    @model_validator(mode="after")
    def _one(self):
        if sum(getattr(self, k) is not None for k in ("circle", "polyline", "file", "profile", "dxf")) != 1:
            raise ValueError("a surface is exactly one of circle, polyline, file, profile, dxf")
        for key in ("layer", "tolerance"):
            if getattr(self, key) is not None and self.dxf is None:
                raise ValueError(f"'{key}' belongs to a dxf surface")
        if self.reverse and self.circle is not None:
            raise ValueError("'reverse' does not apply to a circle (use inside = true)")
        return self


class MotionSpec(CurveMixin):
    """A rigid translation of the mould, applied as (ur, uz) x f(t)."""

    ur: float = 0.0
    uz: float = 0.0


class ContactSpec(Strict):
    """A [[contact]] table: one rigid mould piece; `name` labels it in plots and
    summary.json (default: its DXF layer in lower case, else "contact[k]")."""

    name: Annotated[str, Field(min_length=1)] | None = None
    surface: SurfaceSpec
    slaves: Selector
    penalty: PositiveFloat | None = None
    tangential_penalty: PositiveFloat | None = None
    friction: Annotated[float, Field(ge=0)] = 0.0
    sticky: bool = False
    motion: MotionSpec = MotionSpec()
    depth: PositiveFloat | None = None
    search: Literal["buckets", "binary", "brute"] = "buckets"
    # contact stabilization, a fraction of the normal penalty (ContactPair); absent: on for a
    # body held only by contact, off elsewhere
    stabilization: Annotated[float, Field(ge=0, le=1)] | None = None
    # heat to the mould ([thermal]): h_c (T - temperature x f(t)) through the slave nodes in contact
    temperature: float | None = None
    temperature_curve: CurveKnots | None = None
    conductance: Annotated[float, Field(gt=0)] | None = None
    conductance_gap: Annotated[float, Field(ge=0)] = 0.0  # heat across gaps below this, fading linearly

    @model_validator(mode="after")
    def _law(self):
        if self.sticky and self.friction:
            raise ValueError("give friction or sticky = true, not both")
        if (self.temperature is None) != (self.conductance is None):
            raise ValueError("temperature (the mould's) and conductance go together")
        if self.temperature_curve is not None and self.temperature is None:
            raise ValueError("temperature_curve needs temperature")
        if "conductance_gap" in self.model_fields_set and self.conductance is None:
            raise ValueError(
                "conductance_gap needs conductance (and the mould's temperature): no heat flows without them"
            )
        return self


def youngs_modulus(material: Hyperelastic | Viscoelastic | TemperatureDependent) -> float:
    """The small-strain Young's modulus E = 9 kappa mu / (3 kappa + mu) of the material (for
    the default contact penalty)."""
    mu, k = material.shear_modulus, material.kappa
    return 9.0 * k * mu / (3.0 * k + mu)


# the largest magnitude of a coordinate in a mould file (as of any number in a case: schema.py)
MAX_MAGNITUDE = 1e30


def _surface(spec: SurfaceSpec, motion: tuple[float, float], base: Path, where: str):
    surface = _path_surface(spec, motion, base, where)
    return surface.reversed() if spec.reverse else surface


def _path_surface(spec: SurfaceSpec, motion: tuple[float, float], base: Path, where: str):
    if spec.circle is not None:
        c = spec.circle
        return Circle(motion=motion, center=c.center, radius=c.radius, inside=c.inside)
    if spec.polyline is not None:
        points = np.asarray(spec.polyline, float)
    elif spec.profile is not None:
        pieces = tuple(p.build() for p in spec.profile.pieces)
        try:
            profile = Profile(spec.profile.start, pieces)
            profile.sample(1)  # checks the arcs
            return Polyline.from_profile(profile, motion)
        except (ProfileError, ValueError) as exc:
            raise CaseError(f"{where}.surface.profile: {exc}") from None
    elif spec.dxf is not None:
        path = Path(spec.dxf)
        try:
            return read_dxf(
                path if path.is_absolute() else base / path, spec.layer, tolerance=spec.tolerance, motion=motion
            )
        except DxfError as exc:
            raise CaseError(f"{where}.surface.dxf: {exc}") from None
    else:
        assert spec.file is not None, "a surface is a circle, polyline, profile, dxf or file (_one)"
        path = Path(spec.file)
        path = path if path.is_absolute() else base / path
        try:
            with warnings.catch_warnings():  # an empty file: refused below, not warned about
                warnings.simplefilter("ignore", UserWarning)
                points = np.loadtxt(io.StringIO(read_text(path)), delimiter=",", ndmin=2, comments="#")
        except (OSError, ValueError) as exc:  # UnicodeDecodeError is a ValueError
            raise CaseError(f"{where}.surface.file: cannot read {path} as r, z rows ({exc})") from None
        if points.size == 0:
            raise CaseError(f"{where}.surface.file: {path} holds no r, z rows")
        if points.shape[1] != 2:
            raise CaseError(f"{where}.surface.file: {path} must have two columns, r and z")
        bad = np.flatnonzero(~(np.abs(points) <= MAX_MAGNITUDE).all(axis=1))  # NaN compares False
        if bad.size:
            raise CaseError(
                f"{where}.surface.file: {path} row {bad[0] + 1} of the data is not two finite numbers "
                f"(of at most {MAX_MAGNITUDE:g} in magnitude)"
            )
    try:
        return Polyline(motion=motion, points=points)
    except ValueError as exc:
        raise CaseError(f"{where}.surface: {exc}") from None


def _uncrossed(surface, where: str):
    """Refuse a mould outline (sampled arcs included) that crosses or runs back over itself."""
    if isinstance(surface, Polyline):
        pts = surface.polyline()
        found = chain_crossing(pts)
        if found is not None:
            i, j = found
            raise CaseError(
                f"{where}.surface: the outline crosses or runs back over itself (near r, z = "
                f"{pts[i][0]:.6g}, {pts[i][1]:.6g} and {pts[j][0]:.6g}, {pts[j][1]:.6g})"
            )
    return surface


def contact_pair(mesh: Mesh, model: Model, spec: ContactSpec, base: Path, where: str) -> ContactPair:
    """The contact pair of a [[contact]] table (`where`: its key path); files are taken from the
    folder `base` when relative, the default penalty from the model's material."""
    surface = _uncrossed(_surface(spec.surface, (spec.motion.ur, spec.motion.uz), base, where), where)
    surface.curve = spec.motion.build_curve()
    slaves = select_nodes(mesh, spec.slaves.model_dump(), f"{where}.slaves")
    try:
        pair = ContactPair(
            mesh,
            surface,
            slaves,
            spec.penalty,
            friction=spec.friction,
            sticky=spec.sticky,
            tangential_penalty=spec.tangential_penalty,
            depth=spec.depth,
            search=spec.search,
            modulus=youngs_modulus(model.material),
            stabilization=spec.stabilization,
        )
    except ValueError as exc:
        raise CaseError(f"{where}.slaves: {exc}") from None
    if spec.depth is None and spec.conductance is not None:
        # the default search depth follows the element size; heat across gaps up to
        # conductance_gap needs the nodes that far seen, on every mesh of the case (refined too),
        # up to half the body's smaller extent (deeper, nodes behind the mould would be caught)
        reach = 0.5 * float(np.ptp(mesh.points, axis=0).min())
        pair.depth = max(pair.depth, min(spec.conductance_gap, reach))
    pair.name = spec.name or (spec.surface.layer.lower() if spec.surface.layer else None)
    return pair
