"""What the numbers of a case's results are: its units, the physical quantity that the load
factor lambda scales, and the quantity of each monitor.  The results writer puts them in
summary.json (`units`, `load`, `monitor_quantities`), so that `axiform plot DIR` labels every
axis from the folder alone (post.labels reads them back).

`load` is None (the axis is the load factor) or a dict: {"quantity": "pressure" | "force" |
"displacement", "value": v, "name": label, "curve": [[t, f], ...]} (the loaded quantity is
v f(lambda), f(lambda) = lambda without a curve), or {"quantity": "pressure", "monitor":
column} when a cavity pressure monitor of history.csv carries it.

`applied` lists every applied quantity of the case the same way (each pressure, point load,
prescribed displacement, mould motion and cavity target: a cavity under volume control as
{"quantity": "volume", "cavity": name, "value": V, ...}, its volume V0 + f(t) (V - V0); a gas
cavity as {"quantity": "content", "cavity": name, "value": C, "ambient": p0, ...}, its gas
content p_abs V = p0 V0 + f(t) (C - p0 V0));
`process` is true for a multi-stage process (a curve with more than two knots, or loads on
different curves): its load curve panels are drawn against the process time t;
`real_time` is true where the load factor is a physical time (time_is_real: a law with
memory): the pictures and the progress line then say t with the unit of [units] time.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import numpy as np

from .base import CurveMixin

if TYPE_CHECKING:
    from .cavity import CavitySpec
    from .contact import ContactSpec
    from .monitor import MonitorSpec
    from .tables import Case


def case_labels(case: Case) -> dict[str, Any]:
    """units, load, monitor_quantities, applied, process and real_time of a validated case."""
    applied = applied_quantities(case)
    return {
        "units": {k: v for k, v in case.units.model_dump().items() if v},
        "load": loaded_quantity(case),
        "monitor_quantities": {m.name: monitor_quantity(m) for m in case.monitor},
        "applied": applied,
        "process": is_process(applied, case.cavity),
        "real_time": time_is_real(case),
    }


def time_is_real(case: Case) -> bool:
    """Whether the load factor of a validated case is a physical time (its result depends on
    how fast the loads come): a material with memory (`[material] viscoelastic`, a network), or
    heat conduction (`[thermal]`)."""
    return case.material.memory or case.thermal is not None


def monitor_quantity(m: MonitorSpec) -> str:
    """ "displacement", "rotation", "force", "area", "pressure", "volume" or "temperature" of a
    monitor spec."""
    if m.quantity == "temperature":
        return "temperature"
    if m.cavity is not None and m.quantity:
        return m.quantity
    if m.contact is not None:
        return {"force-r": "force", "force-z": "force", "area": "area"}.get(m.quantity or "", "displacement")
    if m.reaction is not None:
        return "force"
    return "rotation" if m.dof == "rot" else "displacement"


def _curve(spec: CurveMixin) -> list | None:
    """The load curve of a table as lists of floats, None without one."""
    return None if spec.curve is None else [list(map(float, knot)) for knot in spec.curve]


def _scaled(quantity: str, value: float, name: str, curve: list | None) -> dict[str, Any]:
    out = {"quantity": quantity, "value": float(value), "name": name}
    if curve is not None:
        out["curve"] = curve
    return out


def loaded_quantity(case: Case) -> dict[str, Any] | None:
    """The physical quantity lambda scales, in this order: a cavity pressure monitor, a
    cavity under pressure control, the pressures (the largest, named by its table when they
    differ), the point loads, the prescribed displacements and mould motions; None when there
    is none."""
    for m in case.monitor:
        if m.cavity is not None and m.quantity == "pressure":
            return {"quantity": "pressure", "monitor": m.name, "name": f"{m.cavity} pressure"}
    for c in case.cavity:
        if c.control == "pressure" and c.pressure:
            return _scaled("pressure", c.pressure, f"{c.name} pressure", _curve(c))
    loads: tuple[tuple[str, list[Any]], ...] = (("pressure", case.pressure), ("force", case.point_load))
    for kind, specs in loads:
        if specs:
            k = int(np.argmax([abs(p.value) for p in specs]))
            same = all(p.value == specs[k].value and _curve(p) == _curve(specs[k]) for p in specs)
            name = kind if same else f"{kind}[{k}]"
            return _scaled(kind, specs[k].value, name, _curve(specs[k]))
    for i, f in enumerate(case.fix):
        if f.value:
            return _scaled("displacement", f.value, f"fix[{i}] {', '.join(f.dofs)}", _curve(f))
    for i, contact in enumerate(case.contact):
        ur, uz = contact.motion.ur, contact.motion.uz
        if ur or uz:
            dof = "uz" if abs(uz) >= abs(ur) else "ur"
            piece = _piece(contact, i)
            value = uz if dof == "uz" else ur
            return _scaled("displacement", value, f"{piece} displacement {dof}", _curve(contact.motion))
    return None


def _piece(contact: ContactSpec, i: int) -> str:
    """The name of contact table i: its own, its DXF layer in lower case, else "mould i"."""
    layer = contact.surface.layer
    return contact.name or (layer.lower() if layer else f"mould {i}")


def applied_quantities(case: Case) -> list[dict[str, Any]]:
    """Every quantity the case applies, as loaded_quantity says one (the same pressures or
    point loads on the same curve once): cavities under pressure, volume or gas control (the
    gas content; its pressure is its monitor's), pressures, point loads, prescribed
    displacements and mould motions."""
    out: list[dict[str, Any]] = []
    for c in case.cavity:
        if c.control == "pressure" and c.pressure:
            out.append(_scaled("pressure", c.pressure, f"{c.name} pressure", _curve(c)))
        elif c.control == "volume" and c.volume is not None:
            out.append({**_scaled("volume", c.volume, f"{c.name} volume", _curve(c)), "cavity": c.name})
        elif c.control == "gas" and c.content is not None and c.ambient is not None:
            out.append(
                {
                    **_scaled("content", c.content, f"{c.name} gas content p·V", _curve(c)),
                    "cavity": c.name,
                    "ambient": float(c.ambient),
                }
            )
    loads: tuple[tuple[str, list[Any]], ...] = (("pressure", case.pressure), ("force", case.point_load))
    for kind, specs in loads:
        seen = []
        for k, p in enumerate(specs):
            if p.value and (p.value, _curve(p)) not in seen:
                seen.append((p.value, _curve(p)))
                name = kind if len({(q.value, str(_curve(q))) for q in specs}) == 1 else f"{kind}[{k}]"
                out.append(_scaled(kind, p.value, name, _curve(p)))
    for i, f in enumerate(case.fix):
        if f.value:
            out.append(_scaled("displacement", f.value, f"fix[{i}] {', '.join(f.dofs)}", _curve(f)))
    for i, contact in enumerate(case.contact):
        for dof, value in (("ur", contact.motion.ur), ("uz", contact.motion.uz)):
            if value:
                piece = _piece(contact, i)
                out.append(_scaled("displacement", value, f"{piece} displacement {dof}", _curve(contact.motion)))
    return out


def is_process(applied: list[dict[str, Any]], cavities: list[CavitySpec]) -> bool:
    """A multi-stage process: a curve with more than two knots, or loads on different curves
    (a gas cavity's curve counts too)."""
    curves = [a.get("curve") for a in applied] + [_curve(c) for c in cavities if c.control == "gas"]
    return len({str(c) for c in curves}) > 1 or any(len(c or ()) > 2 for c in curves)
