"""A viscous network with Bergström and Boyce's flow rule, integrated by the exponential map.

Kinematics: F = Fe Fv, det Fv = 1, no viscous spin.  The elastic part is the isochoric part of
a hyperelastic law (base.Hyperelastic) at Fe; tau its Kirchhoff stress (deviatoric),
q = sqrt(3/2 tau':tau'), lambda_v = sqrt(tr(Cv)/3), Cv = Fv^T Fv, and the flow

    Dv = eps_dot (3/2) tau'/q,    eps_dot = A (lambda_v - 1 + E)^C q^m / a_T(T)

(A, C, m, E named as Abaqus' parallel rheological framework).  The state is Cv^-1 (reference
frame, symmetric; components RR, RZ, ZZ, TT): Be = F Cv^-1 F^T.

Over a step (elastic predictor, viscous corrector): Be_tr = F Cv_n^-1 F^T, its meridian block
diagonalized in closed form (eigenvalues mu_1 >= mu_2 on the unit axes n_1, n_2) and the hoop
mu_3.  With isotropy the exponential map keeps these axes and acts on the principal log strains
e_i = ln(lambda_e,i); the flow is isochoric and along tau', deviatoric, so sum(e) = sum(e_tr)
and only the deviatoric part moves, two unknowns w = (y, z) on the plane sum(e) = 0
(principal.py's basis, where the law gives tau' = (t_y, t_z) and k = dtau'/dw):

    r(w) = w - w_tr + a g(q) tau'(w) = 0,   a = 3/2 dt,   g(q) = eps_dot / q = rate q^(m - 1),

a 2 x 2 Newton per point, vectorized; lambda_v in eps_dot is the one of the start of the step
(the hardening factor lags a step; stress and flow direction are implicit).  Then be_i =
mu_i exp(2 (e_i - e_tr,i)) (det Fv = 1 to round-off), Cv^-1 = F^-1 Be F^-T, P = tau F^-T.

Tangent: with h_j = F^-1 n_j, de_tr,j = n_j.dF h_j (meridian) and df/f (hoop), so that the
directions O_j = n_j h_j^T (and e_theta/f) carry both de_tr along dx and tau's part in P.  The
algorithmic modulus M = k (dr/dw)^-1 (= (k^-1 + a g I + a c tau' tau'^T)^-1 where k is regular,
dg/dw = c k tau') is symmetric, and
A = O_w M O_w^T + (t_1 - t_2)/(mu_1 - mu_2) O_12 d(Be_tr)_12 (the rotation of the axes; its
limit where mu_1 = mu_2) - P dF^T F^-T (the geometric part), O_w = (O_y, O_z) on the plane.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from .base import Hyperelastic
from .principal import SQRT2, SQRT6, Plane, plane_function

PlaneLaw = Callable[[np.ndarray, np.ndarray], Plane]
MAX_ITERATIONS = 50
TOLERANCE = 1e-12  # on the local residual, a logarithmic strain (its Euclidean norm)
ROUNDOFF = 1e-14  # the residual's round-off per unit of |dr/dw| (some 50 machine epsilons)
DEGENERATE = 1e-8  # relative gap of the meridian eigenvalues below which the limit is used
# rows of the local state (local_system): the unknowns, the law's t and k there, the residual,
# the Jacobian dr/dw and the residual's squared norm
Y, Z, TY, TZ, KYY, KYZ, KZZ, RY, RZ, JYY, JYZ, JZY, JZZ, NORM = range(14)


def power(x: np.ndarray, e: float) -> np.ndarray:
    """x^e (n) for x > 0: NumPy's own power where it has a short way (e 0, 1/2, 1, 2), else
    exp(e ln x) (two vectorized functions cost less than the general power)."""
    if e in (0.0, 0.5, 1.0, 2.0):
        return x**e
    return np.exp(e * np.log(x))


class LocalUpdateError(ArithmeticError):
    """The local Newton of a network did not converge at some points (their flat indices)."""

    def __init__(self, points: np.ndarray):
        self.points = np.asarray(points)
        super().__init__(f"the viscous network's update did not converge at point(s) {self.points[:10].tolist()}")


@dataclass(frozen=True)
class BergstromBoyce:
    """Flow eps_dot = A (lambda_v - 1 + E)^C q^m / a_T: A > 0, -1 <= C <= 0, m >= 1, E > 0;
    `shift` False: the network ignores the temperature shift a_T."""

    A: float
    C: float
    m: float
    E: float = 0.01
    shift: bool = True

    def __post_init__(self):
        if not self.A > 0:
            raise ValueError(f"A: the flow's rate constant must be > 0, got {self.A}")
        if not -1.0 <= self.C <= 0.0:
            raise ValueError(f"C: the flow's stretch exponent must lie in [-1, 0], got {self.C}")
        if not self.m >= 1.0:
            raise ValueError(f"m: the flow's stress exponent must be >= 1, got {self.m}")
        if not self.E > 0:
            raise ValueError(f"E: the flow's stretch offset must be > 0, got {self.E}")

    def rate_factor(self, trace_Cv: np.ndarray, a_T: np.ndarray | float) -> np.ndarray:
        """A (lambda_v - 1 + E)^C / a_T (n), lambda_v = sqrt(tr(Cv)/3) from tr(Cv) (n)."""
        lam_v = np.sqrt(trace_Cv / 3.0)
        return self.A * power(lam_v - 1.0 + self.E, self.C) / a_T


@dataclass(frozen=True)
class Network:
    """A viscous network: its elastic law (the law's isochoric part, times `scale`) and its flow."""

    law: Hyperelastic
    flow: BergstromBoyce
    scale: float = 1.0

    def __post_init__(self):
        if not self.scale > 0:
            raise ValueError(f"stiffness_ratio: must be > 0, got {self.scale}")

    def plane(self, y: np.ndarray, z: np.ndarray) -> Plane:
        """The elastic part on the deviatoric plane (principal.py): at log strains (y, z) (n
        each), the principal Kirchhoff stresses (t_y, t_z) and k = dt/de (k_yy, k_yz, k_zz)."""
        return plane_function(self.law, self.scale)(y, z)


def local_system(
    plane: PlaneLaw,
    y: np.ndarray,
    z: np.ndarray,
    y_tr: np.ndarray,
    z_tr: np.ndarray,
    rate: np.ndarray,
    m: float,
    a: float,
) -> tuple[np.ndarray, ...]:
    """The local state (14 arrays (n), rows Y .. NORM) at w = (y, z) (n each): residual_system
    of the law's t and k there."""
    return residual_system(plane(y, z), y, z, y_tr, z_tr, rate, m, a)


def residual_system(
    law: Plane, y: np.ndarray, z: np.ndarray, y_tr: np.ndarray, z_tr: np.ndarray, rate: np.ndarray, m: float, a: float
) -> tuple[np.ndarray, ...]:
    """The local state (14 arrays (n), rows Y .. NORM) at w = (y, z) (n each) where the law gives
    t and k (law, principal.py's five arrays): the residual r = w - w_tr + a g t, g = rate
    q^(m-1), and dr/dw = I + a (g k + c t (k t)^T), c = 3/2 (m - 1) rate q^(m-3) (dg/dw = c k t)."""
    ty, tz, kyy, kyz, kzz = law
    q2 = 1.5 * (ty * ty + tz * tz)
    positive = q2 > 0
    safe = np.where(positive, q2, 1.0)  # q = 0: t = 0, the terms with q^(m-3) vanish
    rate_q = rate * power(safe, 0.5 * (m - 1.0))  # rate q^(m-1)
    ag = a * (rate_q if m == 1.0 else np.where(positive, rate_q, 0.0))
    ac = (1.5 * (m - 1.0) * a) * rate_q / safe
    kty, ktz = ac * (kyy * ty + kyz * tz), ac * (kyz * ty + kzz * tz)
    ry, rz = (y - y_tr) + ag * ty, (z - z_tr) + ag * tz
    jyy = 1.0 + ag * kyy + ty * kty
    jyz = ag * kyz
    jzy = jyz + tz * kty
    jyz += ty * ktz
    jzz = 1.0 + ag * kzz + tz * ktz
    return y, z, ty, tz, kyy, kyz, kzz, ry, rz, jyy, jyz, jzy, jzz, ry * ry + rz * rz


def flow_guess(
    ty: np.ndarray, tz: np.ndarray, y_tr: np.ndarray, z_tr: np.ndarray, rate: np.ndarray, m: float, a: float
) -> tuple[np.ndarray, np.ndarray]:
    """The points that flow far within the step (their indices) and for them rho: the solution
    for an elastic part linear in w (2 mu_eff = t.w_tr / w_tr.w_tr with t = (ty, tz) (n each)
    at the predictor) is w = rho w_tr, rho (1 + c rho^(m-1)) = 1, c = a rate q_tr^(m-1) 2 mu_eff;
    far: rho < 0.9.  For u = ln(rho), u + ln(1 + c e^((m-1) u)) = 0 (convex, slope in [1, m]):
    one Newton step from u = -ln(1 + c)/m (right of the root), within the model's own error
    of the root.  For a steep flow and a long step the plain Newton from the predictor creeps."""
    ww = y_tr * y_tr + z_tr * z_tr
    two_mu = np.where(ww > 0, (ty * y_tr + tz * z_tr) / np.where(ww > 0, ww, 1.0), 0.0)
    q2 = 1.5 * (ty * ty + tz * tz)
    c = a * rate * power(np.where(q2 > 0, q2, 1.0), 0.5 * (m - 1.0)) * np.maximum(two_mu, 0.0)
    far = np.flatnonzero(c > (1.0 / 0.9 - 1.0) / 0.9 ** (m - 1.0))  # rho(c) < 0.9
    c = c[far]
    u = -np.log1p(c) / m
    w = c * np.exp((m - 1.0) * u)
    u -= (u + np.log1p(w)) * (1.0 + w) / (1.0 + m * w)
    return far, np.exp(u)


def solve_local(
    plane: PlaneLaw, y_tr: np.ndarray, z_tr: np.ndarray, rate: np.ndarray, m: float, dt: float
) -> tuple[np.ndarray, ...]:
    """The local state (14 rows (n), local_system) at the w = (y, z) solving r(w) = 0.  Newton
    from the elastic predictor, or from flow_guess where that one flows far; a step that does
    not lower |r| is halved (up to 8 times).  While at least a quarter of the points iterate,
    all points are evaluated and the converged ones held (a zero step: the same numbers again);
    then only the others (gathered).  Either way a point's iterates are its own."""
    n, a = y_tr.size, 1.5 * dt
    law = plane(y_tr, z_tr)
    far, rho = flow_guess(law[0], law[1], y_tr, z_tr, rate, m, a) if dt > 0 else (np.arange(0), None)
    if far.size and 4 * far.size >= n:  # the predictor's residual and Jacobian are not needed
        scale = np.ones(n)
        scale[far] = rho
        X = local_system(plane, scale * y_tr, scale * z_tr, y_tr, z_tr, rate, m, a)
    else:
        X = residual_system(law, y_tr, z_tr, y_tr, z_tr, rate, m, a)
        if far.size:
            new = local_system(plane, rho * y_tr[far], rho * z_tr[far], y_tr[far], z_tr[far], rate[far], m, a)
            X = scatter(X, far, new)
    for _ in range(MAX_ITERATIONS):
        active = unconverged(X)
        count = np.count_nonzero(active)
        if not count:
            return X
        idx = None if 4 * count >= n else np.flatnonzero(active)
        S = X if idx is None else tuple(row[idx] for row in X)
        idet = 1.0 / (S[JYY] * S[JZZ] - S[JYZ] * S[JZY])
        dy = (S[JYZ] * S[RZ] - S[JZZ] * S[RY]) * idet
        dz = (S[JZY] * S[RY] - S[JYY] * S[RZ]) * idet
        if idx is None:
            dy, dz = np.where(active, dy, 0.0), np.where(active, dz, 0.0)
            args = (y_tr, z_tr, rate, m, a)
        else:
            args = (y_tr[idx], z_tr[idx], rate[idx], m, a)
        factor: float | np.ndarray = 1.0
        for _halving in range(9):
            new = local_system(plane, S[Y] + factor * dy, S[Z] + factor * dz, *args)
            worse = new[NORM] > S[NORM]
            if not worse.any():
                break
            factor = np.where(worse, 0.5 * factor, factor)
        X = new if idx is None else scatter(X, idx, new)
    raise LocalUpdateError(np.flatnonzero(unconverged(X)))


def unconverged(X: tuple[np.ndarray, ...]) -> np.ndarray:
    """Where the local state X (14 rows (n)) is not converged (n, bool): |r| above TOLERANCE,
    or above ROUNDOFF tr(dr/dw) where that is more (the trace: about the largest eigenvalue of
    dr/dw, whose diagonal is 1 + a g k_ii + ..., positive).  A step far longer than the flow's
    relaxation makes dr/dw large (I + a g k) and r's round-off with it (about eps a g |k|); the
    stress is then as exact as where the test is TOLERANCE: dtau = k (dr/dw)^-1 dr ~ dr / (a g).
    A residual that is not a number is unconverged."""
    scale = ROUNDOFF * (X[JYY] + X[JZZ])
    return ~(X[NORM] <= np.maximum(TOLERANCE * TOLERANCE, scale * scale))


def scatter(X: tuple[np.ndarray, ...], idx: np.ndarray, new: tuple[np.ndarray, ...]) -> tuple[np.ndarray, ...]:
    """The rows of X (n each) with the points idx replaced by the rows of new (idx.size each)."""
    out = []
    for row, value in zip(X, new, strict=True):
        row = row.copy()
        row[idx] = value
        out.append(row)
    return tuple(out)


def meridian_axes(p: np.ndarray, s: np.ndarray, r: np.ndarray, pm: np.ndarray) -> tuple[np.ndarray, ...]:
    """Eigenvalues mu_1 >= mu_2 (n) of the symmetric positive [[p, r], [r, s]] of determinant
    pm, the unit axis (cos, sin) of mu_1 (the second is (-sin, cos)) and the half gap rad =
    (mu_1 - mu_2)/2 (n each).  The axis from the column without cancellation."""
    half = 0.5 * (p - s)
    rad = np.sqrt(half * half + r * r)
    mu1 = 0.5 * (p + s) + rad
    mu2 = pm / mu1  # no cancellation where mu_2 << mu_1
    big = rad + np.abs(half)
    norm = np.sqrt(2.0 * rad * big)  # |(big, r)|, rad = 0 only where the block is round
    round_ = norm == 0
    inv = 1.0 / np.where(round_, 1.0, norm)
    up = half >= 0
    cos = np.where(round_, 1.0, np.where(up, big, r) * inv)
    sin = np.where(up, r, big) * inv
    return mu1, mu2, cos, sin, rad


def network_rows(network: Network, xt: np.ndarray, Cvi: np.ndarray, dt: float, a_T: np.ndarray | float) -> tuple:
    """P (5, n), A (5, 5, n) and the trial Cv^-1 (4, n) of one network at rows xt (5, n) after a
    step dt from the committed Cv^-1 rows (4, n) (RR, RZ, ZZ, TT), a_T (n) or a number."""
    a, b, c, d, f = xt
    RR, RZ, ZZ, TT = Cvi
    Ya, Yb, Yc, Yd = RR * a + RZ * b, RZ * a + ZZ * b, RR * c + RZ * d, RZ * c + ZZ * d  # Cv^-1 F^T
    p, r, s = a * Ya + b * Yb, c * Ya + d * Yb, c * Yc + d * Yd  # Be_tr = F Cv^-1 F^T, meridian
    h = f * f * TT  # its hoop value
    j2 = a * d - b * c
    det_m = RR * ZZ - RZ * RZ
    pm = j2 * j2 * det_m  # det of Be_tr's meridian block
    mu1, mu2, cos, sin, rad = meridian_axes(p, s, r, pm)
    y_tr = np.log(mu1 * mu1 / pm) * (0.5 / SQRT2)  # (e_1 - e_2)/sqrt 2, e = ln(mu)/2
    z_tr = np.log(pm / (h * h)) * (0.5 / SQRT6)  # (e_1 + e_2 - 2 e_3)/sqrt 6
    rate = network.flow.rate_factor((RR + ZZ) / det_m + 1.0 / TT, a_T if network.flow.shift else 1.0)
    rate = np.broadcast_to(rate, a.shape)
    X = solve_local(network.plane, y_tr, z_tr, rate, network.flow.m, dt)
    ij = 1.0 / j2
    H = np.stack(
        [(d * cos - b * sin) * ij, (a * sin - c * cos) * ij, (-d * sin - b * cos) * ij, (c * sin + a * cos) * ij]
    )
    # be_i = mu_i exp(2 (e_i - e_tr,i)), e - e_tr = (dy u_y + dz u_z)
    ez = np.exp((2.0 / SQRT6) * (X[Z] - z_tr))
    ey = np.exp(SQRT2 * (X[Y] - y_tr))
    trial = elastic_state(mu1 * ez * ey, mu2 * ez / ey, TT / (ez * ez), H)
    P, A = tangent_rows(X, H, (cos, sin), mu1, mu2, rad, xt)
    return P, A, trial


def elastic_state(be1: np.ndarray, be2: np.ndarray, TT: np.ndarray, H: np.ndarray) -> np.ndarray:
    """Cv^-1 = F^-1 Be F^-T (4, n) (RR, RZ, ZZ, TT) of Be = be1 n_1 n_1 + be2 n_2 n_2 (meridian)
    from h_j = F^-1 n_j, H (4, n) = (h_1R, h_1Z, h_2R, h_2Z), and the new TT (n)."""
    h1R, h1Z, h2R, h2Z = H
    out = np.empty((4, be1.size))
    out[0] = be1 * h1R * h1R + be2 * h2R * h2R
    out[1] = be1 * h1R * h1Z + be2 * h2R * h2Z
    out[2] = be1 * h1Z * h1Z + be2 * h2Z * h2Z
    out[3] = TT
    return out


def tangent_rows(
    X: tuple[np.ndarray, ...] | np.ndarray,
    H: np.ndarray,
    axis: tuple,
    mu1: np.ndarray,
    mu2: np.ndarray,
    rad: np.ndarray,
    xt: np.ndarray,
) -> tuple[np.ndarray, np.ndarray]:
    """P (5, n) and A = dP/dx (5, 5, n) from the local state X at the solution (14, n), the
    axes h_j = F^-1 n_j (H (4, n): h_1R, h_1Z, h_2R, h_2Z), n_1 = axis = (cos, sin) (n each),
    the trial eigenvalues and half gap (module docstring).  A is symmetric (the update derives
    from a potential of F at fixed Cv_n^-1): its upper triangle is computed, entry by entry."""
    n = xt.shape[1]
    f = xt[4]
    cos, sin = axis
    q1, q2 = (cos, sin), (-sin, cos)  # n_1, n_2 (r, z)
    h1, h2 = (H[0], H[1]), (H[2], H[3])
    pairs = [(i // 2, i % 2) for i in range(4)]  # x's meridian components (a, B): F_aB
    O1 = [q1[a] * h1[B] for a, B in pairs]  # O_j = n_j h_j^T
    O2 = [q2[a] * h2[B] for a, B in pairs]
    Oy = [(u - v) * (1.0 / SQRT2) for u, v in zip(O1, O2, strict=True)]
    Oz = [(u + v) * (1.0 / SQRT6) for u, v in zip(O1, O2, strict=True)] + [(-2.0 / SQRT6) / f]
    ty, tz = X[TY], X[TZ]
    P = np.empty((5, n))
    for i in range(4):
        P[i] = ty * Oy[i] + tz * Oz[i]
    P[4] = tz * Oz[4]
    # M = k (dr/dw)^-1, symmetric
    kyy, kyz, kzz, jyy, jyz, jzy, jzz = X[KYY], X[KYZ], X[KZZ], X[JYY], X[JYZ], X[JZY], X[JZZ]
    idet = 1.0 / (jyy * jzz - jyz * jzy)
    Myy = (kyy * jzz - kyz * jzy) * idet
    Myz = 0.5 * (kyz * jyy - kyy * jyz + kyz * jzz - kzz * jzy) * idet
    Mzz = (kzz * jyy - kyz * jyz) * idet
    Dy = [Myy * u + Myz * v for u, v in zip(Oy, Oz, strict=False)] + [Myz * Oz[4]]
    Dz = [Myz * u + Mzz * v for u, v in zip(Oy, Oz, strict=False)] + [Mzz * Oz[4]]
    # the rotation of the axes: dtau_12 = ratio dBe_12, dBe_12 = n_1.dF mu_2 h_2 + n_2.dF mu_1 h_1
    gap = rad > DEGENERATE * mu1
    ratio = np.where(gap, ty / (SQRT2 * np.where(gap, rad, 1.0)), Myy / (mu1 + mu2))
    rO12 = [ratio * (q1[a] * h2[B] + q2[a] * h1[B]) for a, B in pairs]
    m2h2, m1h1 = (mu2 * h2[0], mu2 * h2[1]), (mu1 * h1[0], mu1 * h1[1])
    dBe12 = [q1[a] * m2h2[B] + q2[a] * m1h1[B] for a, B in pairs]
    # the geometric part tau d(F^-T) = -P dF^T F^-T: [(a, B), (alpha, beta)] = -P_a,beta F^-T_alpha,B
    ij = 1.0 / (xt[0] * xt[3] - xt[1] * xt[2])
    Gi = (xt[3] * ij, -xt[2] * ij, -xt[1] * ij, xt[0] * ij)
    A = np.empty((5, 5, n))
    for i, (a, B) in enumerate(pairs):
        for j in range(i, 4):
            alpha, beta = pairs[j]
            A[i, j] = Oy[i] * Dy[j] + Oz[i] * Dz[j] + rO12[i] * dBe12[j] - P[2 * a + beta] * Gi[2 * alpha + B]
            if j > i:
                A[j, i] = A[i, j]
        A[i, 4] = A[4, i] = Oy[i] * Dy[4] + Oz[i] * Dz[4]
    A[4, 4] = Oz[4] * Dz[4] - P[4] / f
    return P, A
