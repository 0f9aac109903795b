"""What the numbers of a results folder are: the case's units, the physical quantity that
the load factor lambda scales, and the quantity of each monitor.  The results writer puts
them in summary.json (`units`, `load`, `monitor_quantities`), so that `axiform plot DIR`
labels every axis from the folder alone.

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

from typing import Any

import numpy as np

QUANTITY_UNIT = {
    "pressure": "pressure",
    "stress": "pressure",
    "force": "force",
    "displacement": "length",
    "length": "length",
    "time": "time",
    "temperature": "temperature",
}  # quantity -> key of [units]


def case_labels(case: Any) -> dict[str, Any]:
    """units, load, monitor_quantities, applied, process and real_time of a validated case
    (axiform.case.schema.Case)."""
    applied = applied_quantities(case)
    return {
        "units": {k: v for k, v in case.units.model_dump().items() if v},
        "load": loaded_quantity(case),
        "monitor_quantities": {m.name: monitor_quantity(m) for m in case.monitor},
        "applied": applied,
        "process": is_process(applied, getattr(case, "cavity", [])),
        "real_time": time_is_real(case),
    }


def time_is_real(case: Any) -> bool:
    """Whether the load factor of a validated case is a physical time (its result depends on
    how fast the loads come): a material with a Prony series (`[material] viscoelastic`), or
    heat conduction (`[thermal]`)."""
    return (
        getattr(getattr(case, "material", None), "viscoelastic", None) is not None
        or getattr(case, "thermal", None) is not None
    )


def monitor_quantity(m: Any) -> str:
    """ "displacement", "rotation", "force", "area", "pressure", "volume" or "temperature" of a
    monitor spec."""
    if getattr(m, "quantity", None) == "temperature":
        return "temperature"
    cavity_quantity = getattr(m, "cavity", None) is not None and m.quantity
    if cavity_quantity:
        return cavity_quantity
    if m.contact is not None:
        return {"force-r": "force", "force-z": "force", "area": "area"}.get(m.quantity, "displacement")
    if m.reaction is not None:
        return "force"
    return "rotation" if m.dof == "rot" else "displacement"


def _curve(spec: Any) -> list | None:
    curve = getattr(spec, "curve", None)
    return None if curve is None else [list(map(float, knot)) for knot in curve]


def _scaled(quantity: str, value: float, name: str, curve: list | None) -> dict[str, Any]:
    out = {"quantity": quantity, "value": float(value), "name": name}
    if curve is not None:
        out["curve"] = curve
    return out


def loaded_quantity(case: Any) -> dict[str, Any] | None:
    """The physical quantity lambda scales, in this order: a cavity pressure monitor, a
    cavity under pressure control, the pressures (the largest, named by its table when they
    differ), the point loads, the prescribed displacements and mould motions; None when there
    is none."""
    for m in case.monitor:
        if getattr(m, "cavity", None) is not None and m.quantity == "pressure":
            return {"quantity": "pressure", "monitor": m.name, "name": f"{m.cavity} pressure"}
    for c in getattr(case, "cavity", []):
        if c.control == "pressure" and c.pressure:
            return _scaled("pressure", c.pressure, f"{c.name} pressure", _curve(c))
    for kind, specs in (("pressure", case.pressure), ("force", case.point_load)):
        if specs:
            k = int(np.argmax([abs(p.value) for p in specs]))
            same = all(p.value == specs[k].value and _curve(p) == _curve(specs[k]) for p in specs)
            name = kind if same else f"{kind}[{k}]"
            return _scaled(kind, specs[k].value, name, _curve(specs[k]))
    for i, f in enumerate(case.fix):
        if f.value:
            return _scaled("displacement", f.value, f"fix[{i}] {', '.join(f.dofs)}", _curve(f))
    for i, c in enumerate(case.contact):
        ur, uz = c.motion.ur, c.motion.uz
        if ur or uz:
            dof = "uz" if abs(uz) >= abs(ur) else "ur"
            piece = _piece(c, i)
            return _scaled("displacement", uz if dof == "uz" else ur, f"{piece} displacement {dof}", _curve(c.motion))
    return None


def _piece(contact: Any, i: int) -> str:
    layer = getattr(contact.surface, "layer", None)
    return contact.name or (layer.lower() if layer else f"mould {i}")


def applied_quantities(case: Any) -> list[dict[str, Any]]:
    """Every quantity the case applies, as loaded_quantity says one (the same pressures or
    point loads on the same curve once): cavities under pressure, volume or gas control (the
    gas content; its pressure is its monitor's), pressures, point loads, prescribed
    displacements and mould motions."""
    out: list[dict[str, Any]] = []
    for c in getattr(case, "cavity", []):
        if c.control == "pressure" and c.pressure:
            out.append(_scaled("pressure", c.pressure, f"{c.name} pressure", _curve(c)))
        elif c.control == "volume":
            out.append({**_scaled("volume", c.volume, f"{c.name} volume", _curve(c)), "cavity": c.name})
        elif c.control == "gas":
            out.append(
                {
                    **_scaled("content", c.content, f"{c.name} gas content p·V", _curve(c)),
                    "cavity": c.name,
                    "ambient": float(c.ambient),
                }
            )
    for kind, specs in (("pressure", case.pressure), ("force", case.point_load)):
        seen = []
        for k, p in enumerate(specs):
            if p.value and (p.value, _curve(p)) not in seen:
                seen.append((p.value, _curve(p)))
                name = kind if len({(q.value, str(_curve(q))) for q in specs}) == 1 else f"{kind}[{k}]"
                out.append(_scaled(kind, p.value, name, _curve(p)))
    for i, f in enumerate(case.fix):
        if f.value:
            out.append(_scaled("displacement", f.value, f"fix[{i}] {', '.join(f.dofs)}", _curve(f)))
    for i, c in enumerate(case.contact):
        for dof in ("ur", "uz"):
            value = getattr(c.motion, dof)
            if value:
                out.append(_scaled("displacement", value, f"{_piece(c, i)} displacement {dof}", _curve(c.motion)))
    return out


def is_process(applied: list[dict[str, Any]], cavities: Any = ()) -> bool:
    """A multi-stage process: a curve with more than two knots, or loads on different curves
    (a gas cavity's curve counts too)."""
    curves = [a.get("curve") for a in applied] + [_curve(c) for c in cavities if c.control == "gas"]
    return len({str(c) for c in curves}) > 1 or any(len(c or ()) > 2 for c in curves)


def load_values(load: dict[str, Any], lam: np.ndarray, start: float = 0.0) -> np.ndarray:
    """The loaded quantity v f(lambda) at the load factors lam (a value-scaled load); with
    `start` (a cavity's initial volume V0), start + f(lambda) (v - start)."""
    lam = np.asarray(lam, float)
    curve = load.get("curve")
    if curve is None:
        f = lam
    else:
        t, fk = np.asarray(curve, float).T
        f = np.interp(lam, t, fk)
    return start + f * (load["value"] - start)


def unit_of(quantity: str, units: dict[str, str]) -> str:
    """The unit of a quantity from the case's [units] ("" when not given): area and volume
    are length squared and cubed, a gas content pressure times volume, rotations are in rad."""
    length = units.get("length")
    if quantity == "content":
        return f"{units['pressure']}·{length}³" if length and units.get("pressure") else ""
    if quantity == "area":
        return f"{length}²" if length else ""
    if quantity == "volume":
        return f"{length}³" if length else ""
    if quantity == "rotation":
        return "rad"
    return units.get(QUANTITY_UNIT.get(quantity, ""), "")


def with_unit(label: str, quantity: str, units: dict[str, str]) -> str:
    """'label (unit)', or the label alone when the unit is not known."""
    unit = unit_of(quantity, units)
    return f"{label} ({unit})" if unit else label


def short(value: float) -> str:
    """A number rounded for a title: three significant digits (172, 33.4, 0.0276), an
    exponent only below 1e-3 or from 1e5 on."""
    a = float(f"{abs(value):.3g}")
    if a == 0:
        return "0"
    if a < 1e-3 or a >= 1e5:
        return f"{value:.2e}"
    return f"{value:.{max(0, 2 - int(np.floor(np.log10(a))))}f}"
