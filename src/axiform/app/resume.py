"""What `axiform run --resume DIR` checks before it continues a run: the checkpoint of the
folder (`resume_state`), that it fits the model at hand (`check_fit`), and that the case
changes nothing of the physics the run has already been through (`check_frozen`).

A resumed run splices its steps onto those of the run it continues, so everything that made
those steps must be what makes the next ones: the tables of FROZEN_TABLES whole ([mesh],
[material], [temperature], [thermal], [[convection]]), every [[contact]] key but the
numerical ones of CONTACT_NUMERICS (its geometry, motion, friction and heat), and the loads
([[fix]], [[pressure]], [[point_load]], [[cavity]]) up to the resume time: each key of
theirs but `curve` unchanged, and their curve f(t) the same from t = 0 to the load factor
the checkpoint reached (a curve may change beyond it); [gravity] as those loads; and [units]
temperature (an Arrhenius shift's absolute temperature); the path the steps followed
(solver.control, and the dof displacement control drives: the checkpoint's progress is that
dof's).  A later solver.target, other solver numbers and more output are allowed.  The
checkpoint's meta holds these tables as the case had them (`frozen_meta`); a checkpoint
written before it (only the fingerprints of [mesh] and [material]) is checked on those two.
"""

from __future__ import annotations

import hashlib
import json
from pathlib import Path
from typing import Any

import numpy as np

from ..case.schema import CaseError, fingerprint
from ..fem.curves import Curve

# tables that cannot change at all; the first two are also kept as fingerprints (the meta of
# earlier checkpoints, which hold only these)
FROZEN_TABLES = ("mesh", "material", "temperature", "thermal", "convection")
FINGERPRINTED = ("mesh", "material")
# the [[contact]] keys a resumed run may change: how contact is enforced and searched, not what touches what
CONTACT_NUMERICS = ("name", "penalty", "tangential_penalty", "depth", "search", "stabilization")
# the arrays of tables whose loads are frozen up to the resume time: every key but the curve
LOADS = ("fix", "pressure", "point_load", "cavity")
# single load tables, frozen as those of LOADS are
SINGLE_LOADS = ("gravity",)


def _plain(value: Any) -> Any:
    """The tree as JSON has it (what a checkpoint's meta gives back)."""
    return json.loads(json.dumps(value, sort_keys=True, default=str))


def _physics(data: dict[str, Any]) -> dict[str, Any]:
    """The frozen tables, the [[contact]], the load tables, the temperature unit and the path
    (solver.control, solver.dof) of a case (as JSON has them)."""
    units = data.get("units")
    unit = units.get("temperature") if isinstance(units, dict) else None
    solver = data.get("solver")
    if not isinstance(solver, dict):
        solver = {}
    path = {"control": solver.get("control", "load"), "dof": solver.get("dof")}
    physics = {key: data.get(key) for key in (*FROZEN_TABLES, "contact", *LOADS, *SINGLE_LOADS)}
    return _plain(physics | {"units": {"temperature": unit}, "path": path})


def _named_files(data: dict[str, Any]) -> list[tuple[str, str]]:
    """(key path, file name) of the files the frozen tables read: the gmsh mesh, the moulds'
    outlines and drawings."""
    out = []
    mesh = data.get("mesh")
    if isinstance(mesh, dict) and isinstance(mesh.get("file"), str):
        out.append(("mesh.file", mesh["file"]))
    contacts = data.get("contact")
    for k, c in enumerate(contacts if isinstance(contacts, list) else []):
        surface = c.get("surface") if isinstance(c, dict) else None
        for key in ("file", "dxf"):
            if isinstance(surface, dict) and isinstance(surface.get(key), str):
                out.append((f"contact[{k}].surface.{key}", surface[key]))
    return out


def _file_digests(data: dict[str, Any], base: Path) -> dict[str, str]:
    """key path -> the SHA-256 of the file it names (relative names from the folder `base`,
    the case file's), "" where it cannot be read: the geometry the frozen tables stand for."""
    from ..io.text import read_bytes

    out = {}
    for key, name in _named_files(data):
        try:
            out[key] = hashlib.sha256(read_bytes(base / name)).hexdigest()
        except OSError:
            out[key] = ""
    return out


def frozen_meta(data: dict[str, Any], base: Path) -> dict[str, Any]:
    """What a checkpoint keeps of the case (its meta): the fingerprints of FINGERPRINTED and,
    under `physics`, the frozen tables, the [[contact]], the load tables and the temperature
    unit as the case has them, and the digests of the files they read (`base`: the case
    file's folder)."""
    physics = _physics(data) | {"files": _file_digests(data, base)}
    return {key: fingerprint(data.get(key, {})) for key in FINGERPRINTED} | {"physics": physics}


def _first_difference(a: Any, b: Any, where: str) -> str | None:
    """The key path of the first place where two trees differ, or None."""
    if isinstance(a, dict) and isinstance(b, dict):
        for key in sorted(set(a) | set(b)):
            found = _first_difference(a.get(key), b.get(key), f"{where}.{key}")
            if found:
                return found
        return None
    if isinstance(a, list) and isinstance(b, list) and len(a) == len(b):
        for i, (x, y) in enumerate(zip(a, b, strict=True)):
            found = _first_difference(x, y, f"{where}[{i}]")
            if found:
                return found
        return None
    return None if a == b else where


def _refuse(table: str, where: str, why: str = "differs from the run being resumed") -> CaseError:
    brackets = f"[[{table}]]" if table in ("convection", "contact", *LOADS) else f"[{table}]"
    return CaseError(
        f"{table}: {why} (at {where}): {brackets} cannot change on --resume, the steps already made "
        "would not be those of this case; start a new run instead"
    )


def _same_curve(old: list | None, new: list | None, until: float) -> bool:
    """Whether two load curves (knots, or None: f(t) = t) agree from t = 0 to `until`: both are
    piecewise linear, so they agree there when they agree at 0, `until` and every knot between."""
    knots = [k[0] for k in (old or []) + (new or []) if 0.0 < k[0] < until]
    f, g = Curve(old), Curve(new)
    return all(abs(f(t) - g(t)) <= 1e-12 * max(abs(f(t)), abs(g(t))) for t in (0.0, *knots, until))


def _check_entries(table: str, old: list, new: list, reached: float) -> None:
    """The [[table]] entries of a resumed case against those of its run (see the module docstring)."""
    if len(old) != len(new):
        raise _refuse(table, table, f"{len(new)} tables, the run being resumed had {len(old)}")
    for i, (a, b) in enumerate(zip(old, new, strict=True)):
        if table == "contact":
            a, b = ({k: v for k, v in x.items() if k not in CONTACT_NUMERICS} for x in (a, b))
            found = _first_difference(a, b, f"{table}[{i}]")
            if found:
                raise _refuse(table, found)
        else:
            _check_load(table, f"{table}[{i}]", a, b, reached)


def _check_load(table: str, where: str, old: dict, new: dict, reached: float) -> None:
    """A load table (at the key path `where`) of a resumed case against the run's: every key
    but the curve the same, the curve the same up to the load factor `reached`."""
    if not _same_curve(old.get("curve"), new.get("curve"), reached):
        raise _refuse(table, f"{where}.curve", f"the curve differs before the resume time {reached:g}")
    a, b = ({k: v for k, v in x.items() if k != "curve"} for x in (old, new))
    found = _first_difference(a, b, where)
    if found:
        raise _refuse(table, found)


def check_frozen(meta: dict[str, Any], data: dict[str, Any], reached: float, base: Path) -> None:
    """CaseError naming the table (and the key) where the case of a resumed run changes the
    physics of the run its checkpoint (meta) was made by, up to the load factor `reached`
    (`base`: the case file's folder, where its files are read from)."""
    physics = meta.get("physics")
    if not isinstance(physics, dict):  # a checkpoint of before the physics in its meta
        for key in FINGERPRINTED:
            if meta.get(key) != fingerprint(data.get(key, {})):
                raise _refuse(key, key)
        return
    new = _physics(data)
    found = _first_difference(physics.get("path"), new["path"], "solver") if "path" in physics else None
    if found:  # not in the meta of earlier checkpoints
        raise CaseError(
            f"{found}: differs from the run being resumed: the control of the path and the dof it drives "
            "cannot change on --resume (a later target, other step numbers and tolerances can); start a new "
            "run instead"
        )
    for key in (*FROZEN_TABLES, "units"):  # "units": not in the meta of earlier checkpoints
        found = _first_difference(physics.get(key), new.get(key), key) if key in physics else None
        if found:
            raise _refuse(key, found)
    for key in ("contact", *LOADS):
        _check_entries(key, physics.get(key) or [], new.get(key) or [], reached)
    for key in SINGLE_LOADS:
        if key not in physics:  # earlier checkpoints
            continue
        old_load, new_load = physics[key], new.get(key)
        if (old_load is None) != (new_load is None):
            raise _refuse(key, key, "added since the run being resumed" if old_load is None else "dropped")
        if isinstance(old_load, dict) and isinstance(new_load, dict):
            _check_load(key, key, old_load, new_load, reached)
    _check_files(physics.get("files"), _file_digests(data, base), dict(_named_files(data)))


def _check_files(old: Any, new: dict[str, str], names: dict[str, str]) -> None:
    """The files the frozen tables read, by their digests (`old` None: a checkpoint of before them)."""
    if not isinstance(old, dict):
        return
    for key, digest in new.items():
        if key in old and old[key] != digest:
            raise _refuse(
                key.split(".")[0].split("[")[0], key, f"the file {names[key]} changed since the run being resumed"
            )


def resume_state(folder: Path, data: dict, base: Path) -> dict:
    """The checkpoint of a results folder to resume, after checking that the case (its files
    read from the folder `base`) changes nothing frozen (check_frozen); CaseError (exit 2)
    otherwise."""
    from ..io.checkpoint import load as load_checkpoint

    try:
        there = folder.is_dir()
    except OSError as exc:  # a name longer than the file system allows
        raise CaseError(f"--resume: {folder}: {exc.strerror or exc}") from None
    if not there:
        raise CaseError(f"--resume: {folder} is not a results folder")
    try:
        state, meta = load_checkpoint(folder / "restart")
    except ValueError as exc:
        raise CaseError(f"--resume: {exc}") from None
    path = state.get("path")
    reached = path.get("lam", 0.0) if isinstance(path, dict) else 0.0
    check_frozen(meta, data, float(reached) if isinstance(reached, int | float) else 0.0, base)
    return state


def check_fit(state: dict, model, folder: Path) -> None:
    """CaseError (exit 2) naming the checkpoint file and its first item that does not fit the
    model at hand (another number of unknowns, of contact pairs, a number where a table
    belongs), before the solve would fail on it."""
    from ..io.checkpoint import FILE, check_like

    template = {
        "path": {"u_f": np.zeros(model.n_free)},
        "model": model.initial_state().to_dict(),
        "size": 0.0,
        "step": 0,
        "newton_iterations": 0,
    }
    try:
        check_like(state, template)
    except ValueError as exc:
        raise CaseError(f"--resume: {folder / 'restart' / FILE}: {exc}") from None
