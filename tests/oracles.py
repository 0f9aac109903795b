"""Reference solutions (oracles) for the tests, independent of the finite element code.

Thick-walled cylinder r in [A, B] in plane strain (axial stretch 1) under internal pressure:

- `lame_plane_strain`: small-strain (Lame) radial displacement.
- `incompressible_cylinder_pressure`: exact large-strain pressure of an incompressible
  Mooney-Rivlin tube (DESIGN.md section 8).
- `RadialBVP`: the compressible law *exactly as implemented* (axiform.materials), reduced to
  the 1D radial boundary-value problem and solved with scipy's solve_bvp.  Only the
  constitutive routine is shared with the code under test; kinematics, equilibrium, boundary
  conditions and the discretization are independent.
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
