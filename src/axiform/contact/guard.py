"""The mid-point guards of the straight slave edges of a pair (ContactPair.guard): a
frictionless penalty on the mid-point of each straight edge that acts only where the
mid-point lies more than its allowance behind the surface, so that a convex tool does not
cut through the wall between two nodes.  Arrays over the guarded edges (m,)."""

from __future__ import annotations

import numpy as np

from .law import normal_law, outer


def guard_forces(
    proj,
    allowance: np.ndarray,
    kn: np.ndarray,
    weight: np.ndarray,
    d: float,
    velocity: np.ndarray,
    arm: np.ndarray,
    dpn: int,
) -> tuple[np.ndarray | None, np.ndarray | None, np.ndarray | None, np.ndarray]:
    """The guards at the mid-points' projection `proj` (surfaces.Projection, m rows): the
    rounded normal law (penalty kn (m,), band d) at the mid-point's gap plus its allowance
    (m,), over the weight (m,) (the mid-point's share of the edge's ring area).  The
    mid-point is x_m = (x_a + x_b) / 2, and for SFR (dpn = 3) also + (theta_a - theta_b) arm,
    arm (m, 2) = (-dZ, dR) / 4 with (dR, dZ) = X_b - X_a.

    Returns per edge over the edge's dofs (node by node, 2 dpn) the force on the body F
    (m, 2 dpn), its derivative K = dF/du (m, 2 dpn, 2 dpn), the rate K_x velocity (m, 2 dpn)
    of a surface moving with velocity (2,), and the force on each mid-point (m, 2); F, K and
    the rate are None where no guard acts."""
    m = len(allowance)
    g = proj.g + allowance
    if not np.count_nonzero(proj.active & (g < 0.0)):  # no mid-point behind its allowance: no force
        return None, None, None, np.zeros((m, 2))
    fn, dfn = normal_law(g, proj.active, kn, d)
    force = (weight * fn)[:, None] * proj.n  # on the mid-point (m, 2)
    Kx = (weight * dfn)[:, None, None] * outer(proj.n, proj.n)
    Kx += (weight * fn * proj.kappa)[:, None, None] * outer(proj.t, proj.t)
    Kv = Kx @ velocity
    if dpn == 2:  # P = [I I] / 2: the products are copies of force, Kx and Kx v
        half, quarter = 0.5 * force, 0.25 * Kx
        return (
            np.concatenate((half, half), axis=1),
            np.broadcast_to(quarter[:, None, :, None, :], (m, 2, 2, 2, 2)).reshape(m, 4, 4),
            np.concatenate((0.5 * Kv,) * 2, axis=1),
            force,
        )
    dx = np.zeros((m, 2, 2, dpn))  # d x_m / d (node, dof)
    dx[:, 0, :, 0] = dx[:, 1, :, 1] = 0.5
    dx[:, :, 0, 2], dx[:, :, 1, 2] = arm, -arm
    P = dx.reshape(m, 2, 2 * dpn)
    PT = P.transpose(0, 2, 1)  # (m, 2 dpn, 2): stacked matrix products, not einsums on tiny operands
    return (PT @ force[..., None])[..., 0], PT @ (Kx @ P), (PT @ Kv[..., None])[..., 0], force
