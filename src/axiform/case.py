"""The TOML case file: schema (every key validated), and the model built from it.

An invalid case raises CaseError naming the key path and the reason, before any work.
"""

from __future__ import annotations

import contextlib
import hashlib
import io
import itertools
import json
import tomllib
import warnings
from dataclasses import dataclass
from pathlib import Path
from typing import Annotated, Any, Literal

import numpy as np
from pydantic import (
    BaseModel,
    ConfigDict,
    Field,
    ValidationError,
    field_validator,
    model_validator,
)

from .cavity import CavityError
from .contact.dxf import DxfError, read_dxf
from .contact.pair import ContactPair
from .curves import PROPORTIONAL, Curve
from .contact.surfaces import Circle, Polyline
from .case_material import MaterialSpec
from .guards import boundary_crossing, chain_crossing, free_to_slide, not_numbers
from .materials import Hyperelastic
from .mesh import Mesh, MeshError, layered, read_gmsh, rectangle
from .model import Model
from .profile import Arc, Line, Profile, ProfileError
from .selectors import SelectorError, select_edges, select_nodes
from .solver import ArcLengthControl, DisplacementControl, LoadControl, NewtonOptions
from .thickness import default_wall

DofName = Literal["ur", "uz", "rot"]
PositiveFloat = Annotated[float, Field(gt=0)]
# a load curve [[t0, f0], [t1, f1], ...]: t increasing, the applied value is value x f(t)
CurveKnots = Annotated[list[tuple[float, float]], Field(min_length=1)]


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


class LinePiece(Strict):
    to: tuple[float, float]
    divisions: Annotated[int, Field(ge=1)]


class ArcPiece(Strict):
    center: tuple[float, float]
    to: tuple[float, float]
    divisions: Annotated[int, Field(ge=1)]
    ccw: bool = True


class PieceSpec(Strict):
    """One piece of a profile: { line = {...} } or { arc = {...} }."""

    line: LinePiece | None = None
    arc: ArcPiece | None = None

    @model_validator(mode="after")
    def _one(self):
        if (self.line is None) == (self.arc is None):
            raise ValueError("a profile piece is either { line = ... } or { arc = ... }")
        return self


_GRID_KEYS = {"rectangle": ("r", "z", "divisions"), "gmsh": ("file",),
              "layered": ("start", "profile", "thickness", "layers")}


class MeshSpec(Strict):
    kind: Literal["rectangle", "gmsh", "layered"] = "rectangle"
    element: Literal["q4", "q8", "sfr"]
    r: tuple[float, float] | None = None
    z: tuple[float, float] | None = None
    divisions: tuple[Annotated[int, Field(ge=1)], Annotated[int, Field(ge=1)]] | None = None
    file: str | None = None
    start: tuple[float, float] | None = None
    profile: Annotated[list[PieceSpec], Field(min_length=1)] | None = None
    thickness: PositiveFloat | Annotated[list[tuple[float, PositiveFloat]], Field(min_length=2)] | None = None
    wall: Literal["r", "z"] | None = None  # rectangle: direction through the wall (thickness)
    grading: tuple[PositiveFloat, PositiveFloat] | None = None  # rectangle: last element / first
    layers: Annotated[int, Field(ge=1)] | None = None
    sfr_edges: Literal["tie", "fix", "free"] = "tie"
    formulation: Literal["mixed", "displacement"] = "mixed"

    @model_validator(mode="after")
    def _kind(self):
        for kind, keys in _GRID_KEYS.items():
            for key in keys:
                given = getattr(self, key) is not None
                if kind == self.kind and not given:
                    raise ValueError(f"a {kind} mesh needs '{key}'")
                if kind != self.kind and given and key not in _GRID_KEYS[self.kind]:
                    raise ValueError(f"'{key}' belongs to kind = \"{kind}\"")
        if self.wall is not None and self.kind != "rectangle":
            raise ValueError("'wall' belongs to kind = \"rectangle\" (a layered wall knows its own)")
        if self.grading is not None and self.kind != "rectangle":
            raise ValueError("'grading' belongs to kind = \"rectangle\"")
        if self.kind == "rectangle":
            if not self.r[0] < self.r[1] or not self.z[0] < self.z[1]:
                raise ValueError("r and z must be given as [min, max] with min < max")
            if self.r[0] < 0:
                raise ValueError("r must be >= 0 (the meridian plane)")
        if self.kind == "layered" and isinstance(self.thickness, list):
            s = [row[0] for row in self.thickness]
            if any(b <= a for a, b in itertools.pairwise(s)):
                raise ValueError("thickness table: arc lengths must increase")
        return self

    def build_profile(self):
        pieces = tuple(Line(p.line.to, p.line.divisions) if p.line else
                       Arc(p.arc.center, p.arc.to, p.arc.divisions, p.arc.ccw) for p in self.profile)
        return Profile(self.start, pieces)


class CurveMixin(Strict):
    curve: CurveKnots | None = None

    @model_validator(mode="after")
    def _curve(self):
        if self.curve is not None:
            t = [k[0] for k in self.curve]
            if any(b <= a for a, b in zip(t, t[1:])):
                raise ValueError("curve: the times must increase")
        return self

    def build_curve(self) -> Curve:
        return PROPORTIONAL if self.curve is None else Curve(self.curve)


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


class CavitySpec(CurveMixin):
    """A gas cavity (DESIGN 10.5): the wall edges that bound the gas, and its control."""

    name: Annotated[str, Field(min_length=1)]
    boundary: Selector
    control: Literal["pressure", "volume", "gas"] = "pressure"
    pressure: float | None = None
    volume: PositiveFloat | None = None
    content: PositiveFloat | None = None
    ambient: PositiveFloat | None = None

    @model_validator(mode="after")
    def _control(self):
        need = {"pressure": ("pressure",), "volume": ("volume",), "gas": ("content", "ambient")}[self.control]
        for key in need:
            if getattr(self, key) is None:
                raise ValueError(f"control = \"{self.control}\" needs '{key}'")
        for key in ("pressure", "volume", "content", "ambient"):
            if key not in need and getattr(self, key) is not None:
                raise ValueError(f"'{key}' does not belong to control = \"{self.control}\"")
        return self

    @property
    def value(self) -> float:
        return {"pressure": self.pressure, "volume": self.volume, "gas": self.content}[self.control]


HISTORY_COLUMNS = ("step", "load_factor", "iterations")  # history.csv's first columns


class MonitorSpec(Strict):
    """One node's displacement (at + dof), the reaction summed over nodes (reaction + dof), or
    a quantity of a contact pair (contact = index of the [[contact]] table + quantity)."""

    name: str
    at: Selector | None = None
    reaction: Selector | None = None
    dof: DofName | None = None
    contact: Annotated[int, Field(ge=0)] | None = None
    cavity: str | None = None
    quantity: Literal["force-r", "force-z", "area", "penetration", "pressure", "volume"] | None = None

    @field_validator("name")
    @classmethod
    def _name(cls, name: str) -> str:
        if not name.strip() or name in HISTORY_COLUMNS or name != name.strip():
            raise ValueError(f"{name!r}: a monitor name must not be empty, begin or end with blanks, or be "
                             f"one of the columns {', '.join(HISTORY_COLUMNS)}")
        return name

    @model_validator(mode="after")
    def _one(self):
        given = [k for k in ("at", "reaction", "contact", "cavity") if getattr(self, k) is not None]
        if len(given) != 1:
            raise ValueError("a monitor needs exactly one of 'at', 'reaction', 'contact' or 'cavity'")
        if self.cavity is not None:
            if self.quantity not in ("pressure", "volume"):
                raise ValueError("a cavity monitor needs quantity = \"pressure\" or \"volume\"")
            if self.dof is not None:
                raise ValueError("'dof' does not belong to a cavity monitor")
            return self
        if self.quantity in ("pressure", "volume"):
            raise ValueError(f"quantity = \"{self.quantity}\" belongs to a cavity monitor")
        if self.contact is None:
            if self.dof is None:
                raise ValueError(f"a monitor with '{given[0]}' needs 'dof'")
            if self.quantity is not None:
                raise ValueError("'quantity' belongs to a contact monitor")
        else:
            if self.quantity is None:
                raise ValueError("a contact monitor needs 'quantity'")
            if self.dof is not None:
                raise ValueError("'dof' does not belong to a contact monitor")
        return self


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
    surface: SurfaceSpec
    slaves: Selector
    penalty: PositiveFloat | None = None
    tangential_penalty: PositiveFloat | None = None
    friction: Annotated[float, Field(ge=0)] = 0.0
    sticky: bool = False
    motion: MotionSpec = MotionSpec()
    depth: PositiveFloat | None = None
    search: Literal["buckets", "binary", "brute"] = "buckets"

    @model_validator(mode="after")
    def _law(self):
        if self.sticky and self.friction:
            raise ValueError("give friction or sticky = true, not both")
        return self


class DofRef(Strict):
    at: Selector
    dof: DofName


class StopSpec(Strict):
    at: Selector
    dof: Literal["ur", "uz"]
    value: float


class SolverSpec(Strict):
    control: Literal["load", "displacement", "arc-length"] = "load"
    dof: DofRef | None = None
    target: float | None = None
    steps: Annotated[int, Field(ge=1)] = 10
    arc_length: PositiveFloat | None = None
    stop: StopSpec | None = None
    max_steps: Annotated[int, Field(ge=1)] = 1000
    max_iterations: Annotated[int, Field(ge=1)] = 20
    tolerance: Annotated[float, Field(gt=0, lt=1)] = 1e-8
    min_step: Annotated[float, Field(gt=0, le=1)] = 1e-4
    growth: Annotated[float, Field(ge=1)] = 1.5

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
        if self.target is not None and self.target == 0:
            raise ValueError("target must not be 0")
        return self


class OutputSpec(Strict):
    every: Annotated[int, Field(ge=1)] = 1  # field output every k-th converged step (and the last)
    vtu: bool = True
    gid: bool = False
    plots: bool = True
    revolved: Annotated[int, Field(ge=0)] = 0  # sectors of a 3D revolved copy of the last step
    thickness_every: Annotated[int, Field(ge=1)] | None = None  # thickness/step_NNNN.csv every k-th step


Unit = Annotated[str, Field(min_length=1)]


class UnitsSpec(Strict):
    """The units the case's numbers are in: labels for plots and summary.json, no conversion."""

    length: Unit | None = None
    pressure: Unit | None = None
    force: Unit | None = None
    time: Unit | None = None


class RestartSpec(Strict):
    """Checkpoints for `axiform run --resume`: every k converged steps and at any stop (0: none)."""

    every: Annotated[int, Field(ge=0)] = 10


class Case(Strict):
    title: str = ""
    mesh: MeshSpec
    material: MaterialSpec
    fix: list[FixSpec] = []
    pressure: list[PressureSpec] = []
    point_load: list[PointLoadSpec] = []
    monitor: list[MonitorSpec] = []
    contact: list[ContactSpec] = []
    cavity: list[CavitySpec] = []
    solver: SolverSpec = SolverSpec()
    output: OutputSpec = OutputSpec()
    restart: RestartSpec = RestartSpec()
    units: UnitsSpec = UnitsSpec()


# the names pydantic gives the members of a union in an error's location: not keys
_PYDANTIC_TAGS = ("function-", "tuple[", "list[", "dict[", "constrained-", "lax-or-strict[", "json-or-python[",
                  "tagged-union[", "union[", "nullable[", "is-instance[", "literal[")


def _loc(loc: tuple) -> str:
    out = ""
    for part in loc:
        if isinstance(part, int):
            out += f"[{part}]"
        elif str(part).startswith(_PYDANTIC_TAGS) or part in ("float", "int", "str", "bool"):
            continue
        else:
            out += ("." if out else "") + str(part)
    return out or "(case)"


def parse(data: dict[str, Any]) -> Case:
    """Validate a case given as a dict (as TOML reads it); CaseError lists every problem with
    its key path.  Every number must be finite, and types are strict: no "80" for 80.0, no
    true for 1 (the tree goes through JSON, whose strict mode still takes arrays for tuples
    and integers for floats)."""
    bad = not_numbers(data)
    if bad:
        raise CaseError("\n".join(bad))
    try:
        return Case.model_validate_json(json.dumps(data), strict=True)
    except ValidationError as exc:
        lines = []
        for err in exc.errors():
            msg = err["msg"].removeprefix("Value error, ")
            if err["type"] == "extra_forbidden":
                msg = "unknown key"
            lines.append(f"{_loc(err['loc'])}: {msg}")
        raise CaseError("\n".join(dict.fromkeys(lines))) from None


def override(data: dict[str, Any], assignment: str) -> None:
    """Apply KEY=VALUE: KEY dotted, with [i] for an entry of an array of tables
    (contact[1].friction), VALUE in TOML syntax (a bare word is taken as a string)."""
    key, sep, text = assignment.partition("=")
    if not sep or not key.strip():
        raise CaseError(f"--set {assignment!r}: expected KEY=VALUE")
    try:
        value = tomllib.loads(f"v = {text}")["v"]
    except tomllib.TOMLDecodeError:
        value = text
    parts = []
    for part in key.strip().split("."):
        name, _, index = part.partition("[")
        parts.append(name)
        if index:
            if not index.endswith("]") or not index[:-1].isdigit():
                raise CaseError(f"--set {key}: bad index in '{part}'")
            parts.append(int(index[:-1]))
    node: Any = data
    for p, nxt in itertools.pairwise(parts):
        if isinstance(p, int):
            if not isinstance(node, list) or p >= len(node):
                raise CaseError(f"--set {key}: there is no entry {p}")
            node = node[p]
        else:
            if not isinstance(node, dict):
                raise CaseError(f"--set {key}: '{p}' is not inside a table")
            node = node.setdefault(p, [] if isinstance(nxt, int) else {})
    last = parts[-1]
    if isinstance(last, int) or not isinstance(node, dict):
        raise CaseError(f"--set {key}: name a key, not an array entry")
    node[last] = value


def load(path: str | Path, overrides: list[str] = ()) -> Case:
    """Read and validate a TOML case file, with optional KEY=VALUE overrides."""
    return parse(read(path, overrides))


def fingerprint(data: dict[str, Any]) -> str:
    """SHA-256 of a case tree (after overrides): equal for texts that differ only in comments,
    layout or key order."""
    return hashlib.sha256(json.dumps(data, sort_keys=True, default=str).encode()).hexdigest()


def read(path: str | Path, overrides: list[str] = ()) -> dict[str, Any]:
    """The tree of a TOML case file with KEY=VALUE overrides applied, not yet validated."""
    path = Path(path)
    try:
        data = tomllib.loads(path.read_bytes().decode("utf-8"))
    except FileNotFoundError:
        raise CaseError(f"{path}: no such file") from None
    except IsADirectoryError:
        raise CaseError(f"{path}: is a directory, not a case file") from None
    except OSError as exc:
        raise CaseError(f"{path}: cannot read it ({exc.strerror or exc})") from None
    except UnicodeDecodeError as exc:
        raise CaseError(f"{path}: not UTF-8 text (byte {exc.start}): a case file is TOML text") from None
    except tomllib.TOMLDecodeError as exc:
        raise CaseError(f"{path}: not valid TOML ({exc})") from None
    for assignment in overrides:
        override(data, assignment)
    return data


_CONTACT_QUANTITY = {"force-r": "force_r", "force-z": "force_z", "area": "contact_area",
                     "penetration": "penetration"}


@dataclass
class Monitor:
    """A named scalar read off each converged step: one dof, a sum of reactions, a contact
    pair's total force, contact area or penetration, or a cavity's pressure or volume."""

    name: str
    dofs: np.ndarray | None = None
    reaction: bool = False
    pair: object = None
    quantity: str = ""
    cavity: object = None

    def value(self, step) -> float:
        if self.cavity is not None:
            return float(self.cavity.pressure_now if self.quantity == "pressure" else self.cavity.volume_now)
        if self.pair is not None:
            return float(self.pair.report()[_CONTACT_QUANTITY[self.quantity]])
        if self.reaction:
            return float(step.r_full[self.dofs].sum())
        return float(step.u[self.dofs].sum())


@dataclass
class Built:
    """What a case turns into: the model, the path-following control, Newton options, monitors."""

    case: Case
    model: Model
    control: LoadControl | DisplacementControl | ArcLengthControl
    options: NewtonOptions
    monitors: list[Monitor]


def _mesh(spec: MeshSpec, base: Path) -> Mesh:
    if spec.kind == "rectangle":
        return rectangle(spec.r, spec.z, spec.divisions, spec.element, grading=spec.grading or (1.0, 1.0))
    if spec.kind == "layered":
        try:
            return layered(spec.build_profile(), spec.thickness, spec.layers, spec.element)
        except ProfileError as exc:
            raise CaseError(f"mesh.profile: {exc}") from None
    path = Path(spec.file)
    path = path if path.is_absolute() else base / path
    if not path.exists():
        raise CaseError(f"mesh.file: no such file {path}")
    said = io.StringIO()  # meshio prints its warnings and errors itself
    try:
        with contextlib.redirect_stdout(said), contextlib.redirect_stderr(said):
            return read_gmsh(path, spec.element)
    except MeshError as exc:
        raise CaseError(f"mesh.file: {exc}") from None
    except (Exception, SystemExit) as exc:  # noqa: BLE001 - meshio raises anything (and calls sys.exit) on bad files
        why = f"{type(exc).__name__}: {exc}" if not isinstance(exc, SystemExit) else said.getvalue().strip()
        raise CaseError(f"mesh.file: cannot read {path} as a gmsh mesh ({' '.join(why.split())})") from None


def youngs_modulus(material: Hyperelastic) -> float:
    """The small-strain Young's modulus E = 9 kappa mu / (3 kappa + mu) of the material (for
    the default contact penalty)."""
    mu, k = material.shear_modulus, material.kappa
    return 9.0 * k * mu / (3.0 * k + mu)


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
        pieces = tuple(Line(p.line.to, 1) if p.line else Arc(p.arc.center, p.arc.to, 1, p.arc.ccw)
                       for p in spec.profile.pieces)
        try:
            profile = Profile(spec.profile.start, pieces)
            profile.sample(1)  # checks the arcs
            return Polyline.from_profile(profile, motion)
        except (ProfileError, ValueError) as exc:
            raise CaseError(f"{where}.surface.profile: {exc}") from None
    elif spec.dxf is not None:
        path = Path(spec.dxf)
        try:
            return read_dxf(path if path.is_absolute() else base / path, spec.layer, tolerance=spec.tolerance,
                            motion=motion)
        except DxfError as exc:
            raise CaseError(f"{where}.surface.dxf: {exc}") from None
    else:
        path = Path(spec.file)
        path = path if path.is_absolute() else base / path
        try:
            with warnings.catch_warnings():  # an empty file: refused below, not warned about
                warnings.simplefilter("ignore", UserWarning)
                points = np.loadtxt(path, delimiter=",", ndmin=2, comments="#")
        except (OSError, ValueError) as exc:
            raise CaseError(f"{where}.surface.file: cannot read {path} as r, z rows ({exc})") from None
        if points.size == 0:
            raise CaseError(f"{where}.surface.file: {path} holds no r, z rows")
        if points.shape[1] != 2:
            raise CaseError(f"{where}.surface.file: {path} must have two columns, r and z")
        bad = np.flatnonzero(~np.isfinite(points).all(axis=1))
        if bad.size:
            raise CaseError(f"{where}.surface.file: {path} row {bad[0] + 1} of the data is not two finite numbers")
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
            raise CaseError(f"{where}.surface: the outline crosses or runs back over itself (near r, z = "
                            f"{pts[i][0]:.6g}, {pts[i][1]:.6g} and {pts[j][0]:.6g}, {pts[j][1]:.6g})")
    return surface


def _contact(mesh: Mesh, model: Model, spec: ContactSpec, base: Path, where: str) -> ContactPair:
    surface = _uncrossed(_surface(spec.surface, (spec.motion.ur, spec.motion.uz), base, where), where)
    surface.curve = spec.motion.build_curve()
    slaves = select_nodes(mesh, spec.slaves.model_dump(), f"{where}.slaves")
    try:
        return ContactPair(mesh, surface, slaves, spec.penalty, friction=spec.friction, sticky=spec.sticky,
                           tangential_penalty=spec.tangential_penalty, depth=spec.depth, search=spec.search,
                           modulus=youngs_modulus(model.material))
    except ValueError as exc:
        raise CaseError(f"{where}.slaves: {exc}") from None


def _one_node(mesh: Mesh, sel: Selector, where: str) -> int:
    nodes = select_nodes(mesh, sel.model_dump(), where)
    if len(nodes) != 1:
        raise CaseError(f"{where}: selector must match exactly one node, it matches {len(nodes)}")
    return int(nodes[0])


def _fix(model: Model, mesh: Mesh, fixes: list[FixSpec]) -> None:
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
                raise CaseError(f"fix[{i}].value: {name} of node {int(nodes[k])} is also prescribed by "
                                f"fix[{owner[d][k]}], with value {float(value[d][k])!r}, not {f.value!r}")
            owner[d], value[d] = i, f.value
        model.prescribe(nodes, f.dofs, f.value, f.build_curve())


def build(case: Case, base: str | Path = ".") -> Built:
    """Turn a validated case into a finalized model; errors name the key at fault."""
    base = Path(base)
    try:
        mesh = _mesh(case.mesh, base)
    except MeshError as exc:
        raise CaseError(f"mesh: {exc}") from None
    try:
        material = case.material.build()
    except ValueError as exc:
        raise CaseError(f"material: {exc}") from None
    try:
        model = Model(mesh, material, formulation=case.mesh.formulation, sfr_edges=case.mesh.sfr_edges)
    except MeshError as exc:
        raise CaseError(f"mesh: {exc}") from None
    crossing = boundary_crossing(mesh.points, mesh.boundary_edges)
    if crossing is not None:
        p = mesh.points[mesh.boundary_edges[crossing[0], 0]]
        raise CaseError(f"mesh: the boundary crosses itself near r, z = {p[0]:.6g}, {p[1]:.6g} "
                        f"(a profile that crosses itself, or overlapping elements)")
    try:
        _fix(model, mesh, case.fix)
        for i, p in enumerate(case.pressure):
            model.pressure(select_edges(mesh, p.on.model_dump(), f"pressure[{i}].on"), p.value, p.build_curve())
        for i, pl in enumerate(case.point_load):
            model.point_load(select_nodes(mesh, pl.at.model_dump(), f"point_load[{i}].at"), pl.dof, pl.value,
                             pl.build_curve())
        cavities = {}
        for i, c in enumerate(case.cavity):
            if c.name in cavities:
                raise CaseError(f"cavity[{i}].name: '{c.name}' is used twice")
            edges = select_edges(mesh, c.boundary.model_dump(), f"cavity[{i}].boundary")
            try:
                cavities[c.name] = model.cavity(edges, c.name, c.control, c.value, c.ambient or 0.0, c.build_curve())
            except CavityError as exc:
                raise CaseError(f"cavity[{i}].boundary: {exc}") from None
        pairs = [_contact(mesh, model, c, base, f"contact[{i}]") for i, c in enumerate(case.contact)]
        for pair in pairs:
            model.contact(pair)
        monitors = []
        for i, m in enumerate(case.monitor):
            if m.cavity is not None:
                if m.cavity not in cavities:
                    raise CaseError(f"monitor[{i}].cavity: no [[cavity]] is named '{m.cavity}'")
                monitors.append(Monitor(m.name, cavity=cavities[m.cavity], quantity=m.quantity))
                continue
            if m.contact is not None:
                if m.contact >= len(pairs):
                    raise CaseError(f"monitor[{i}].contact: there are {len(pairs)} [[contact]] tables (from 0)")
                monitors.append(Monitor(m.name, pair=pairs[m.contact], quantity=m.quantity))
                continue
            if m.dof == "rot" and model.dpn == 2:
                raise CaseError(f"monitor[{i}].dof: element '{case.mesh.element}' has no rotation dof")
            if m.at is not None:
                nodes = np.array([_one_node(mesh, m.at, f"monitor[{i}].at")])
            else:
                nodes = select_nodes(mesh, m.reaction.model_dump(), f"monitor[{i}].reaction")
            monitors.append(Monitor(m.name, model.dof(nodes, m.dof), m.reaction is not None))
        if len({m.name for m in monitors}) != len(monitors):
            raise CaseError("monitor: names must be unique")
        s = case.solver
        if s.control == "displacement":
            if s.dof.dof == "rot":
                raise CaseError("solver.dof.dof: drive a displacement (ur or uz), not a fibre rotation")
            node = _one_node(mesh, s.dof.at, "solver.dof.at")
            dof = int(model.dof(node, s.dof.dof))
            if dof in model.fixed:
                raise CaseError("solver.dof: the driven dof is also fixed by a [[fix]] table")
            control = DisplacementControl(dof, s.target, s.steps)
        elif s.control == "arc-length":
            stop_dof = stop_value = None
            if s.stop is not None:
                stop_dof = int(model.dof(_one_node(mesh, s.stop.at, "solver.stop.at"), s.stop.dof))
                if stop_dof in model.fixed:
                    raise CaseError("solver.stop: that dof is fixed by a [[fix]] table")
                stop_value = s.stop.value
            control = ArcLengthControl(1.0 if s.target is None else s.target, s.steps, s.arc_length,
                                       stop_dof, stop_value, s.max_steps)
        else:
            control = LoadControl(1.0 if s.target is None else s.target, s.steps)
        moving = any(c.motion.ur or c.motion.uz for c in case.contact)
        gas = any(c.control != "pressure" or c.pressure for c in case.cavity)
        loads = [*case.pressure, *case.point_load, *case.fix]
        if not any(item.value for item in loads) and not moving and not gas:
            raise CaseError("pressure: nothing loads the model: every [[pressure]], [[point_load]] and [[fix]] "
                            "value is zero (or absent), no [[contact]] surface moves and no [[cavity]] is loaded")
    except SelectorError as exc:
        raise CaseError(str(exc)) from None
    held_uz = [d // model.dpn for d in model.fixed if d % model.dpn == 1]
    touching = np.concatenate([p.nodes for p in pairs]) if pairs else np.zeros(0, np.int64)
    free = free_to_slide(mesh.n_nodes, mesh.cells, np.array(held_uz, np.int64), touching)
    if free:
        raise CaseError(f"fix: a mechanism: {len(free)} bod{'y' if len(free) == 1 else 'ies'} of the mesh can "
                        "move rigidly along z (no [[fix]] holds uz on it and no [[contact]] touches it)")
    if case.mesh.kind == "rectangle":  # the wall is normal to the faces that carry the pressure
        loaded = model.pressures + getattr(model, "cavities", [])
        mesh.set_wall(case.mesh.wall or default_wall(mesh.points, [p.nodes for p in loaded]))
    try:
        model.finalize()
    except ValueError as exc:  # a tied fibre rotation prescribed twice
        raise CaseError(f"fix: {exc}") from None
    options = NewtonOptions(tolerance=s.tolerance, max_iterations=s.max_iterations,
                            min_step=s.min_step, growth=s.growth)
    return Built(case, model, control, options, monitors)
