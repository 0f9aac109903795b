"""A network's update as it was before its local problem was reduced to the deviatoric plane
(three principal log strains, a 3 x 3 local Newton, the tangent direction by direction) and the
principal stresses of the laws in three components, kept verbatim as the reference the reduced
update must reproduce."""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from axiform.materials.base import Hyperelastic
from axiform.materials.invariant import InvariantLaw
from axiform.materials.ogden import Ogden
from axiform.materials.principal import generic_principal

Rows = tuple[np.ndarray, np.ndarray]
MAX_ITERATIONS = 50
TOLERANCE = 1e-12
DEGENERATE = 1e-8
THIRD = 1.0 / 3.0


def principal_function(law: Hyperelastic, scale: float = 1.0) -> Callable[[np.ndarray], Rows]:
    """e (3, n) -> (t (3, n), K (3, 3, n)) of `scale` times the law's isochoric part."""
    if isinstance(law, InvariantLaw):
        return lambda e: invariant_principal(law, e, scale)
    if isinstance(law, Ogden):
        return lambda e: ogden_principal(law, e, scale)
    return lambda e: generic_principal(law, e, scale)


def invariant_principal(law: InvariantLaw, e: np.ndarray, scale: float) -> Rows:
    """t and K of W_iso = Psi(I1bar, I2bar) (module docstring)."""
    eb = e - e.mean(0)
    b = np.exp(2.0 * eb)  # bbar_i
    I1 = b.sum(0)
    bb = b * b
    S2 = bb.sum(0)
    I2 = 0.5 * (I1 * I1 - S2) if law.uses_I2 else None
    P1, P2, P11, P12, P22 = law.psi_derivatives(I1, I2, True)
    d1 = 2.0 * b - 2.0 * THIRD * I1
    t = P1 * d1
    # dd1_j/de_k = 4 b_j (delta_jk - 1/3) - 2/3 d1_k
    dd1 = -4.0 * THIRD * b[:, None] - 2.0 * THIRD * d1[None]
    for j in range(3):
        dd1[j, j] += 4.0 * b[j]
    K = P1 * dd1
    if P11 is not None:
        K += P11 * (d1[:, None] * d1[None])
    if P2 is not None:
        d2 = I1 * d1 - 2.0 * bb + 2.0 * THIRD * S2
        t += P2 * d2
        # dd2_j/de_k = d1_j d1_k + I1 dd1_jk - 8 b_j^2 (delta_jk - 1/3) + 8/3 b_k^2 - 8/9 sum b^2
        dd2 = d1[:, None] * d1[None] + I1 * dd1 + 8.0 * THIRD * (bb[:, None] + bb[None]) - 8.0 / 9.0 * S2
        for j in range(3):
            dd2[j, j] -= 8.0 * bb[j]
        K += P2 * dd2
        if P12 is not None:
            K += P12 * (d1[:, None] * d2[None] + d2[:, None] * d1[None])
        if P22 is not None:
            K += P22 * (d2[:, None] * d2[None])
    return scale * t, scale * K


def ogden_principal(law: Ogden, e: np.ndarray, scale: float) -> Rows:
    """t and K of Ogden's W_iso: t_j = sum_p 2 mu_p/alpha_p (L_pj - S_p/3), L_pj = lbar_j^alpha_p,
    S_p = sum_j L_pj; K_jk = sum_p 2 mu_p (L_pj (delta_jk - 1/3) - L_pk/3 + S_p/9)."""
    eb = e - e.mean(0)
    t = np.zeros_like(e)
    K = np.zeros((3, 3, e.shape[1]))
    for mu_p, alpha_p in zip(law.mu, law.alpha, strict=True):
        L = np.exp(alpha_p * eb)
        S = L.sum(0)
        t += 2.0 * mu_p / alpha_p * (L - THIRD * S)
        Kp = -THIRD * (L[:, None] + L[None]) + S / 9.0
        for j in range(3):
            Kp[j, j] += L[j]
        K += 2.0 * mu_p * Kp
    return scale * t, scale * K


def inverse3(M: np.ndarray) -> np.ndarray:
    """The inverse of 3x3 matrices M (3, 3, n) by cofactors, (3, 3, n)."""
    C = np.empty_like(M)
    for i in range(3):
        for j in range(3):
            i1, i2 = (i + 1) % 3, (i + 2) % 3
            j1, j2 = (j + 1) % 3, (j + 2) % 3
            C[j, i] = M[i1, j1] * M[i2, j2] - M[i1, j2] * M[i2, j1]  # adjugate: transposed cofactors
    det = M[0, 0] * C[0, 0] + M[0, 1] * C[1, 0] + M[0, 2] * C[2, 0]
    return C / det


def local_system(t: np.ndarray, K: np.ndarray, rate: np.ndarray, m: float, dt: float) -> tuple[np.ndarray, np.ndarray]:
    """dt (3/2) g(q) t' (3, n) and its Jacobian in e (3, 3, n), g = rate q^(m-1), from the
    principal stresses t (3, n), K = dt/de (3, 3, n) and rate (n)."""
    dev = t - t.mean(0)
    q = np.sqrt(1.5 * (dev * dev).sum(0))
    safe = np.where(q > 0, q, 1.0)  # q = 0: dev = 0, the terms with q^(m-3) vanish
    power = rate * safe ** (m - 1.0)
    g = power * np.where(q > 0, 1.0, 0.0 if m > 1.0 else 1.0)
    flow = (1.5 * dt) * g * dev
    Kdev = K - K.mean(0)
    dg = (1.5 * (m - 1.0)) * power / (safe * safe) * (dev[:, None] * K).sum(0)  # dg/de (3, n)
    jac = (1.5 * dt) * (g * Kdev + dev[:, None] * dg[None])
    for i in range(3):
        jac[i, i] += 1.0
    return flow, jac


def scalar_guess(
    e_tr: np.ndarray, t: np.ndarray, rate: np.ndarray, m: float, dt: float
) -> tuple[np.ndarray, np.ndarray]:
    """A first iterate of the local Newton (3, n) and rho (n): the solution for an elastic part
    linear in the deviatoric log strain (2 mu_eff = t':e_tr' / e_tr':e_tr' at the predictor), e =
    mean(e_tr) + rho e_tr', rho (1 + c rho^(m-1)) = 1, c = 3/2 dt rate q_tr^(m-1) 2 mu_eff,
    solved for u = ln(rho) (u + ln(1 + c e^((m-1) u)) = 0: convex, slope in [1, m]) by Newton
    from u = 0.  For a steep flow and a long step the plain Newton from the predictor creeps."""
    mean = e_tr.mean(0)
    dev = e_tr - mean
    tdev = t - t.mean(0)
    ee = (dev * dev).sum(0)
    two_mu = np.where(ee > 0, (tdev * dev).sum(0) / np.where(ee > 0, ee, 1.0), 0.0)
    q = np.sqrt(1.5 * (tdev * tdev).sum(0))
    c = 1.5 * dt * rate * np.where(q > 0, q, 1.0) ** (m - 1.0) * np.maximum(two_mu, 0.0)
    u = np.zeros_like(mean)
    for _ in range(30):
        w = c * np.exp((m - 1.0) * u)
        du = -(u + np.log1p(w)) / (1.0 + (m - 1.0) * w / (1.0 + w))
        u += du
        if not (np.abs(du) > 1e-3).any():  # the Newton of solve_local finishes the work
            break
    rho = np.exp(u)
    return mean + rho * dev, rho


def solve_local(
    principal: Callable[[np.ndarray], Rows], e_tr: np.ndarray, rate: np.ndarray, m: float, dt: float
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """The principal log strains e (3, n) solving r(e) = 0, and at the solution t (3, n),
    K (3, 3, n) and the local Jacobian dr/de (3, 3, n).  Newton from the elastic predictor, or
    from scalar_guess where that one flows far (rho < 0.9), on the points not yet converged
    only; a step that does not lower |r| is halved (up to 8 times)."""
    n = e_tr.shape[1]
    t, K = principal(e_tr)
    e = e_tr.copy()
    if dt > 0:
        guess, rho = scalar_guess(e_tr, t, rate, m, dt)
        far = np.flatnonzero(rho < 0.9)
        if far.size:
            e[:, far] = guess[:, far]
            t[:, far], K[:, :, far] = principal(guess[:, far])
    flow, jac = local_system(t, K, rate, m, dt)
    r = e - e_tr + flow
    norm = np.abs(r).max(0)
    for _ in range(MAX_ITERATIONS):
        idx = np.flatnonzero(norm > TOLERANCE)
        if not idx.size:
            return e, t, K, jac
        at: slice | np.ndarray = slice(None) if idx.size == n else idx
        e_a, e_tr_a, rate_a, norm_a = e[:, at], e_tr[:, at], rate[at], norm[at]
        step = -(inverse3(jac[:, :, at]) * r[None, :, at]).sum(1)
        factor = np.ones_like(norm_a)
        for _halving in range(9):
            trial = e_a + factor * step
            t_a, K_a = principal(trial)
            flow_a, jac_a = local_system(t_a, K_a, rate_a, m, dt)
            r_a = trial - e_tr_a + flow_a
            new = np.abs(r_a).max(0)
            worse = new > norm_a
            if not worse.any():
                break
            factor = np.where(worse, 0.5 * factor, factor)
        e[:, at], t[:, at], K[:, :, at], jac[:, :, at], r[:, at], norm[at] = trial, t_a, K_a, jac_a, r_a, new
    raise ArithmeticError(np.flatnonzero(norm > TOLERANCE))


def meridian_eigen(p: np.ndarray, s: np.ndarray, r: np.ndarray) -> tuple[np.ndarray, ...]:
    """Eigenvalues mu_1 >= mu_2 (n) of the symmetric positive [[p, r], [r, s]] and the axes as
    c2 = cos(2 phi), s2 = sin(2 phi), phi the angle of the first axis from r; also the half gap
    rad = (mu_1 - mu_2)/2 (n)."""
    mean = 0.5 * (p + s)
    half = 0.5 * (p - s)
    rad = np.hypot(half, r)
    mu1 = mean + rad
    mu2 = (p * s - r * r) / mu1  # no cancellation where mu_2 << mu_1
    safe = np.where(rad > 0, rad, 1.0)
    c2 = np.where(rad > 0, half / safe, 1.0)
    s2 = np.where(rad > 0, r / safe, 0.0)
    return mu1, mu2, c2, s2, rad


def network_rows(network, xt: np.ndarray, Cvi: np.ndarray, dt: float, a_T: np.ndarray | float) -> tuple:
    """P (5, n), A (5, 5, n) and the trial Cv^-1 (4, n) of one network at rows xt (5, n) after a
    step dt from the committed Cv^-1 rows (4, n) (RR, RZ, ZZ, TT), a_T (n) or a number."""
    a, b, c, d, f = xt
    RR, RZ, ZZ, TT = Cvi
    Y = (RR * a + RZ * b, RR * c + RZ * d, RZ * a + ZZ * b, RZ * c + ZZ * d)  # Cv^-1 F^T, meridian
    p, r, s = a * Y[0] + b * Y[2], a * Y[1] + b * Y[3], c * Y[1] + d * Y[3]  # Be_tr = F Cv^-1 F^T
    mu1, mu2, c2, s2, rad = meridian_eigen(p, s, r)
    mu = np.stack([mu1, mu2, f * f * TT])
    det_m = RR * ZZ - RZ * RZ
    rate = network.flow.rate_factor((RR + ZZ) / det_m + 1.0 / TT, a_T if network.flow.shift else 1.0)
    rate = np.broadcast_to(rate, a.shape)
    e, t, K, jac = solve_local(
        principal_function(network.law, network.scale), 0.5 * np.log(mu), rate, network.flow.m, dt
    )
    j2 = a * d - b * c
    Gi = (d / j2, -c / j2, -b / j2, a / j2)  # F^-T of the meridian block, rows r, z; columns R, Z
    trial = elastic_state(np.exp(2.0 * e), c2, s2, Gi, f)
    # the isotropic function tau(Be_tr): dt_i/dmu_j and the weight of the axes' rotation
    G = (K[:, :, None] * inverse3(jac)[None]).sum(1) / (2.0 * mu[None])
    gap = rad > DEGENERATE * mu1
    ratio = np.where(gap, (t[0] - t[1]) / np.where(gap, mu1 - mu2, 1.0), 0.5 * (G[0, 0] - G[0, 1] + G[1, 1] - G[1, 0]))
    tau = meridian_tensor(t[0], t[1], c2, s2) + (t[2],)
    P = np.stack(piola(tau, Gi, f))
    A = np.empty((5, 5, xt.shape[1]))
    zero = np.zeros_like(a)
    directions = (  # dBe_tr (p, s, r, hoop) along each component of x
        (2.0 * Y[0], zero, Y[1], zero),
        (2.0 * Y[2], zero, Y[3], zero),
        (zero, 2.0 * Y[1], Y[0], zero),
        (zero, 2.0 * Y[3], Y[2], zero),
        (zero, zero, zero, 2.0 * f * TT),
    )
    for k, (dp, ds, dr, dh) in enumerate(directions):
        dm, dd = 0.5 * (dp + ds), 0.5 * (dp - ds)
        drad = c2 * dd + s2 * dr
        w = c2 * dr - s2 * dd  # rad d(2 phi)
        dmu = (dm + drad, dm - drad, dh)
        dt_ = [G[i, 0] * dmu[0] + G[i, 1] * dmu[1] + G[i, 2] * dmu[2] for i in range(3)]
        dmean, dhalf = 0.5 * (dt_[0] + dt_[1]), 0.5 * (dt_[0] - dt_[1])
        dtau = (
            dmean + dhalf * c2 - ratio * w * s2,
            dmean - dhalf * c2 + ratio * w * s2,
            dhalf * s2 + ratio * w * c2,
            dt_[2],
        )
        A[:, k] = np.stack(piola(dtau, Gi, f)) + piola_geometric(tau, Gi, f, k)
    return P, A, trial


def meridian_tensor(t1: np.ndarray, t2: np.ndarray, c2: np.ndarray, s2: np.ndarray) -> tuple[np.ndarray, ...]:
    """(rr, zz, rz) of the symmetric tensor with principal values t1, t2 on the axes (c2, s2)."""
    mean, half = 0.5 * (t1 + t2), 0.5 * (t1 - t2)
    return mean + half * c2, mean - half * c2, half * s2


def piola(tau: tuple, Gi: tuple, f: np.ndarray) -> tuple[np.ndarray, ...]:
    """P = tau F^-T (5 rows) from tau (rr, zz, rz, tt) and Gi = F^-T (rR, rZ, zR, zZ)."""
    rr, zz, rz, tt = tau
    return (
        rr * Gi[0] + rz * Gi[2],
        rr * Gi[1] + rz * Gi[3],
        rz * Gi[0] + zz * Gi[2],
        rz * Gi[1] + zz * Gi[3],
        tt / f,
    )


def piola_geometric(tau: tuple, Gi: tuple, f: np.ndarray, k: int) -> np.ndarray:
    """tau d(F^-T) (5, n) along the component k of x: d(F^-T) = -F^-T dF^T F^-T."""
    if k == 4:
        out = np.zeros((5, f.size))
        out[4] = -tau[3] / (f * f)
        return out
    alpha, beta = divmod(k, 2)  # dF = e_alpha e_beta^T (rows r, z; columns R, Z)
    G = ((Gi[0], Gi[1]), (Gi[2], Gi[3]))
    dG = [[-G[j][beta] * G[alpha][K] for K in range(2)] for j in range(2)]
    rr, zz, rz, _ = tau
    tm = ((rr, rz), (rz, zz))
    out = np.zeros((5, f.size))
    for i in range(2):
        for K in range(2):
            out[2 * i + K] = tm[i][0] * dG[0][K] + tm[i][1] * dG[1][K]
    return out


def elastic_state(be: np.ndarray, c2: np.ndarray, s2: np.ndarray, Gi: tuple, f: np.ndarray) -> np.ndarray:
    """Cv^-1 = F^-1 Be F^-T (4, n) (RR, RZ, ZZ, TT) from the principal values be (3, n) of Be
    on the axes (c2, s2) and the hoop, Gi = F^-T."""
    rr, zz, rz = meridian_tensor(be[0], be[1], c2, s2)
    # F^-1 Be F^-T: (F^-1)_Ri = Gi[i, R]
    g = ((Gi[0], Gi[1]), (Gi[2], Gi[3]))  # g[i][K] = (F^-T)_iK
    B = ((rr, rz), (rz, zz))
    out = np.empty((4, f.size))
    for n_, (K, L) in enumerate(((0, 0), (0, 1), (1, 1))):
        out[n_] = sum(g[i][K] * B[i][j] * g[j][L] for i in range(2) for j in range(2))
    out[3] = be[2] / (f * f)
    return out
