"""Pre-run warnings of a built case: what is valid but probably not what was
meant, found without solving.  Each warning is one line that begins with the table and key at
fault.

- a curve (of a fix, pressure, point load, cavity, the weight, a mould's motion or temperature,
  a film's ambient, the prescribed change of temperature) that still changes after
  [solver] target: the run ends at target, the rest of the process is cut off;
- slave nodes inside a mould at t = 0 (deeper than the contact smoothing);
- a mould that faces away from its slaves (a polyline walked the wrong way, a circle with the
  wrong `inside`): the surface's normal at the slaves' projections points the way the body's
  own outward normal does, not against it, the slaves behind it; or slaves on the face of
  the body away from the mould (the same normals, the slaves in front of it: the body would
  pass through the mould);
- a load (the weight too) that inverts elements within one nominal step, in one linear
  solve of the reference tangent (no contact) for the largest increment its curve makes
  over one nominal step (INVERTING_FRACTION of it), and for a force whose step also asks
  the wall's mid-surface MEMBRANE_MARGIN times the tension a sheet of its thickness carries
  (case.membrane: a thin wall's linear bending overestimates its first step as much as a
  unit's factor): a value typed in other units (a pressure in Pa in an mm / MPa case, a
  density in kg/m^3 in a t/mm^3 one); under displacement control (the load factor an
  unknown), the driven dof's step target / steps instead.  Not for cavities under volume or
  gas control;
- the units' plausibility (case.plausible): tables of T out of reach of every temperature
  of the case, a modulus in Pa in an MPa case.

`preflight(built)` runs them all; nothing here writes or prints.
"""

from __future__ import annotations

import dataclasses
import functools
from collections.abc import Callable

import numpy as np

from ..fem.curves import Curve
from ..fem.elements import gradient_operator
from ..fem.selectors import select_nodes
from ..solve.linsolve import SingularTangentError, factorize
from ..solve.solver import DisplacementControl
from . import membrane
from .plausible import modulus_units, tables_out_of_reach
from .schema import Built

# a load is flagged where this fraction of its largest step would already invert elements in
# the linear estimate: a margin for walls whose linear bending overestimates the first step
# several times over (the cup's vacuum: gradients up to 9 in a linear step that the membrane
# carries), while a value in other units is off by 1e3 to 1e6
INVERTING_FRACTION = 0.1
# ... and where its largest step asks the wall's mid-surface this many times the tension a
# sheet of its thickness carries (case.membrane): a sheet 10 wide pressed onto a mould at 0.6
# times its modulus asks 0.75 and 3 in 20 steps (0.2 and 0.05 thick), 15 and 60 in one; a
# pressure in kPa for MPa 74 (the parison's cavity), 211 (the cup), in Pa 7e4 and more
MEMBRANE_MARGIN = 50.0
# a mould faces away from its slaves where more than this fraction of the slave nodes that
# project onto it lie behind it with its normal pointing the way their body's outward normal does
WRONG_FACE_FRACTION = 0.5
# a slave node in front of a mould lies on the body's face away from it where the angle between
# the body's outward normal and the mould's is below 60 degrees: a node beside the segment it
# projects onto (the normals at right angles, the side of a tube over a mould's floor) does not
FACING = 0.5


def preflight(built: Built) -> list[str]:
    """Every pre-run warning of a built case (one line each), in the order of the checks.  A
    check that fails on an unforeseen case gives no warning rather than stopping the run it
    only advises (each check alone raises: the tests call them one by one)."""
    out = []
    for check in (
        curves_past_target,
        mould_checks,
        inverting_loads,
        idle_temperature,
        tables_out_of_reach,
        modulus_units,
    ):
        try:
            out += check(built)
        except Exception:  # noqa: BLE001 - advice only: never in the way of a valid case
            continue
    return out


# ---- (a) curves that run past the end of the run -------------------------------------------------
def _curves(built: Built):
    """(key path, knots) of every curve the case gives."""
    case = built.case
    for name in ("fix", "pressure", "point_load", "cavity"):
        for i, item in enumerate(getattr(case, name)):
            if item.curve is not None:
                yield f"{name}[{i}].curve", item.curve
    for i, c in enumerate(case.contact):
        if c.motion.curve is not None:
            yield f"contact[{i}].motion.curve", c.motion.curve
        if c.temperature_curve is not None:
            yield f"contact[{i}].temperature_curve", c.temperature_curve
    for i, film in enumerate(case.convection):
        if film.curve is not None:
            yield f"convection[{i}].curve", film.curve
    if case.gravity is not None and case.gravity.curve is not None:
        yield "gravity.curve", case.gravity.curve
    if case.temperature is not None and case.temperature.change is not None:
        yield "temperature.change", case.temperature.change


def _end_time(built: Built) -> float | None:
    """The process time the run ends at ([solver] target), None where it is not known before
    the run (displacement control: the load factor is an unknown)."""
    if isinstance(built.control, DisplacementControl):
        return None
    return float(built.control.target)


def curves_past_target(built: Built) -> list[str]:
    """Curves that still change after the run's end time: the process is cut short."""
    end = _end_time(built)
    if end is None:
        return []
    out = []
    for where, knots in _curves(built):
        curve = Curve(knots)
        assert curve.t is not None and curve.f is not None, "a curve built from knots has them"
        t_last = float(curve.t[-1])
        tol = 1e-9 * max(1.0, abs(end))
        if t_last <= end + tol:
            continue
        f_end = curve(end)
        later = curve.f[curve.t > end + tol]
        if np.all(np.abs(later - f_end) <= 1e-12 * max(1.0, np.abs(curve.f).max())):
            continue  # constant after the end: nothing is cut off
        target = "target" if built.case.solver.target is not None else "target (default 1)"
        out.append(
            f"{where}: the curve runs to t = {t_last:g}, but the run ends at [solver] {target} = "
            f"{end:g}: the process is cut short there (set [solver] target = {t_last:g}?)"
        )
    return out


# ---- (b), (c) moulds ----------------------------------------------------------------------------
def _mould_name(built: Built, i: int) -> str:
    pair = built.model.contacts[i]
    return f"contact[{i}]" + (f' ("{pair.name}")' if getattr(pair, "name", None) else "")


def body_normals(pair) -> np.ndarray:
    """The body's outward unit normal at each slave node of a contact pair (n, 2): the mean
    of the outward normals of its slave edges (membrane.outward_normals)."""
    return membrane.outward_normals(pair.X, pair.edges)


def mould_checks(built: Built) -> list[str]:
    """Moulds that face away from their slaves, and slave nodes inside a mould at t = 0."""
    model = built.model
    if not model.contacts:
        return []
    from ..contact.surfaces import Circle

    span = float(np.ptp(model.mesh.points, axis=0).max())
    out = []
    for i, pair in enumerate(model.contacts):
        spec = built.case.contact[i]
        x = pair.X - pair.surface.offset(0.0)  # the surface's own frame at t = 0
        # every projection, however deep: a mould walked the wrong way has its slaves behind it
        proj = pair.surface.local(x, x, depth=10.0 * span + 1.0, method=pair.search)
        on = proj.active & (proj.kind == 1)
        if not on.any():
            continue
        cosine = np.einsum("ij,ij->i", proj.n, body_normals(pair))
        alike = cosine > 0.0
        wrong = alike & (proj.g < pair.smoothing)  # behind it, and facing the way it faces
        away = (cosine > FACING) & ~wrong  # in front of it, on the body's face away from it (not beside it)
        where = _mould_name(built, i)
        if wrong[on].mean() > WRONG_FACE_FRACTION:
            if isinstance(pair.surface, Circle):
                assert spec.surface.circle is not None, "a Circle surface comes from a circle table"
                fix = f"inside = {str(not spec.surface.circle.inside).lower()}"
            else:
                fix = f"reverse = {str(not spec.surface.reverse).lower()}"
            out.append(
                f"{where}.surface: faces away from its slaves: {int(wrong[on].sum())} of the {int(on.sum())} "
                "slave nodes that project onto it lie behind it, its normal pointing the way the body's "
                f"outward normal does (walked the wrong way, or contact on the wrong face?): try {fix}"
            )
            continue
        if away[on].mean() > WRONG_FACE_FRACTION:
            out.append(
                f"{where}.slaves: on the face away from the mould: {int(away[on].sum())} of the {int(on.sum())} "
                "slave nodes that project onto it lie in front of it with the body's outward normal pointing "
                "the way the mould's does (the body between them and the mould): the body would pass through "
                "the mould unseen; select the face towards it"
            )
            continue
        inside = proj.active & ~alike & (proj.g < -pair.smoothing)
        if inside.any():
            k = int(np.argmin(np.where(inside, proj.g, np.inf)))
            r, z = pair.X[k]
            out.append(
                f"{where}.slaves: {int(inside.sum())} slave node(s) lie inside the mould at t = 0, up to "
                f"{-proj.g[k]:.3g} deep (at r, z = {r:.6g}, {z:.6g})"
            )
    return out


# ---- (d) loads that invert the first steps -------------------------------------------------------
def _step_increment(curve, t_end: float, steps: int) -> float:
    """The largest change of f over one nominal step t_end / steps of [0, t_end]."""
    t = np.linspace(0.0, t_end, steps + 1)
    f = np.array([curve(s) for s in t])
    return float(np.abs(np.diff(f)).max())


def _contact_free(built: Built):
    """The system of the model without its contact pairs (the reference tangent of the body
    and its loads): the built system itself where it has none (its evaluation keeps nothing),
    else finalized again from the model as built (model.model.Model) without them."""
    if not built.builder.contacts:
        return built.model
    return dataclasses.replace(built.builder, contacts=[]).finalize()


def _gradients(model, u_full: np.ndarray) -> tuple[float, float]:
    """The largest displacement gradient |H| and the smallest det(I + H) (the hoop stretch
    1 + u_r / R included) over the Gauss points of the mesh, for displacements u_full."""
    mesh = model.mesh
    G, _ = gradient_operator(mesh.element, mesh.points[mesh.cells])
    ue = u_full[model.solid.dofs]
    g = np.einsum("eqcn,en->eqc", G, ue)  # du_r/dR, du_r/dZ, du_z/dR, du_z/dZ, u_r/R
    det = ((1 + g[..., 0]) * (1 + g[..., 3]) - g[..., 1] * g[..., 2]) * (1 + g[..., 4])
    return float(np.abs(g).max()), float(det.min())


def _reference_tangent(built: Built):
    """The contact-free copy of the model, its evaluation at rest (u = 0, t = 0) and the
    factorization of its tangent; None where there is none (held by its moulds alone)."""
    try:
        body = _contact_free(built)
        ev = body.evaluate(np.zeros(body.n_free), 0.0)
        if not np.all(np.isfinite(ev.K.data)):
            return None
        return body, ev, factorize(ev.K)
    except (SingularTangentError, ValueError, np.linalg.LinAlgError):
        return None


def _inverts(body, du: np.ndarray, presc: np.ndarray) -> tuple[bool, float]:
    """Whether INVERTING_FRACTION of the step (du on the unknowns, presc on the prescribed
    equations) inverts an element, and the step's largest displacement gradient."""
    dm = body.dofmap
    if not (np.all(np.isfinite(du)) and np.all(np.isfinite(presc))):
        return False, 0.0
    h, det = _gradients(body, INVERTING_FRACTION * dm.expand(du[: dm.nf], presc))
    return det <= 0.0, h / INVERTING_FRACTION


def _driven_step(built: Built, reference) -> list[str]:
    """Displacement control: whether the driven dof's step target / steps inverts elements,
    the loads in proportion along the reference tangent.  The linear estimate alone: the
    step's size is given, not estimated."""
    body, ev, solve = reference
    control = built.control
    assert isinstance(control, DisplacementControl), "called for displacement control only"
    dm = body.dofmap
    eq = int(dm.eq[control.dof])
    v = solve(-ev.dr_dlam)  # the response to a unit load factor
    if eq >= dm.nf or not np.isfinite(v[eq]) or abs(v[eq]) <= 1e-300:
        return []
    lam = control.target / control.steps / v[eq]
    bad, h = _inverts(body, lam * v, lam * body.prescribed(0.0)[1])
    if not bad:
        return []
    unit = built.case.units.length
    return [
        f"solver.target: {control.target:g}{' ' + unit if unit else ''} in {control.steps} steps would invert "
        f"elements within one step (a linear estimate at the reference state: displacement gradients up to "
        f"{h:.2g}): is it in the units of the rest of the case?"
    ]


@dataclasses.dataclass
class _Load:
    """One load over its largest nominal step: where it is given (key path), its value and
    unit (or what stands for it), its full load vector (n_full,), the full prescribed
    displacements (a fix's; None for a force) and the membrane's answer to it (`membrane`:
    T / (mu t), case.membrane; None for a displacement, whose size is given)."""

    where: str
    value: float
    unit: str | None
    force: np.ndarray
    prescribed: np.ndarray | None = None
    membrane: Callable[[], float] | None = None


def _force_loads(built: Built, body, t_end: float, steps: int) -> list[_Load]:
    """The pressures, point loads, cavities under pressure control and the weight of a case,
    each over its largest nominal step, with the membrane's answer (lazily: only a load the
    linear estimate flags asks it)."""
    case, mesh, zero = built.case, body.mesh, np.zeros(body.n_full)
    mu = float(getattr(body.material, "shear_modulus", np.nan))
    units = case.units
    loads = []
    for i, (spec, p) in enumerate(zip(case.pressure, body.pressures, strict=False)):
        step = spec.value * _step_increment(p.curve, t_end, steps)
        if step:
            fe, _ = p.evaluate(zero, tangent=False)
            f = np.bincount(p.dofs.ravel(), fe.ravel(), body.n_full) / p.value * step
            ask = functools.partial(membrane.pressure_ratio, mesh, p.nodes, step, mu)
            loads.append(_Load(f"pressure[{i}].value", spec.value, units.pressure, f, membrane=ask))
    for i, load in enumerate(case.point_load):
        step = load.value * _step_increment(load.build_curve(), t_end, steps)
        if step:
            f = _point_load_vector(body, case, i) * step / load.value
            nodes = np.flatnonzero(f.reshape(-1, body.dpn).any(axis=1))
            ask = functools.partial(membrane.ring_ratio, mesh, nodes, step, mu)
            loads.append(_Load(f"point_load[{i}].value", load.value, units.force, f, membrane=ask))
    for i, (gas, cav) in enumerate(zip(case.cavity, body.cavities, strict=False)):
        if gas.control != "pressure":
            continue
        assert gas.pressure is not None, "a cavity under pressure control has its pressure"
        step = gas.pressure * _step_increment(cav.curve, t_end, steps)
        if step:
            _, ge, _ = cav.evaluate(zero, tangent=False)
            f = np.bincount(cav.dofs.ravel(), ge.ravel(), body.n_full) * step
            ask = functools.partial(membrane.pressure_ratio, mesh, cav.nodes, step, mu)
            loads.append(_Load(f"cavity[{i}].pressure", gas.pressure, units.pressure, f, membrane=ask))
    if case.gravity is not None:
        from ..model.gravity import GravityTerm  # only where the case has a weight

        for weight in (t for t in body.terms if isinstance(t, GravityTerm)):
            step = _step_increment(weight.curve, t_end, steps)
            if step:
                density = f"(material.density {case.material.density:g})"
                rho_g = (case.material.density or 0.0) * case.gravity.g * step  # a weight has its density
                ask = functools.partial(membrane.weight_ratio, mesh, rho_g, mu)
                loads.append(_Load("gravity.g", case.gravity.g, density, weight.force * step, membrane=ask))
    return loads


def _fix_loads(built: Built, body, t_end: float, steps: int) -> list[_Load]:
    """The prescribed displacements of a case, each over its largest nominal step (the load:
    the internal forces they make at the reference state, reversed)."""
    out = []
    for i, fix in enumerate(built.case.fix):
        if not fix.value:
            continue
        step = fix.value * _step_increment(fix.build_curve(), t_end, steps)
        if step:
            u_fix = np.zeros(body.n_full)
            u_fix[_fix_dofs(body, built.case, i)] = step
            unit = built.case.units.length
            out.append(_Load(f"fix[{i}].value", fix.value, unit, -_internal_rate(body, u_fix), u_fix))
    return out


def inverting_loads(built: Built) -> list[str]:
    """Loads that invert elements within one nominal step (under displacement control: the
    driven dof's step), where two estimates agree: the linear one (one solve of the reference
    tangent: INVERTING_FRACTION of the step inverts an element) and, for a force, the
    membrane's (case.membrane: the step asks the wall's mid-surface MEMBRANE_MARGIN times the
    tension a sheet of its thickness carries).  The linear estimate of a wall of span L and
    thickness t overestimates its first deflection by about (L / t)^2, as much as a unit's
    factor; the membrane's answer does not, and a value in other units still asks a thousand
    times what the wall carries.  A displacement (a fix's value, the driven dof) is given,
    not estimated: the linear estimate alone."""
    reference = _reference_tangent(built)
    if reference is None:
        return []  # held by its moulds alone: no reference tangent without them
    if isinstance(built.control, DisplacementControl):
        return _driven_step(built, reference)
    body, ev, solve = reference
    t_end, steps = float(built.control.target), int(built.control.steps)
    dm = body.dofmap
    nf, n_eq = dm.nf, body.n_free
    out = []
    for load in _force_loads(built, body, t_end, steps) + _fix_loads(built, body, t_end, steps):
        b = np.zeros(n_eq)
        b[:nf] = dm.gather(load.force)[:nf]
        presc = np.zeros(dm.np)
        if load.prescribed is not None:
            moved = np.flatnonzero(load.prescribed)
            presc[dm.eq[moved] - nf] = load.prescribed[moved]
        bad, h = _inverts(body, solve(b), presc)
        if not bad:
            continue
        tension = load.membrane() if load.membrane is not None else None
        if tension is not None and tension < MEMBRANE_MARGIN:  # NaN (no modulus): the linear estimate alone
            continue
        given = f"{load.value:g}" + (f" {load.unit}" if load.unit else "")
        known = tension is not None and np.isfinite(tension)
        said = f"; the membrane's: a tension {tension:.2g} times what its wall carries" if known else ""
        out.append(
            f"{load.where}: {given} would invert elements within one nominal step (a linear estimate at the "
            f"reference state: displacement gradients up to {h:.2g} in one step of {t_end / steps:g}"
            f"{said}): is it in the units of the rest of the case?"
        )
    return out


def _point_load_vector(model, case, i: int) -> np.ndarray:
    """The full force vector of [[point_load]] i at its full value."""
    spec = case.point_load[i]
    nodes = select_nodes(model.mesh, spec.at.model_dump(), f"point_load[{i}].at")
    f = np.zeros(model.n_full)
    f[model.dof(nodes, spec.dof)] = spec.value
    return f


def _fix_dofs(model, case, i: int) -> np.ndarray:
    """The full dofs [[fix]] i prescribes."""
    spec = case.fix[i]
    nodes = select_nodes(model.mesh, spec.at.model_dump(), f"fix[{i}].at")
    names = [n for n in spec.dofs if not (n == "rot" and model.dpn == 2)]
    return np.concatenate([model.dof(nodes, n) for n in names])


def _internal_rate(model, u_p: np.ndarray) -> np.ndarray:
    """K u_p (full vector): the internal forces of the displacements u_p at the reference
    state, linearised (central differences of the solid's internal forces)."""
    scale = float(np.abs(u_p).max())
    eps = 1e-6 * model.mesh.size() / scale

    def f_int(u):
        fe, _ = model.solid.evaluate(u, False, model.solid.buffers(False))
        return np.bincount(model.solid.dofs.ravel(), fe.ravel(), model.n_full)

    return (f_int(eps * u_p) - f_int(-eps * u_p)) / (2 * eps)


def idle_temperature(built: Built) -> list[str]:
    """A [temperature] that changes nothing: a shift without a Prony series (nothing
    relaxes), or a temperature with neither tables of T in the law, a shift, [thermal] nor a
    frozen network under a prescribed change."""
    case = built.case
    heat = case.temperature
    if heat is None:
        return []
    viscous = case.material.memory
    if heat.shift is not None and not viscous:
        return [
            "temperature.shift: the material has no Prony series ([material] viscoelastic) and no network: "
            "the shift of its relaxation times changes nothing"
        ]
    freezing = case.material.freeze is not None and heat.change is not None  # a frozen network born as it cools
    if heat.shift is None and not case.material.tables() and not freezing and case.thermal is None:
        return [
            "temperature: no constant of [material] is a table of T, there is no shift and no [thermal]: the "
            "temperature is written out but changes nothing"
        ]
    return []
