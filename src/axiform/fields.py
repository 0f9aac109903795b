"""Nodal fields for output: displacement, fibre rotation, J, Cauchy and von Mises stress,
principal stretches, contact pressure, time of first contact.

Quadrature-point values are averaged to the nodes (each element's mean, then the mean over
the elements around a node): enough for pictures, not for error estimates.
"""

from __future__ import annotations

import numpy as np

from .materials import cauchy_stress


def point_fields(model, u_full: np.ndarray) -> dict[str, np.ndarray]:
    mesh = model.mesh
    dpn = model.dpn
    u = u_full.reshape(-1, dpn)
    solid = model.solid
    x = solid.gradient(u_full)
    P = model.material.stress(x)
    J = x[..., 4] * (x[..., 0] * x[..., 3] - x[..., 1] * x[..., 2])
    sig = cauchy_stress(x, P)  # (e, q, 4): rr, zz, tt, rz
    s_rr, s_zz, s_tt, s_rz = (sig[..., i] for i in range(4))
    mises = np.sqrt(0.5 * ((s_rr - s_zz) ** 2 + (s_zz - s_tt) ** 2 + (s_tt - s_rr) ** 2) + 3 * s_rz**2)
    # principal stretches: eigenvalues of the meridian block of C = F^T F, and the hoop stretch
    a, b, c, d = x[..., 0], x[..., 1], x[..., 2], x[..., 3]
    C11, C22, C12 = a * a + c * c, b * b + d * d, a * b + c * d
    mean, dev = 0.5 * (C11 + C22), np.sqrt(0.25 * (C11 - C22) ** 2 + C12**2)
    l1, l2 = np.sqrt(mean + dev), np.sqrt(np.maximum(mean - dev, 0.0))
    stretches = np.stack([l1, l2, x[..., 4]], axis=-1)
    cell_values = np.column_stack([J.mean(1), sig.mean(1), mises.mean(1), stretches.mean(1)])  # (e, 9)
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
    }
    if dpn == 3:
        out["fibre_rotation"] = u[:, 2].copy()
    if model.contacts:
        pressure = np.zeros(mesh.n_nodes)
        for pair in model.contacts:
            if pair.last is not None:
                rep = pair.report()
                pressure[rep["node"]] += rep["pressure"]
        out["contact_pressure"] = pressure
        out["first_contact"] = first_contact(model)
    return out


def first_contact(model) -> np.ndarray:
    """Per node (n_nodes,): the time t (load factor) of the step in which it first touched a
    mould (the earliest over the contact pairs), -1 where it never did."""
    t = np.full(model.mesh.n_nodes, np.inf)
    for pair in model.contacts:
        np.fmin.at(t, pair.nodes, pair.first_contact)
    return np.where(np.isfinite(t), t, -1.0)
