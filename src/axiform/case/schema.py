"""The TOML case file: schema (every key validated), and the model built from it.

An invalid case raises CaseError naming the key path and the reason, before any work.
Each table has a module beside this one, with its schema and what it builds: case/mesh.py,
material.py, loads.py ([[fix]], [[pressure]], [[point_load]]), contact.py, cavity.py,
monitor.py, solver.py, output.py ([output], [units], [restart]), temperature.py, thermal.py
([thermal], [[convection]]), gravity.py; base.py holds what they share, tables.py the list
of tables and the validated Case.  A table's module (and the model code behind it) is
imported where a case holds the table.  This module holds the whole case: reading,
validation and `build`.
"""

from __future__ import annotations

import hashlib
import itertools
import json
import math
import tomllib
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
from pydantic import ValidationError

from ..fem.mesh import MeshError
from ..fem.selectors import SelectorError
from ..io.columns import HISTORY_COLUMNS
from ..io.text import MAX_CASE_BYTES, FileTooLarge, read_text
from ..materials import LAWS
from ..model.guards import boundary_crossing, free_to_slide
from ..model.model import Model
from ..model.system import System
from ..post.thickness import default_wall
from ..solve.solver import ArcLengthControl, DisplacementControl, LoadControl, NewtonOptions
from .base import CaseError, CurveKnots, CurveMixin, DofName, PositiveFloat, Selector, Strict
from .loads import FixSpec, PointLoadSpec, PressureSpec, apply_loads, prescribe_fixes
from .mesh import build_mesh
from .output import MAX_REVOLVED_POINTS
from .solver import build_control
from .suggest import did_you_mean
from .tables import TABLES, Case, validator
from .tree import key_path, not_numbers

if TYPE_CHECKING:
    from .monitor import Monitor

__all__ = [
    "CaseError",
    "Strict",
    "Selector",
    "DofName",
    "PositiveFloat",
    "CurveKnots",
    "CurveMixin",
    "HISTORY_COLUMNS",
    "TABLES",
    "Case",
    "parse",
    "override",
    "load",
    "fingerprint",
    "read",
    "Built",
    "build",
]


# the names pydantic gives the members of a union in an error's location: not keys
_PYDANTIC_TAGS = (
    "function-",
    "tuple[",
    "list[",
    "dict[",
    "constrained-",
    "lax-or-strict[",
    "json-or-python[",
    "tagged-union[",
    "union[",
    "nullable[",
    "is-instance[",
    "literal[",
)


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


# the magnitudes a number of a case may have: the model multiplies lengths, moduli, pressures and
# penalties together (a stiffness is a modulus x a length^2 / a length, an energy a modulus x a
# volume, the penalty of a contact a modulus / a length x 1e3 ...), and a number beyond 1e30 in
# magnitude (or a nonzero one below 1e-30) overflows (or underflows) in those products, to be
# found much later as "a singular tangent" or "an overflow of the material law"; no unit
# system needs them (a modulus of 1e11 Pa, a length of 1e-9 m)
MAX_MAGNITUDE = 1e30
MIN_MAGNITUDE = 1e-30


def out_of_range(data: Any, path: list[str | int] | None = None) -> list[str]:
    """Every number of a case tree beyond MAX_MAGNITUDE or nonzero below MIN_MAGNITUDE in
    magnitude, and every string holding a NUL character, as 'key.path: reason' lines."""
    path = path or []
    if isinstance(data, dict):
        return [line for k, v in data.items() for line in out_of_range(v, [*path, str(k)])]
    if isinstance(data, list):
        return [line for i, v in enumerate(data) for line in out_of_range(v, [*path, i])]
    if isinstance(data, str) and "\x00" in data:  # no file name, label or name holds one
        return [f"{key_path(path)}: holds a NUL character"]
    if isinstance(data, (int, float)) and not isinstance(data, bool) and math.isfinite(data):
        size = abs(data)
        if size > MAX_MAGNITUDE:
            return [
                f"{key_path(path)}: {data:g} is too large a magnitude (at most {MAX_MAGNITUDE:g}: the "
                f"products of lengths, moduli, pressures and penalties would overflow); use other units"
            ]
        if 0 < size < MIN_MAGNITUDE:
            return [
                f"{key_path(path)}: {data:g} is too small a magnitude (nonzero values must be at least "
                f"{MIN_MAGNITUDE:g}: their products would underflow to zero); use 0 or other units"
            ]
    return []


def not_table_numbers(data: Any, path: list[str | int] | None = None) -> list[str]:
    """Every cell of a table (a list of rows: [[x, y], ...], as a curve, a temperature table, a
    polyline or a box) that is not a number (a string, a boolean, a list, a table), and every
    row of one that is not a list, as 'key.path: reason' lines: a table of a case holds
    numbers only, and its validators compare and sort them."""
    path = path or []
    if isinstance(data, dict):
        return [line for k, v in data.items() for line in not_table_numbers(v, [*path, str(k)])]
    if not isinstance(data, list):
        return []
    if not any(isinstance(row, list) for row in data):
        return [line for i, v in enumerate(data) for line in not_table_numbers(v, [*path, i])]
    bad = []
    for i, row in enumerate(data):
        if not isinstance(row, list):
            bad.append(f"{key_path([*path, i])}: a row of the table must be a list of numbers, got {row!r}")
            continue
        bad += [
            f"{key_path([*path, i, j])}: must be a number, got {cell!r}"
            for j, cell in enumerate(row)
            if isinstance(cell, bool) or not isinstance(cell, int | float)
        ]
    return bad


NETWORK_KEYS = ("stiffness_ratio", "flow", "A", "C", "m", "E", "shift")  # a [[material.network]]'s own


def law_keys(data: dict[str, Any]) -> dict[tuple, list[str]]:
    """The keys [material] and each [[material.network]] take for their model (when the model
    is a known one; a network without one: its own keys), for the "did you mean" of an unknown
    key there: C3 in a Mooney-Rivlin table is not a Yeoh C30, kappa in a network no Ogden alpha."""
    table = data.get("material")
    if not isinstance(table, dict):
        return {}
    out: dict[tuple, list[str]] = {}
    model = table.get("model")
    if isinstance(model, str) and model in LAWS:
        common = ["kappa", "E", "nu", "viscoelastic", "network", "freeze", "density"]
        out[("material",)] = ["model", *LAWS[model].key_names, *common]
    networks = table.get("network")
    for k, network in enumerate(networks if isinstance(networks, list) else ()):
        model = network.get("model") if isinstance(network, dict) else None
        if model is None or (isinstance(model, str) and model in LAWS):
            own = LAWS[model].key_names if model is not None else ()
            out[("material", "network", k)] = ["model", *own, *NETWORK_KEYS]
    return out


def parse(data: dict[str, Any]) -> Case:
    """Validate a case given as a dict (as TOML reads it); CaseError lists every problem with
    its key path.  Every number must be finite, and types are strict: no "80" for 80.0, no
    true for 1 (the tree goes through JSON, whose strict mode still takes arrays for tuples
    and integers for floats)."""
    bad = not_numbers(data) or not_table_numbers(data) or out_of_range(data)
    if bad:
        raise CaseError("\n".join(bad))
    root = validator(frozenset(data.keys() & TABLES.keys()))
    try:
        checked = root.model_validate_json(json.dumps(data), strict=True)
    except ValidationError as exc:
        lines = []
        for err in exc.errors():
            msg = err["msg"].removeprefix("Value error, ")
            if err["type"] == "extra_forbidden":
                msg = "unknown key"
            lines.append(f"{_loc(err['loc'])}: {msg}{did_you_mean(root, dict(err), law_keys(data))}")
        raise CaseError("\n".join(dict.fromkeys(lines))) from None
    return Case(**dict(checked))


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
    parts: list[str | int] = []
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


def load(path: str | Path, overrides: Sequence[str] = ()) -> Case:
    """Read and validate a TOML case file, with optional KEY=VALUE overrides."""
    return parse(read(path, overrides))


def fingerprint(data: dict[str, Any]) -> str:
    """SHA-256 of a case tree (after overrides): equal for texts that differ only in comments,
    layout or key order."""
    return hashlib.sha256(json.dumps(data, sort_keys=True, default=str).encode()).hexdigest()


def read(path: str | Path, overrides: Sequence[str] = ()) -> dict[str, Any]:
    """The tree of a TOML case file with KEY=VALUE overrides applied, not yet validated."""
    path = Path(path)
    try:
        data = tomllib.loads(read_text(path, MAX_CASE_BYTES))
    except FileTooLarge as exc:
        raise CaseError(str(exc)) from None
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


@dataclass
class Built:
    """What a case turns into: the finalized model (model.system.System), the path-following
    control, Newton options, monitors, and the model as built (`builder`, model.model.Model:
    for a variant of it, e.g. without its contact pairs)."""

    case: Case
    model: System
    control: LoadControl | DisplacementControl | ArcLengthControl
    options: NewtonOptions
    monitors: list[Monitor]
    builder: Model


def _loaded(case: Case) -> bool:
    """Whether something loads the case: a value of a [[pressure]], [[point_load]] or [[fix]],
    a moving mould, a loaded cavity, heat flowing in or out, the body's weight."""
    moving = any(c.motion.ur or c.motion.uz for c in case.contact)
    gas = any(c.control != "pressure" or c.pressure for c in case.cavity)
    loads: list[PressureSpec | PointLoadSpec | FixSpec] = [*case.pressure, *case.point_load, *case.fix]
    heated = case.thermal is not None and bool(case.convection or any(c.conductance for c in case.contact))
    weight = case.gravity is not None and case.gravity.g != 0.0
    return any(item.value for item in loads) or moving or gas or heated or weight


def _loads(case: Case, model: Model, mesh) -> dict:
    """Give the model the supports, loads and cavities of the case; the cavities by name.
    The cavity module is imported where the case has one."""
    prescribe_fixes(model, mesh, case.fix)
    apply_loads(model, mesh, case.pressure, case.point_load)
    if not case.cavity:
        return {}
    from .cavity import build_cavities

    return build_cavities(model, mesh, case.cavity)


def _moulds(case: Case, model: Model, mesh, base: Path) -> list:
    """Give the model the moulds, heat conduction and weight of the case (after its initial
    temperature: the conduction starts from it); the contact pairs.  The modules of the tables
    the case lacks are not imported."""
    pairs = []
    if case.contact:
        from .contact import contact_pair

        pairs = [contact_pair(mesh, model, c, base, f"contact[{i}]") for i, c in enumerate(case.contact)]
        for pair in pairs:
            model.contact(pair)
    if case.thermal is not None or case.convection or any(c.conductance is not None for c in case.contact):
        from .thermal import build_conduction  # also to refuse a film or a conductance without [thermal]

        build_conduction(model, mesh, case.thermal, case.convection, case.contact, case.material.density)
    if case.gravity is not None:
        from .gravity import build_gravity

        build_gravity(model, mesh, case.gravity, case.material.density)
    return pairs


def build(case: Case, base: str | Path = ".") -> Built:
    """Turn a validated case into a finalized model; errors name the key at fault."""
    base = Path(base)
    try:
        mesh = build_mesh(case.mesh, base)
    except MeshError as exc:
        raise CaseError(f"mesh: {exc}") from None
    sectors = case.output.revolved
    if sectors and mesh.n_nodes * sectors > MAX_REVOLVED_POINTS:
        raise CaseError(
            f"output.revolved: {sectors} sectors of a mesh of {mesh.n_nodes:,} nodes make a 3D copy of "
            f"{mesh.n_nodes * sectors:,} points (at most {MAX_REVOLVED_POINTS:,}): use fewer sectors"
        )
    heat = case.temperature
    try:
        material = case.material.build(None if heat is None else heat.representative())
    except ValueError as exc:
        raise CaseError(case.material.error(exc)) from None
    try:
        model = Model(mesh, material, formulation=case.mesh.formulation, sfr_edges=case.mesh.sfr_edges)
    except MeshError as exc:
        raise CaseError(f"mesh: {exc}") from None
    crossing = boundary_crossing(mesh.points, mesh.boundary_edges)
    if crossing is not None:
        p = mesh.points[mesh.boundary_edges[crossing[0], 0]]
        raise CaseError(
            f"mesh: the boundary crosses itself near r, z = {p[0]:.6g}, {p[1]:.6g} "
            f"(a profile that crosses itself, or overlapping elements)"
        )
    try:
        cavities = _loads(case, model, mesh)
        if case.mesh.kind == "rectangle":  # the wall is normal to the faces that carry the pressure
            loaded = model.pressures + getattr(model, "cavities", [])
            mesh.set_wall(case.mesh.wall or default_wall(mesh.points, [p.nodes for p in loaded]))
        if heat is not None:  # after the wall: a table along s follows it
            from .temperature import give_temperature

            give_temperature(model, mesh, case)
        pairs = _moulds(case, model, mesh, base)
        control = build_control(model, mesh, case.solver)
        if not _loaded(case):
            raise CaseError(
                "pressure: nothing loads the model: every [[pressure]], [[point_load]] and [[fix]] "
                "value is zero (or absent), no [[contact]] surface moves and no [[cavity]] is loaded"
            )
    except SelectorError as exc:
        raise CaseError(str(exc)) from None
    held_uz = [d // model.dpn for d in model.fixed if d % model.dpn == 1]
    touching = np.concatenate([p.nodes for p in pairs]) if pairs else np.zeros(0, np.int64)
    free = free_to_slide(mesh.n_nodes, mesh.cells, np.array(held_uz, np.int64), touching)
    if free:
        raise CaseError(
            f"fix: a mechanism: {len(free)} bod{'y' if len(free) == 1 else 'ies'} of the mesh can "
            "move rigidly along z (no [[fix]] holds uz on it and no [[contact]] touches it)"
        )
    try:
        system = model.finalize()
    except ValueError as exc:  # a tied fibre rotation prescribed twice
        raise CaseError(f"fix: {exc}") from None
    monitors: list[Monitor] = []
    if case.monitor:
        from .monitor import build_monitors

        try:
            monitors = build_monitors(system, mesh, case.monitor, cavities, case.mesh.element)
        except SelectorError as exc:
            raise CaseError(str(exc)) from None
    s = case.solver
    options = NewtonOptions(
        tolerance=s.tolerance, max_iterations=s.max_iterations, min_step=s.min_step, growth=s.growth
    )
    return Built(case, system, control, options, monitors, model)
