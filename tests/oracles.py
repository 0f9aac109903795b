"""Reference solutions (oracles) for the tests, independent of the finite element code.

Thick-walled cylinder r in [A, B] in plane strain (axial stretch 1) under internal pressure:

- `lame_plane_strain`: small-strain (Lame) radial displacement.
- `incompressible_cylinder_pressure`: exact large-strain pressure of an incompressible
  Mooney-Rivlin tube.
- `RadialBVP`: the compressible law *exactly as implemented* (axiform.materials), reduced to
  the 1D radial boundary-value problem and solved with scipy's solve_bvp.  Only the
  constitutive routine is shared with the code under test; kinematics, equilibrium, boundary
  conditions and the discretization are independent.

Viscoelasticity (a Prony series on the isochoric 2nd Piola-Kirchhoff stress, docs/internals.md:
Time, temperature and heat), with Mooney-Rivlin written anew in principal stretches
(`mooney_rivlin_iso_pk2`) and the history integrated by scipy, no code of axiform used:

- `uniaxial_prony`: a homogeneous compressible bar stretched along z, lateral faces free.
- `PronySphere`: an incompressible thick sphere (one Gauss point: the thin membrane), its
  pressure under a prescribed bore radius, the bore at a pressure, and its creep.
"""

from __future__ import annotations

import numpy as np
from scipy.integrate import solve_bvp


def linear_constants(C1: float, C2: float, kappa: float) -> tuple[float, float]:
    """Young's modulus and Poisson's ratio of the linearized law (mu = 2 (C1 + C2), K = kappa)."""
    mu = 2.0 * (C1 + C2)
    E = 9.0 * kappa * mu / (3.0 * kappa + mu)
    nu = (3.0 * kappa - 2.0 * mu) / (2.0 * (3.0 * kappa + mu))
    return E, nu


def lame_plane_strain(r, A: float, B: float, p: float, E: float, nu: float):
    """Radial displacement of a plane-strain thick cylinder under internal pressure p:
    sigma_rr = k1 - k2 / r^2 with k1 = p A^2 / (B^2 - A^2), k2 = k1 B^2, and
    u(r) = (1 + nu) / E [ (1 - 2 nu) k1 r + k2 / r ]."""
    r = np.asarray(r, dtype=float)
    k1 = p * A**2 / (B**2 - A**2)
    k2 = k1 * B**2
    return (1.0 + nu) / E * ((1.0 - 2.0 * nu) * k1 * r + k2 / r)


def incompressible_cylinder_pressure(a, A: float, B: float, C1: float, C2: float):
    """Internal pressure that opens an incompressible Mooney-Rivlin tube (plane strain) from
    inner radius A to a: c = a^2 - A^2, b^2 = B^2 + c,
    p = (C1 + C2) [ ln(B^2 a^2 / (b^2 A^2)) + c (1/a^2 - 1/b^2) ]."""
    a = np.asarray(a, dtype=float)
    c = a**2 - A**2
    b2 = B**2 + c
    return (C1 + C2) * (np.log(B**2 * a**2 / (b2 * A**2)) + c * (1.0 / a**2 - 1.0 / b2))


def incompressible_by_quadrature(a: float, A: float, B: float, C1: float, C2: float) -> float:
    """The same pressure from the radial equilibrium integral p = int_a^b (s_tt - s_rr)/r dr
    (plane strain, incompressible, hoop stretch l = r/R, W_eff = (C1 + C2)(l^2 + l^-2 - 2)):
    s_tt - s_rr = 2 (C1 + C2) (l^2 - l^-2).  Checks the closed form above."""
    from scipy.integrate import quad

    c = a**2 - A**2
    b = np.sqrt(B**2 + c)

    def integrand(r):
        R = np.sqrt(r**2 - c)
        lam = r / R
        return 2.0 * (C1 + C2) * (lam**2 - lam**-2) / r

    val, _ = quad(integrand, a, b, epsabs=0.0, epsrel=1e-13)
    return val


class RadialBVP:
    """Plane-strain radial problem of a compressible law given as a `material` object with
    `stress_tangent(x)`, x = (F_rR, F_rZ, F_zR, F_zZ, F_tT) = (1 + u', 0, 0, 1, 1 + u/R).

    Equilibrium in the reference configuration: dP_rR/dR + (P_rR - P_tT)/R = 0, written as a
    second-order ODE for u(R) with dP_rR/dR = A_rr u'' + A_rt (u'/R - u/R^2).
    Boundary conditions: u(A) = a - A, P_rR(B) = 0.  Pressure p = -P_rR(A) A / a.
    """

    def __init__(self, material, A: float, B: float, tol: float = 1e-8, nodes: int = 41):
        self.material = material
        self.A, self.B = A, B
        self.tol = tol
        self.nodes = nodes

    def _x(self, R, u, du):
        x = np.zeros(np.shape(R) + (5,))
        x[..., 0] = 1.0 + du
        x[..., 3] = 1.0
        x[..., 4] = 1.0 + u / R
        return x

    def _rhs(self, R, y):
        u, du = y
        P, Am = self.material.stress_tangent(self._x(R, u, du))
        # dP_rR/dR = A_00 u'' + A_04 d(u/R)/dR = -(P_rR - P_tT)/R
        d2u = (-(P[..., 0] - P[..., 4]) / R - Am[..., 0, 4] * (du - u / R) / R) / Am[..., 0, 0]
        return np.vstack([du, d2u])

    def _P(self, R, u, du):
        return self.material.stress_tangent(self._x(np.asarray(R), np.asarray(u), np.asarray(du)))[0]

    def solve(self, a: float):
        """Solve for inner radius a; returns (p, sol) with sol the scipy result.  Each call
        starts afresh from the guess u = (a - A) A / R on a uniform mesh, so results do not
        depend on the order of calls.  Raises if solve_bvp did not converge."""
        ua = a - self.A
        R = np.linspace(self.A, self.B, self.nodes)
        guess = np.vstack([ua * self.A / R, -ua * self.A / R**2])

        def bc(ya, yb):
            return np.array([ya[0] - ua, self._P(self.B, yb[0], yb[1])[0]])

        sol = solve_bvp(self._rhs, bc, R, guess, tol=self.tol, max_nodes=100000)
        if sol.status != 0:
            raise RuntimeError(f"solve_bvp did not converge at a = {a}: {sol.message}")
        P_A = self._P(self.A, sol.y[0, 0], sol.y[1, 0])[0]
        return -P_A * self.A / a, sol

    def pressures(self, a_values) -> np.ndarray:
        """p at each inner radius."""
        return np.array([self.solve(a)[0] for a in np.ravel(a_values)])


class SphereBVP:
    """Thick sphere R in [A, B] under internal follower pressure p, the compressible law
    exactly as implemented, reduced to the 1D radial problem (solve_bvp).  Principal stretches
    (1 + u', 1 + u/R, 1 + u/R) are put in x = (F_rR, F_rZ, F_zR, F_zZ, F_tT) as
    (1 + u', 0, 0, 1 + u/R, 1 + u/R): the law is isotropic, so P_zZ = P_tT is the hoop stress.

    Equilibrium in the reference configuration: dP_R/dR + 2 (P_R - P_H)/R = 0 with
    dP_R/dR = A_RR u'' + (A_RZ + A_RT) d(u/R)/dR.  Boundary conditions: the follower pressure
    on the bore, P_R(A) = -p (a/A)^2 (Cauchy -p on the current area), and P_R(B) = 0."""

    def __init__(self, material, A: float, B: float, tol: float = 1e-9, nodes: int = 81):
        self.material, self.A, self.B, self.tol, self.nodes = material, A, B, tol, nodes

    def _x(self, R, u, du):
        x = np.zeros(np.shape(R) + (5,))
        x[..., 0] = 1.0 + du
        x[..., 3] = 1.0 + u / R
        x[..., 4] = 1.0 + u / R
        return x

    def _rhs(self, R, y):
        u, du = y
        P, Am = self.material.stress_tangent(self._x(R, u, du))
        d2u = (-2.0 * (P[..., 0] - P[..., 4]) / R - (Am[..., 0, 3] + Am[..., 0, 4]) * (du - u / R) / R) / Am[..., 0, 0]
        return np.vstack([du, d2u])

    def bore_displacement(self, p: float, guess: float = 0.0) -> float:
        """u(A) at internal pressure p."""
        R = np.linspace(self.A, self.B, self.nodes)
        y0 = np.vstack([guess * (self.A / R) ** 2, -2 * guess * self.A**2 / R**3])

        def P_R(R, u, du):
            return self.material.stress_tangent(self._x(np.asarray(R, float), np.asarray(u), np.asarray(du)))[0][..., 0]

        def bc(ya, yb):
            a = self.A + ya[0]
            return np.array([P_R(self.A, ya[0], ya[1]) + p * (a / self.A) ** 2, P_R(self.B, yb[0], yb[1])])

        sol = solve_bvp(self._rhs, bc, R, y0, tol=self.tol, max_nodes=200000)
        if sol.status != 0:
            raise RuntimeError(f"solve_bvp did not converge at p = {p}: {sol.message}")
        return float(sol.y[0, 0])


def mooney_rivlin_iso_pk2(stretches, C1: float, C2: float) -> np.ndarray:
    """Principal isochoric 2nd Piola-Kirchhoff stresses S_a (..., 3) of Mooney-Rivlin,
    W_iso = C1 (I1_bar - 3) + C2 (I2_bar - 3), at principal stretches (..., 3), written in
    principal stretches (not as the code writes it): with lbar_a = J^(-1/3) lambda_a and
    w_a = lbar_a dW_iso/dlbar_a = 2 C1 lbar_a^2 - 2 C2 lbar_a^-2 (I2_bar = sum lbar_a^-2 on
    det = 1), the Kirchhoff stress tau_a = w_a - mean(w), and S_a = tau_a / lambda_a^2."""
    lam = np.asarray(stretches, float)
    bar = lam / np.cbrt(lam.prod(-1))[..., None]
    w = 2.0 * C1 * bar**2 - 2.0 * C2 * bar**-2
    return (w - w.mean(-1, keepdims=True)) / lam**2


def uniaxial_prony(stretch, times, C1: float, C2: float, kappa: float, g, tau, rtol: float = 1e-12):
    """Nominal stress P_zz (n,) and lateral stretch (n,) at `times` (n,) of a homogeneous bar
    of compressible Mooney-Rivlin (kappa/2 (J - 1)^2) with a Prony series (g_i, tau_i) on
    its isochoric 2nd Piola-Kirchhoff stress, stretched along z as stretch(t) (a function,
    stretch(0) = 1), its lateral faces free.

    The history h_i (rr = tt and zz components; the tensor, not the uniaxial stress) obeys
    dh_i/dt = (g_i S_iso - h_i) / tau_i, integrated with scipy (DOP853, rtol); at every time
    the lateral stretch s makes S_rr = kappa (J - 1) J / s^2 + S_iso_rr - sum h_rr = 0 (J =
    s^2 lambda; brentq), and P_zz = lambda (kappa (J - 1) J / lambda^2 + S_iso_zz - sum h_zz)."""
    from scipy.integrate import solve_ivp
    from scipy.optimize import brentq

    g, tau = np.asarray(g, float), np.asarray(tau, float)

    def state(t, h):
        lam = stretch(t)
        hr, hz = h.reshape(2, -1).sum(-1)

        def S(s):
            J = s * s * lam
            iso = mooney_rivlin_iso_pk2(np.array([s, lam, s]), C1, C2)
            vol = kappa * (J - 1.0) * J
            return iso, vol / (s * s) + iso[0] - hr, vol / lam**2 + iso[1] - hz

        s = brentq(lambda s: S(s)[1], 0.5 / np.sqrt(lam), 2.0 / np.sqrt(lam), xtol=1e-15, rtol=1e-15)
        iso, _, Szz = S(s)
        return s, iso, lam * Szz

    def rate(t, h):
        iso = state(t, h)[1]
        return ((np.outer(iso[:2], g) - h.reshape(2, -1)) / tau).ravel()

    sol = solve_ivp(
        rate, (0.0, float(np.max(times))), np.zeros(2 * len(g)), method="DOP853", t_eval=times, rtol=rtol, atol=1e-14
    )
    if not sol.success:
        raise RuntimeError(sol.message)
    out = [state(t, h) for t, h in zip(sol.t, sol.y.T, strict=False)]
    return np.array([o[2] for o in out]), np.array([o[0] for o in out])


class PronySphere:
    """An incompressible thick sphere R in [A, B] of Mooney-Rivlin with a Prony series (g_i,
    tau_i) on its isochoric 2nd Piola-Kirchhoff stress, under internal pressure p.

    Incompressibility fixes the motion by the bore radius a: r^3 = R^3 + a^3 - A^3, hoop
    stretch l = r / R, radial 1 / l^2.  The history h_i (radial and hoop components) of a
    material point obeys dh_i/dt = (g_i S_iso - h_i) / tau_i; the pressure of the law's
    volumetric part cancels from sigma_hoop - sigma_rad = l^2 (S_iso - sum h)_hoop - l^-4
    (S_iso - sum h)_rad, and radial equilibrium gives p = int_A^B 2 (sigma_hoop - sigma_rad)
    / r (R^2 / r^2) dR, by Gauss-Legendre over `points` material points (1 point: the
    thin-membrane formula p = 2 (H / R) sigma / l^3 at the mid-surface)."""

    def __init__(self, A: float, B: float, C1: float, C2: float, g, tau, points: int = 8):
        self.A, self.C1, self.C2 = A, C1, C2
        self.g, self.tau = np.asarray(g, float), np.asarray(tau, float)
        x, w = np.polynomial.legendre.leggauss(points)
        self.R = A + (B - A) * (x + 1) / 2
        self.w = w * (B - A) / 2

    def _iso(self, a: float):
        """Hoop stretch l (q,), current radius r (q,) and S_iso (q, 2) (radial, hoop) at bore a."""
        r = np.cbrt(self.R**3 + a**3 - self.A**3)
        lam = r / self.R
        S = mooney_rivlin_iso_pk2(np.stack([lam**-2, lam, lam], -1), self.C1, self.C2)
        return lam, r, S[:, :2]

    def pressure(self, a: float, h: np.ndarray | None = None) -> float:
        """p at bore radius a with the summed history h (q, 2) (None: none, the elastic law)."""
        lam, r, S = self._iso(a)
        if h is not None:
            S = S - h
        diff = lam**2 * S[:, 1] - lam**-4 * S[:, 0]
        return float((self.w * 2.0 * diff / r * (self.R / r) ** 2).sum())

    def _rate(self, S: np.ndarray, h: np.ndarray) -> np.ndarray:
        return ((self.g * S[:, :, None] - h.reshape(S.shape + (-1,))) / self.tau).ravel()

    def _summed(self, h: np.ndarray) -> np.ndarray:
        return h.reshape(len(self.R), 2, -1).sum(-1)

    def inflation(self, bore, times, rtol: float = 1e-11) -> np.ndarray:
        """p (n,) at times (n,) with the bore radius a prescribed as bore(t), bore(0) = A."""
        from scipy.integrate import solve_ivp

        sol = solve_ivp(
            lambda t, h: self._rate(self._iso(bore(t))[2], h),
            (0.0, float(np.max(times))),
            np.zeros(2 * len(self.R) * len(self.g)),
            method="DOP853",
            t_eval=times,
            rtol=rtol,
            atol=1e-14,
            max_step=np.min(self.tau) / 4,
        )
        return np.array([self.pressure(bore(t), self._summed(h)) for t, h in zip(sol.t, sol.y.T, strict=False)])

    def bore(self, p: float, h: np.ndarray | None = None, scale: float = 1.0, bracket=None) -> float:
        """The bore radius a of the rising branch where scale x pressure(a, h) = p (scale: the
        law's moduli times it, e.g. the long-term 1 - sum g_i): in `bracket` if given, else the
        first root on a grid of steps A / 50 up to 3 A, refined by brentq."""
        from scipy.optimize import brentq

        def f(a):
            return scale * self.pressure(a, h) - p

        if bracket is not None:
            return brentq(f, *bracket, xtol=1e-14, rtol=1e-15)
        grid = self.A * (1.0 + np.arange(1, 101) / 50)
        above = np.nonzero([f(a) > 0 for a in grid])[0]
        if not len(above):
            raise ValueError(f"p = {p} is above the limit point")
        low = grid[above[0] - 1] if above[0] else self.A
        return brentq(f, low, grid[above[0]], xtol=1e-14, rtol=1e-15)

    def creep(self, p: float, times, rtol: float = 1e-11) -> np.ndarray:
        """The bore radius a (n,) at times (n,) under a pressure p applied at t = 0 and held:
        from the law's elastic bore to the long-term one (1 - sum g_i) x the law."""
        from scipy.integrate import solve_ivp

        ends = (self.bore(p), self.bore(p, scale=1.0 - self.g.sum()))
        bracket = (ends[0] - 1e-9 * self.A, ends[1] + 1e-9 * self.A)

        def rate(t, h):
            return self._rate(self._iso(self.bore(p, self._summed(h), bracket=bracket))[2], h)

        sol = solve_ivp(
            rate,
            (0.0, float(np.max(times))),
            np.zeros(2 * len(self.R) * len(self.g)),
            method="DOP853",
            t_eval=times,
            rtol=rtol,
            atol=1e-14,
        )
        return np.array([self.bore(p, self._summed(h), bracket=bracket) for h in sol.y.T])


def network_flow(mode: str, stretch, times, C1: float, C1n: float, flow, a_T: float = 1.0, kinks=()) -> np.ndarray:
    """Nominal stress along the stretch (n,) at `times` (n,) of an incompressible homogeneous
    test of a neo-Hooke equilibrium law (C1) and one neo-Hooke network (C1n) with Bergström and
    Boyce's flow (flow.A, C, m, E; the rate divided by a_T), stretched as stretch(t) (a function,
    stretch(0) = 1; `kinks`: the times where its rate jumps, integrated across apart).

    The viscous stretch lam_v obeys one ordinary differential equation, integrated by scipy to
    1e-10, no code of axiform used (l_e = lam / lam_v, the network's stress difference
    s = 2 C1n f(l_e), q = |s|, eps_dot = A (lam_chain - 1 + E)^C q^m / a_T):
    - uniaxial (lam along z): f(l) = l^2 - 1/l, d ln lam_v / dt = eps_dot sign(s),
      lam_chain = sqrt((lam_v^2 + 2/lam_v) / 3);
    - equibiaxial (lam along r and theta): f(l) = l^2 - l^-4, the flow direction (3/2) tau'/q
      has the in-plane component 1/2: d ln lam_v / dt = eps_dot sign(s) / 2,
      lam_chain = sqrt((2 lam_v^2 + lam_v^-4) / 3);
    P = (2 C1 f(lam) + 2 C1n f(l_e)) / lam."""
    from scipy.integrate import solve_ivp

    uniaxial = mode == "uniaxial"
    share = 1.0 if uniaxial else 0.5

    def f(lam):
        return lam * lam - (1.0 / lam if uniaxial else lam**-4)

    def chain(lam_v):
        return np.sqrt((lam_v**2 + 2.0 / lam_v) / 3.0 if uniaxial else (2.0 * lam_v**2 + lam_v**-4) / 3.0)

    def rate(t, y):
        lam_v = np.exp(y[0])
        s = 2.0 * C1n * f(stretch(t) / lam_v)
        eps = flow.A * (chain(lam_v) - 1.0 + flow.E) ** flow.C * abs(s) ** flow.m / a_T
        return [share * eps * np.sign(s)]

    times = np.asarray(times, float)
    bounds = [0.0, *sorted(k for k in kinks if 0.0 < k < times[-1]), times[-1]]
    y, start = np.zeros(times.shape), np.zeros(1)
    for a, b in zip(bounds, bounds[1:], strict=False):
        piece = solve_ivp(rate, (a, b), start, dense_output=True, method="LSODA", rtol=1e-10, atol=1e-12)
        inside = (times >= a) & (times <= b)
        y[inside] = piece.sol(times[inside])[0]
        start = piece.y[:, -1]
    lam = np.array([stretch(t) for t in times])
    return (2.0 * C1 * f(lam) + 2.0 * C1n * f(lam / np.exp(y))) / lam
