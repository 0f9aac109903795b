"""The TOML case file: schema (every key validated), and the model built from it.

An invalid case raises CaseError naming the key path and the reason, before any work.
"""

from __future__ import annotations

import tomllib
from dataclasses import dataclass
from pathlib import Path
from typing import Annotated, Any, Literal

import numpy as np
from pydantic import BaseModel, ConfigDict, Field, ValidationError, model_validator

from .contact.dxf import DxfError, read_dxf
from .contact.pair import ContactPair
from .contact.surfaces import Circle, Polyline
from .materials import MooneyRivlin
from .mesh import Mesh, MeshError, layered, read_gmsh, rectangle
from .profile import Arc, Line, Profile, ProfileError
from .model import Model
from .selectors import SelectorError, select_edges, select_nodes
from .solver import ArcLengthControl, DisplacementControl, LoadControl, NewtonOptions

DofName = Literal["ur", "uz", "rot"]
PositiveFloat = Annotated[float, Field(gt=0)]


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
    layers: Annotated[int, Field(ge=1)] | None = None
    sfr_edges: Literal["tie", "fix", "free"] = "tie"

    @model_validator(mode="after")
    def _kind(self):
        for kind, keys in _GRID_KEYS.items():
            for key in keys:
                given = getattr(self, key) is not None
                if kind == self.kind and not given:
                    raise ValueError(f"a {kind} mesh needs '{key}'")
                if kind != self.kind and given and key not in _GRID_KEYS[self.kind]:
                    raise ValueError(f"'{key}' belongs to kind = \"{kind}\"")
        if self.kind == "rectangle":
            if not self.r[0] < self.r[1] or not self.z[0] < self.z[1]:
                raise ValueError("r and z must be given as [min, max] with min < max")
            if self.r[0] < 0:
                raise ValueError("r must be >= 0 (the meridian plane)")
        if self.kind == "layered" and isinstance(self.thickness, list):
            s = [row[0] for row in self.thickness]
            if any(b <= a for a, b in zip(s, s[1:])):
                raise ValueError("thickness table: arc lengths must increase")
        return self

    def build_profile(self):
        pieces = tuple(Line(p.line.to, p.line.divisions) if p.line else
                       Arc(p.arc.center, p.arc.to, p.arc.divisions, p.arc.ccw) for p in self.profile)
        return Profile(self.start, pieces)


class MaterialSpec(Strict):
    """Mooney-Rivlin (C1, C2) or neo-Hooke (C1, or E and nu); kappa given, or from E and nu."""

    model: Literal["mooney-rivlin", "neo-hooke"]
    C1: PositiveFloat | None = None
    C2: Annotated[float, Field(ge=0)] | None = None
    kappa: PositiveFloat | None = None
    E: PositiveFloat | None = None
    nu: Annotated[float, Field(gt=-1.0, lt=0.5)] | None = None

    @model_validator(mode="after")
    def _constants(self):
        if (self.E is None) != (self.nu is None):
            raise ValueError("E and nu go together")
        if self.kappa is not None and self.E is not None:
            raise ValueError("give kappa or E and nu, not both")
        if self.kappa is None and self.E is None:
            raise ValueError("missing material constant: kappa (or E and nu)")
        if self.model == "mooney-rivlin":
            missing = [k for k in ("C1", "C2") if getattr(self, k) is None]
            if missing:
                raise ValueError(f"missing material constant: {', '.join(missing)}")
        else:
            if self.C2 not in (None, 0.0):
                raise ValueError("neo-hooke has no C2 (use mooney-rivlin)")
            if self.C1 is None and self.E is None:
                raise ValueError("missing material constant: C1 (or E and nu)")
        return self

    def build(self) -> MooneyRivlin:
        C2 = self.C2 or 0.0
        C1 = self.C1 if self.C1 is not None else self.E / (4.0 * (1.0 + self.nu))  # mu / 2
        if self.kappa is None:
            return MooneyRivlin.from_E_nu(C1, C2, self.E, self.nu)
        return MooneyRivlin(C1, C2, self.kappa)


class FixSpec(Strict):
    at: Selector
    dofs: Annotated[list[DofName], Field(min_length=1)]
    value: float = 0.0


class PressureSpec(Strict):
    on: Selector
    value: float


class PointLoadSpec(Strict):
    at: Selector
    dof: Literal["ur", "uz"]
    value: float


class MonitorSpec(Strict):
    """One node's displacement (at + dof), the reaction summed over nodes (reaction + dof), or
    a quantity of a contact pair (contact = index of the [[contact]] table + quantity)."""

    name: str
    at: Selector | None = None
    reaction: Selector | None = None
    dof: DofName | None = None
    contact: Annotated[int, Field(ge=0)] | None = None
    quantity: Literal["force-r", "force-z", "area", "penetration"] | None = None

    @model_validator(mode="after")
    def _one(self):
        given = [k for k in ("at", "reaction", "contact") if getattr(self, k) is not None]
        if len(given) != 1:
            raise ValueError("a monitor needs exactly one of 'at', 'reaction' or 'contact'")
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


class MotionSpec(Strict):
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


class Case(Strict):
    title: str = ""
    mesh: MeshSpec
    material: MaterialSpec
    fix: list[FixSpec] = []
    pressure: list[PressureSpec] = []
    point_load: list[PointLoadSpec] = []
    monitor: list[MonitorSpec] = []
    contact: list[ContactSpec] = []
    solver: SolverSpec = SolverSpec()
    output: OutputSpec = OutputSpec()


def _loc(loc: tuple) -> str:
    out = ""
    for part in loc:
        if isinstance(part, int):
            out += f"[{part}]"
        elif part in ("function-after",) or str(part).startswith(("function-", "tuple[", "list[")):
            continue
        else:
            out += ("." if out else "") + str(part)
    return out or "(case)"


def parse(data: dict[str, Any]) -> Case:
    """Validate a case given as a dict; CaseError lists every problem with its key path."""
    try:
        return Case.model_validate(data)
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
    for p, nxt in zip(parts[:-1], parts[1:]):
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
    path = Path(path)
    try:
        data = tomllib.loads(path.read_text())
    except FileNotFoundError:
        raise CaseError(f"{path}: no such file") from None
    except tomllib.TOMLDecodeError as exc:
        raise CaseError(f"{path}: not valid TOML ({exc})") from None
    for assignment in overrides:
        override(data, assignment)
    return parse(data)


_CONTACT_QUANTITY = {"force-r": "force_r", "force-z": "force_z", "area": "contact_area",
                     "penetration": "penetration"}


@dataclass
class Monitor:
    """A named scalar read off each converged step: one dof, a sum of reactions, or a
    contact pair's total force, contact area or penetration."""

    name: str
    dofs: np.ndarray | None = None
    reaction: bool = False
    pair: object = None
    quantity: str = ""

    def value(self, step) -> float:
        if self.pair is not None:
            return float(self.pair.report()[_CONTACT_QUANTITY[self.quantity]])
        if self.reaction:
            return float(step.evaluation.r_full[self.dofs].sum())
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
        return rectangle(spec.r, spec.z, spec.divisions, spec.element)
    if spec.kind == "layered":
        try:
            return layered(spec.build_profile(), spec.thickness, spec.layers, spec.element)
        except ProfileError as exc:
            raise CaseError(f"mesh.profile: {exc}") from None
    path = Path(spec.file)
    path = path if path.is_absolute() else base / path
    if not path.exists():
        raise CaseError(f"mesh.file: no such file {path}")
    try:
        return read_gmsh(path, spec.element)
    except MeshError:
        raise
    except Exception as exc:  # meshio's own errors for unreadable files
        raise CaseError(f"mesh.file: cannot read {path} ({exc})") from None


def youngs_modulus(material: MooneyRivlin) -> float:
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
            points = np.loadtxt(path, delimiter=",", ndmin=2, comments="#")
        except (OSError, ValueError) as exc:
            raise CaseError(f"{where}.surface.file: cannot read {path} as r, z rows ({exc})") from None
        if points.shape[1] != 2:
            raise CaseError(f"{where}.surface.file: {path} must have two columns, r and z")
    try:
        return Polyline(motion=motion, points=points)
    except ValueError as exc:
        raise CaseError(f"{where}.surface: {exc}") from None


def _contact(mesh: Mesh, model: Model, spec: ContactSpec, base: Path, where: str) -> ContactPair:
    surface = _surface(spec.surface, (spec.motion.ur, spec.motion.uz), base, where)
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


def build(case: Case, base: str | Path = ".") -> Built:
    """Turn a validated case into a finalized model; errors name the key at fault."""
    base = Path(base)
    try:
        mesh = _mesh(case.mesh, base)
        model = Model(mesh, case.material.build(), sfr_edges=case.mesh.sfr_edges)
    except MeshError as exc:
        raise CaseError(f"mesh: {exc}") from None
    try:
        for i, f in enumerate(case.fix):
            model.prescribe(select_nodes(mesh, f.at.model_dump(), f"fix[{i}].at"), f.dofs, f.value)
        for i, p in enumerate(case.pressure):
            model.pressure(select_edges(mesh, p.on.model_dump(), f"pressure[{i}].on"), p.value)
        for i, pl in enumerate(case.point_load):
            model.point_load(select_nodes(mesh, pl.at.model_dump(), f"point_load[{i}].at"), pl.dof, pl.value)
        pairs = [_contact(mesh, model, c, base, f"contact[{i}]") for i, c in enumerate(case.contact)]
        for pair in pairs:
            model.contact(pair)
        monitors = []
        for i, m in enumerate(case.monitor):
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
        if not case.pressure and not case.point_load and not any(f.value for f in case.fix) and not moving:
            raise CaseError("nothing loads the model: give [[pressure]], [[point_load]], a [[fix]] with a "
                            "value or a moving [[contact]] surface")
    except SelectorError as exc:
        raise CaseError(str(exc)) from None
    model.finalize()
    options = NewtonOptions(tolerance=s.tolerance, max_iterations=s.max_iterations,
                            min_step=s.min_step, growth=s.growth)
    return Built(case, model, control, options, monitors)
