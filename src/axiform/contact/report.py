"""The per-node report of a contact pair's committed state (ContactPair.report): positions,
gaps, pressures, status and the totals that contact.csv, the monitors and summary.json read."""

from __future__ import annotations

import numpy as np

from .state import ContactState


def pair_report(nodes: np.ndarray, area0: np.ndarray, state: ContactState) -> dict:
    """Per slave node (nodes (n,), reference ring areas area0 (n,)) of the committed `state`'s
    evaluation: gap, contact pressure (normal traction per unit current area), status,
    force, areas, time of first contact; and the totals (force_r, force_z with the mid-point
    guards' forces, the contact area of the reference configuration, the largest
    penetration).  Nothing in contact before the first step (or after a restart, until the
    next step)."""
    if state.seen is None:
        return untouched_report(nodes, area0, state)
    seen = state.seen
    proj, f, status, guard = seen.proj, seen.f, seen.status, seen.guard_force
    in_contact = status > 0
    gap = np.where(proj.active, proj.g, np.nan)
    return {
        "node": nodes,
        "pressure": np.where(in_contact, np.einsum("ij,ij->i", seen.traction, proj.n), 0.0),
        "gap": gap,
        "status": status,
        "force": f,
        "area": area0,
        "current_area": seen.a,
        "first_contact": state.first_contact,
        "force_r": float(f[:, 0].sum() + guard[:, 0].sum()),
        "force_z": float(f[:, 1].sum() + guard[:, 1].sum()),
        "contact_area": float(area0[in_contact].sum()),
        "penetration": float(
            max(0.0, -np.nanmin(np.where(in_contact, gap, np.nan))) if (in_contact & proj.active).any() else 0.0
        ),
    }


def untouched_report(nodes: np.ndarray, area0: np.ndarray, state: ContactState) -> dict:
    """The report of a pair whose state holds no evaluation: no force, no contact."""
    n = len(nodes)
    return {
        "node": nodes,
        "pressure": np.zeros(n),
        "gap": np.full(n, np.nan),
        "status": np.zeros(n, np.int8),
        "force": np.zeros((n, 2)),
        "area": area0,
        "current_area": area0,
        "first_contact": state.first_contact,
        "force_r": 0.0,
        "force_z": 0.0,
        "contact_area": 0.0,
        "penetration": 0.0,
    }
