"""The contact law of a pair per unit of its weighted area (ContactPair): the normal penalty
law (eqs. 40-41) rounded over a band of gaps, Coulomb friction with a tangential penalty and
a rounded stick/slip corner (eqs. 42-45), sticky ties, and the damping traction of the contact
stabilization.  Arrays over the slave nodes (n,), vectorized; nothing kept between calls.

Augmented Lagrange: the normal law carries the normal traction of the last converged step
(the multiplier of the history, ContactState.multiplier) and adds the penalty of the gap to
it: fn = law(g - lambda / kn), ~ lambda - kn g.  At the start of every step the multiplier
moves towards the last converged traction (Uzawa's update; all the way for a nominal step,
the step's fraction of the way for a cut one: ContactState.advanced), so that the penalty
carries only the change of traction over one step: the penetration left is that change over
kn, not the whole pressure over kn, and it shrinks again at the next step where the
pressure holds.

A sticky node's tie is a spring TIE times the normal penalty, anchored where it pulls as the
normal law pushed when the node froze (the force does not jump there): a linear spring, whose
stiffness costs Newton next to nothing, where a tie updated like the multiplier would move a
frozen wall at every step with no change of load (a path followed by arc length then turns
back).  A node frozen under a contact pressure p keeps its penetration of that step and adds
a tenth of the penalty's for the pressure after."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .state import ContactState

TIE = 10.0  # a sticky node's tie: this many times the normal penalty (see the module)


def outer(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Row-wise outer products (n, 2, 2) of a and b (n, 2)."""
    return a[:, :, None] * b[:, None, :]


def normal_law(g: np.ndarray, touching: np.ndarray, kn, d: float) -> tuple[np.ndarray, np.ndarray]:
    """The normal law (eqs. 40-41) rounded over -d < g < 0: the force fn (n,) (>= 0, along
    the normal) at gaps g (n,) where `touching` (and g < 0), and dfn/dg (n,)."""
    contact = touching & (g < 0.0)
    band = contact & (g > -d)
    fn = np.where(contact, np.where(band, kn * g * g / (2 * d), -kn * (g + 0.5 * d)), 0.0)
    dfn = np.where(contact, np.where(band, kn * g / d, -kn), 0.0)
    return fn, dfn


@dataclass(frozen=True)
class Law:
    """The parameters of a pair's law: normal and tangential penalties per unit weighted
    area kn, kt (n,), the Coulomb coefficient mu, sticky ties, the rounding band d of the
    normal law."""

    kn: np.ndarray
    kt: np.ndarray
    mu: float
    sticky: bool
    d: float


@dataclass
class Traction:
    """The law's traction t (n, 2), its derivative dt/dx (n, 2, 2), the status of each node
    (0 open, 1 stick, 2 slip, 3 sticky), with friction the slip state (contact, s0, z,
    limit; else None), and the normal traction fn (n,) of the nodes not tied."""

    t: np.ndarray
    dt: np.ndarray
    status: np.ndarray
    slip: tuple | None
    fn: np.ndarray


def traction(law: Law, x: np.ndarray, proj, state: ContactState, resting: bool) -> Traction:
    """The contact law per unit of the weighted area at positions x (n, 2) relative to the
    surface, their projection `proj` (surfaces.Projection) and the committed history
    `state` (its multipliers shift the gap: g - lambda / kn).  resting: nodes resting on the
    surface (0 <= g - lambda / kn < d) get the penalty kn n n^T in the tangent, not in the
    force (ContactPair, the predicting tangent)."""
    status = np.zeros(len(x), np.int8)
    kn, d = law.kn, law.d
    g = proj.g - state.multiplier / kn  # the gap the penalty sees: lambda / kn in front of the surface
    stuck = state.stuck
    contact = proj.active & (g < 0.0) & ~stuck
    # normal law (eqs. 40-41): f = fn n, fn = -kn g, rounded over -d < g < 0 so that a node
    # touching the surface (g = 0) feels no force and the force has a continuous slope
    fn, dfn = normal_law(g, contact, kn, d)
    nv, tv = proj.n, proj.t
    nn, tt = outer(nv, nv), outer(tv, tv)
    f = fn[:, None] * nv
    K = dfn[:, None, None] * nn  # d f / d x
    if resting:  # (the held nodes have no force: dfn = 0 there, and the sum is that of -kn nn + dfn nn)
        on = proj.active & (g >= 0.0) & (g < d) & ~stuck
        K = -((on * kn)[:, None, None] * nn) + K
    K += (fn * proj.kappa)[:, None, None] * tt  # fn dn/dx
    status[contact] = 1
    slip_state = None
    if law.mu > 0 and not law.sticky:
        slip_state = _friction(law, proj, state, contact, fn, dfn, f, K, status)
    if law.sticky:
        tie = stuck * (TIE * kn)  # the tied nodes' spring, 0 elsewhere (whose stuck point is 0)
        f -= tie[:, None] * (x - state.stuck_point)
        K[:, 0, 0] -= tie
        K[:, 1, 1] -= tie
        status[stuck] = 3
    return Traction(f, K, status, slip_state, fn)


def updated_multipliers(state: ContactState, law: Traction, new: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """At the end of a converged step: the multiplier it used and its normal traction fn, the
    target of Uzawa's update at the next step (ContactState.advanced), each (n,) (zero where
    a node left the surface, and for the nodes tied, `state.stuck`, or tied at this step,
    `new`)."""
    tied = state.stuck | new
    return np.where(tied, 0.0, state.multiplier), np.where(tied, 0.0, law.fn)


def _friction(law: Law, proj, state: ContactState, contact, fn, dfn, f, K, status) -> tuple:
    """Coulomb friction (eqs. 42-45) with the stick/slip corner rounded, added in place to the
    traction f (n, 2), its derivative K (n, 2, 2) and the status: ft = -mu fn tanh(z),
    z = kt (s - s0) / (mu fn).  For small slips it is the tangential penalty kt (s - s0)
    (stick, eq. 44), for large ones mu fn (slip, eq. 45).  The sharp law makes Newton cycle
    between stick and slip from one iteration to the next; this one is smooth.  A node
    touching for the first time sticks where it was at the last converged step.  Returns
    the slip state (contact, s0, z, limit)."""
    kt, tv, nv = law.kt, proj.t, proj.n
    tt = outer(tv, tv)
    fresh = contact & np.isnan(state.s_stick)
    s0 = np.where(fresh, proj.s_prev, state.s_stick)
    slip = np.where(contact, proj.s - s0, 0.0)
    limit = law.mu * fn  # eq. 42
    rub = contact & (limit > 0)
    safe = np.where(rub, limit, 1.0)
    z = np.where(rub, kt * slip / safe, 0.0)
    th = np.tanh(z)
    sech2 = 1.0 - th * th
    ft = np.where(rub, -limit * th, 0.0)
    f += ft[:, None] * tv
    K -= (rub * kt * sech2 * proj.m)[:, None, None] * tt  # dft/ds
    K -= (rub * law.mu * (th - z * sech2) * dfn)[:, None, None] * outer(tv, nv)  # dft/dfn
    K -= (ft * proj.kappa)[:, None, None] * outer(nv, tv)  # ft dt/dx
    sliding = rub & (np.abs(z) > 1.0)
    status[sliding] = 2
    return contact, s0, z, limit


def damping(
    c: np.ndarray, d: float, x: np.ndarray, state: ContactState, proj, g: np.ndarray
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The contact stabilization's traction per unit of the weighted area (n, 2), its
    derivative d/dx (n, 2, 2) and the energy it dissipates over the step per unit of that
    area (n,), at positions x (n, 2) relative to the surface: -c s(g) ((x - x_prev) . n) n,
    c (n,) the damping per unit area and normal motion, s = 1 for g >= 0, 0 for g <= -d, a
    cubic between, g (n,) the gap the normal law sees (ContactPair, contact stabilization)."""
    free = proj.active & ~state.stuck
    xi = np.minimum(np.maximum(-g / d, 0.0), 1.0)  # 0 at the surface, 1 at the depth of the rounding
    s = np.where(free, 1.0 - xi * xi * (3.0 - 2.0 * xi), 0.0)
    ds = np.where(free, 6.0 * xi * (1.0 - xi) / d, 0.0)  # ds/dg
    step = x - state.x_prev  # the motion relative to the surface since the last converged step
    nv, tv = proj.n, proj.t
    delta = step[:, 0] * nv[:, 0] + step[:, 1] * nv[:, 1]
    along = step[:, 0] * tv[:, 0] + step[:, 1] * tv[:, 1]
    fs = -c * s * delta
    # d(fs n)/dx = n (dfs/dx)^T + fs dn/dx, dn/dx = kappa t t^T, d delta/dx = n + kappa (step . t) t
    K = -(c * ds * delta)[:, None, None] * outer(nv, nv)
    K -= (c * s)[:, None, None] * outer(nv, nv + (proj.kappa * along)[:, None] * tv)
    K += (fs * proj.kappa)[:, None, None] * outer(tv, tv)
    return fs[:, None] * nv, K, 0.5 * c * s * delta * delta
