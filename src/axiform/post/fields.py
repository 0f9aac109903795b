"""Nodal fields for output: displacement, fibre rotation, J, Cauchy and von Mises stress,
hydrostatic_pressure (-tr sigma / 3, volume-averaged over each element; not the applied
pressure), principal stretches, contact
pressure, time of first contact.

Quadrature-point values are averaged to the nodes (each element's mean, then the mean over
the elements around a node): enough for pictures, not for error estimates.

Meshes with fibres (rectangles, layered walls) also get the wall thickness, and contact
pairs that record contact times the time of first contact.
"""

from __future__ import annotations

import numpy as np

from ..materials import cauchy_stress
from .thickness import contact_times, nodal_thickness, pieces, thickness_table


def point_fields(model, u_full: np.ndarray, state=None) -> dict[str, np.ndarray]:
    """Nodal fields (n,) or (n, k) of the state u_full (all dofs) with the committed history
    `state` (model.state.ModelState; None: the initial one): displacement (ur, uz, 0),
    J, cauchy_stress (rr, zz, tt, rz), von_mises, principal_stretches (in-plane major, minor,
    hoop), hydrostatic_pressure (-tr sigma / 3); fibre_rotation (SFR); temperature (with one); thickness (meshes
    with fibres); contact_pressure and
    first_contact (the time a slave node first touched, -1 where never) with contact, and
    first_contact_K per piece K where several record it.

    Every field is of the converged mechanical state: the stresses at the temperature the
    state's mechanics ran at (ModelState.field_temperature; under heat conduction the
    temperature of the step's start, before its heat update), and `temperature` is that same
    field, so that the stresses and the temperature written beside them agree, as in a state
    restored from the step's checkpoint."""
    mesh = model.mesh
    dpn = model.dpn
    u = u_full.reshape(-1, dpn)
    solid = model.solid
    x = solid.gradient(u_full)
    T = (state or model.initial_state()).field_temperature  # the nodes' (n,) or None: the mechanics'
    # mixed: with the element pressure; a law with state: its stress at the committed state
    held = model.solid_state(state) if state is not None else {}
    held = {k: v for k, v in held.items() if k != "t"} or None
    P = solid.stress(x, temperature=None if T is None else solid.point_values(T), state=held)
    J = x[..., 4] * (x[..., 0] * x[..., 3] - x[..., 1] * x[..., 2])
    sig = cauchy_stress(x, P)  # (e, q, 4): rr, zz, tt, rz
    s_rr, s_zz, s_tt, s_rz = (sig[..., i] for i in range(4))
    # pressure p = -tr(sigma)/3, positive in compression, averaged over the current volume
    dv = J * solid.dV
    pressure = -((s_rr + s_zz + s_tt) * dv).sum(1) / (3.0 * dv.sum(1))
    mises = np.sqrt(0.5 * ((s_rr - s_zz) ** 2 + (s_zz - s_tt) ** 2 + (s_tt - s_rr) ** 2) + 3 * s_rz**2)
    # principal stretches: eigenvalues of the meridian block of C = F^T F, and the hoop stretch
    a, b, c, d = x[..., 0], x[..., 1], x[..., 2], x[..., 3]
    C11, C22, C12 = a * a + c * c, b * b + d * d, a * b + c * d
    mean, dev = 0.5 * (C11 + C22), np.sqrt(0.25 * (C11 - C22) ** 2 + C12**2)
    l1, l2 = np.sqrt(mean + dev), np.sqrt(np.maximum(mean - dev, 0.0))
    stretches = np.stack([l1, l2, x[..., 4]], axis=-1)
    cell_values = np.column_stack([J.mean(1), sig.mean(1), mises.mean(1), stretches.mean(1), pressure])  # (e, 10)
    count = np.bincount(mesh.cells.ravel(), minlength=mesh.n_nodes)
    nodal = np.zeros((mesh.n_nodes, cell_values.shape[1]))
    for k in range(mesh.cells.shape[1]):
        np.add.at(nodal, mesh.cells[:, k], cell_values)
    nodal /= np.maximum(count, 1)[:, None]
    out = {
        "displacement": np.column_stack([u[:, 0], u[:, 1], np.zeros(len(u))]),
        "J": nodal[:, 0],
        "cauchy_stress": nodal[:, 1:5],  # rr, zz, tt, rz
        "von_mises": nodal[:, 5],
        "principal_stretches": nodal[:, 6:9],  # in-plane major, minor, hoop
        "hydrostatic_pressure": nodal[:, 9],
    }
    if dpn == 3:
        out["fibre_rotation"] = u[:, 2].copy()
    if T is not None:
        out["temperature"] = T.copy()
    table = thickness_table(mesh, u[:, :2])
    if table is not None:
        out["thickness"] = nodal_thickness(mesh, table)
    if model.contacts:
        history = model.contact_states(state or model.initial_state())
        pressure = np.zeros(mesh.n_nodes)
        for pair, held in zip(model.contacts, history, strict=False):
            rep = pair.report(held)
            pressure[rep["node"]] += rep["pressure"]
        out["contact_pressure"] = pressure
        when = contact_times(mesh, history)
        if when is not None:
            out["first_contact"] = np.nan_to_num(when, nan=-1.0)
        for k, pair in pieces(history):
            piece = contact_times(mesh, [pair])
            assert piece is not None, "pieces() gives the pairs that record contact times"
            out[f"first_contact_{k}"] = np.nan_to_num(piece, nan=-1.0)
    return out


def with_components(data: dict[str, np.ndarray]) -> dict[str, np.ndarray]:
    """The point data for a VTU file: the fields, hydrostatic_pressure under the name
    `pressure` too (the name readers of the VTU files rely on), and the Cauchy stress's
    components besides as the scalars cauchy_stress_rr, _zz, _tt, _rz (meshio writes no
    ComponentName attributes: ParaView would call them 0..3)."""
    if "hydrostatic_pressure" in data:
        data = data | {"pressure": data["hydrostatic_pressure"]}
    if "cauchy_stress" not in data:
        return data
    sig = data["cauchy_stress"]
    return data | {
        f"cauchy_stress_{c}": np.ascontiguousarray(sig[:, k]) for k, c in enumerate(("rr", "zz", "tt", "rz"))
    }
