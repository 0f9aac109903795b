"""Networks in parallel (parallel.NetworkLaw) along homogeneous incompressible tests at constant
stretch rates, and their constants fitted to such curves (`axiform fit --model network`).

A curve: a mode (uniaxial: F = diag(lambda, lambda^-1/2, lambda^-1/2); equibiaxial: F =
diag(lambda, lambda, lambda^-2)), the engineering stretch rate dlambda/dt > 0 from lambda = 1
at t = 0, the temperature (or none), and the nominal stress at increasing stretches.  The
material is incompressible: F is known, and the pressure follows from the free (last)
direction, so the nominal stress is (tau_1 - tau_3) / lambda, tau the Kirchhoff stress, the sum
of the equilibrium law's (homogeneous.nominal, no history) and each network's.

Each network is integrated along the curve by its own local update (network.solve_local, the
exponential map in the principal logarithmic strains, which is the whole update when F is
diagonal and its axes fixed): per step, e_tr = ln(lambda_i) - ln(lambda_v,i) of the step's
start, the rate factor dt A (lambda_v - 1 + E)^C / a_T of the step's start, then
ln(lambda_v,i) = ln(lambda_i) - e_i.  A test checks it against NetworkLaw.update.  Everything
is vectorized over "points": the curves times the parameter sets of a difference Jacobian (the
rate factor carries each point's dt, A, C and a_T, the elastic part's scale its mu); the
points of one stress exponent m share a call.  The scheme is first order in the step (the
hardening factor lags a step); two grids (K and 2K steps, each holding every data stretch) and
Richardson's extrapolation 2 S_2K - S_K make it second order.

The fit: scipy.optimize.least_squares on the errors of every point divided by the peak stress
of its curve and the square root of the curve's point count (each curve weighs the same),
over the log of the positive constants (the equilibrium law's linear constants, each network's
mu, A), C in [-1, 0], m in [1, M_MAX], and with temperatures the WLF C1 (log) and C2 (above
the data's pole); E fixed.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, replace

import numpy as np
from scipy.optimize import least_squares

from .base import Hyperelastic
from .homogeneous import Data, kinematics, nominal
from .neo_hooke import NeoHooke
from .network import TY, TZ, BergstromBoyce, LocalUpdateError, Network, Y, Z, solve_local
from .parallel import NetworkLaw
from .principal import BASIS, SQRT2, SQRT6, plane_function, plane_strains
from .registry import FitFamily
from .temperature import WLF

MODES = ("uniaxial", "equibiaxial")
STEPS = 40  # steps of the coarse grid of a curve (the fine one has twice as many)
M_MAX = 20.0  # the largest stress exponent m tried
UNIT_NETWORK = NeoHooke(0.5, 0.0)  # shear modulus 1: a network's elastic part, scaled by its mu
MAX_EVALUATIONS = 100  # of the residuals per start (each Jacobian one more)
FAILED = 1e3  # the residual of a point whose update did not converge (a relative error)


@dataclass
class Curves:
    """Test curves: per curve (c,) its mode (index into MODES), rate and temperature (None:
    no temperature); per point (n,) its curve, stretch and nominal stress, the points of a
    curve in increasing stretch."""

    mode: np.ndarray
    rate: np.ndarray
    temperature: np.ndarray | None
    curve: np.ndarray
    stretch: np.ndarray
    stress: np.ndarray

    @property
    def count(self) -> int:
        return len(self.rate)

    def x(self) -> np.ndarray:
        """F components (n, 5) of every point's incompressible test (homogeneous.kinematics)."""
        x = np.empty((len(self.stretch), 5))
        for i, mode in enumerate(MODES):
            sel = self.mode[self.curve] == i
            x[sel] = kinematics(mode, self.stretch[sel])
        return x

    def data(self) -> Data:
        """The points as the hyperelastic fit's test data (homogeneous.Data; the mode indices agree)."""
        return Data(self.mode[self.curve], self.stretch, self.stress)

    def curve_points(self, curves: np.ndarray) -> np.ndarray:
        """The points (indices) of the curves where `curves` (c,) is True."""
        return np.flatnonzero(curves[self.curve])

    def peak(self) -> np.ndarray:
        """The largest |stress| of each curve (c,)."""
        return np.array([np.abs(self.stress[self.curve == c]).max() for c in range(self.count)])


def log_stretches(mode: np.ndarray, lam: np.ndarray) -> np.ndarray:
    """Principal log stretches (3, ...) of the tests of modes (...) (index into MODES) at
    stretches lam (...): loading, the other in-plane direction, the free direction."""
    e = np.log(lam)
    biaxial = mode == 1
    return np.stack([e, np.where(biaxial, e, -0.5 * e), np.where(biaxial, -2.0 * e, -0.5 * e)])


def grid(curves: Curves, steps: int = STEPS) -> tuple[np.ndarray, np.ndarray]:
    """The stretch path (K + 1, c) of every curve from 1 holding each of its data stretches,
    K = max(steps, most points of a curve), the steps uniform in u = sqrt(lambda - 1) (fine
    where the network first loads and starts to flow) spread over the data intervals in
    proportion to their length in u; and the step index (n,) of each point."""
    counts = np.bincount(curves.curve, minlength=curves.count)
    K = max(steps, int(counts.max()))
    path = np.empty((K + 1, curves.count))
    at = np.empty(len(curves.stretch), int)
    for c in range(curves.count):
        sel = np.flatnonzero(curves.curve == c)
        knots = np.sqrt(np.concatenate([[1.0], curves.stretch[sel]]) - 1.0)  # u = sqrt(lambda - 1)
        d = np.diff(knots)
        n = np.maximum(1, np.round(K * d / d.sum()).astype(int))
        while n.sum() > K:
            n[np.argmax(np.where(n > 1, n, 0))] -= 1
        while n.sum() < K:
            n[np.argmax(d / n)] += 1
        ends = np.cumsum(n)
        at[sel] = ends
        path[0, c] = 1.0
        for j in range(len(d)):
            k0 = ends[j] - n[j]
            path[k0 + 1 : ends[j] + 1, c] = 1.0 + (knots[j] + d[j] * np.arange(1, n[j] + 1) / n[j]) ** 2
        path[ends, c] = curves.stretch[sel]  # exactly
    return path, at


def integrate(
    path: np.ndarray, mode: np.ndarray, time_scale: np.ndarray, mu: np.ndarray, C: np.ndarray, m: np.ndarray, E: float
) -> np.ndarray:
    """The nominal stress (K + 1, b) of one viscous network (neo-Hooke elastic part of shear
    modulus mu (b,), Bergström-Boyce flow of exponents C, m (b,), offset E) at the stretches
    path (K + 1, b) of tests of mode (b,); time_scale (b,) = A / (a_T rate): the rate factor
    of a step dlambda is dlambda time_scale (lambda_v - 1 + E)^C.  LocalUpdateError where a
    local update fails."""
    b = path.shape[1]
    lnv = np.zeros((3, b))  # ln lambda_v
    out = np.zeros_like(path)
    groups = [(float(v), np.flatnonzero(m == v)) for v in np.unique(m)]
    plane = plane_function(UNIT_NETWORK)
    scaled = time_scale * mu**m  # tau = mu tau_1(e): the local equation of the unit network, rate x mu^m
    for k in range(1, path.shape[0]):
        L = log_stretches(mode, path[k])
        lam_v = np.sqrt(np.exp(2.0 * lnv).sum(0) / 3.0)
        rate = (path[k] - path[k - 1]) * scaled * (lam_v - 1.0 + E) ** C
        w_tr = BASIS.T @ (L - lnv)  # the trial elastic log strains on the deviatoric plane (2, b)
        for v, idx in groups:
            X = solve_local(plane, w_tr[0, idx], w_tr[1, idx], rate[idx], v, 1.0)
            lnv[:, idx] = L[:, idx] - plane_strains(X[Y], X[Z])
            t_diff = X[TY] / SQRT2 + 3.0 * X[TZ] / SQRT6  # t_1 - t_3 of t = t_y u_y + t_z u_z
            out[k, idx] = mu[idx] * t_diff / path[k, idx]
    return out


@dataclass(frozen=True)
class Layout:
    """Where each constant sits in the fitted vector theta: the equilibrium law's linear
    constants (log where "positive") and nonlinear ones, then per network log mu, log A, C, m,
    then (with temperatures) log C1 and C2 of WLF at `reference`."""

    family: FitFamily
    networks: int
    E: float
    reference: float | None
    wlf: bool

    @property
    def n_eq(self) -> int:
        return len(self.family.linear) + len(self.family.nonlinear)

    @property
    def size(self) -> int:
        return self.n_eq + 4 * self.networks + (2 if self.wlf else 0)

    def constants(self, theta: np.ndarray) -> np.ndarray:
        """The equilibrium law's constants (linear, then nonlinear) of theta, as FitFamily.make takes them."""
        n = len(self.family.linear)
        lin = np.where(np.array(self.family.linear_sign) == "positive", np.exp(theta[:n]), theta[:n])
        return np.concatenate([lin, theta[n : self.n_eq]])

    def equilibrium(self, theta: np.ndarray) -> Hyperelastic:
        """The equilibrium law (kappa = 1) of theta."""
        p = self.constants(theta)
        n = len(self.family.linear)
        return self.family.make(p[:n], p[n:])

    def network(self, theta: np.ndarray, k: int) -> tuple[float, float, float, float]:
        """(mu, A, C, m) of network k."""
        lmu, lA, C, m = theta[self.n_eq + 4 * k : self.n_eq + 4 * k + 4]
        return float(np.exp(lmu)), float(np.exp(lA)), float(C), float(m)

    def shift(self, theta: np.ndarray) -> WLF | None:
        if not self.wlf:
            return None
        assert self.reference is not None
        return WLF(float(np.exp(theta[-2])), float(theta[-1]), self.reference)

    def law(self, theta: np.ndarray, kappa: float) -> NetworkLaw:
        """The fitted law: the equilibrium law with bulk modulus kappa, the networks, the shift."""
        eq = replace(self.equilibrium(theta), kappa=kappa)  # type: ignore[type-var]
        networks = []
        for k in range(self.networks):
            mu, A, C, m = self.network(theta, k)
            networks.append(Network(NeoHooke(mu / 2.0, 0.0), BergstromBoyce(A, C, m, self.E)))
        return NetworkLaw(eq, networks, shift=self.shift(theta))


def model_stress(layout: Layout, thetas: np.ndarray, curves: Curves, grids: list[tuple]) -> np.ndarray:
    """The model's nominal stress (s, n) at the data points for each parameter set thetas (s, p);
    grids: (path (K + 1, c), at (n,), weight) of the step sizes combined (Richardson).
    TemperatureDomainError where a set's WLF pole is at or above a curve's temperature."""
    s, c = len(thetas), curves.count
    x = curves.x()
    out = np.array([nominal(layout.equilibrium(th), x) for th in thetas])
    a_T = np.ones((s, c))
    for j, th in enumerate(thetas):
        shift = layout.shift(th)
        if shift is not None and curves.temperature is not None:
            a_T[j] = shift.shift(curves.temperature)
    for k in range(layout.networks):
        # the sets that differ only in other constants give this network the same stress: each
        # distinct (mu, A, C, m, a_T) is integrated once
        own = np.column_stack([[layout.network(th, k) for th in thetas], a_T])
        unique, back = np.unique(own, axis=0, return_inverse=True)
        u = len(unique)
        mu, A, C, m = (np.repeat(unique[:, i], c) for i in range(4))
        scale = A / (unique[:, 4:].ravel() * np.tile(curves.rate, u))
        for path, at, weight in grids:
            S = integrate(np.tile(path, (1, u)), np.tile(curves.mode, u), scale, mu, C, m, layout.E)
            out += weight * S[at[None, :], curves.curve[None, :] + c * np.ravel(back)[:, None]]
    return out


def richardson(curves: Curves, steps: int = STEPS) -> list[tuple]:
    """The grids of model_stress: K steps (weight -1) and 2K (each step halved, weight 2)."""
    path, at = grid(curves, steps)
    fine = np.empty((2 * path.shape[0] - 1, path.shape[1]))
    fine[::2] = path
    fine[1::2] = 0.5 * (path[1:] + path[:-1])
    return [(path, at, -1.0), (fine, 2 * at, 2.0)]


@dataclass
class NetworkFit:
    """A fit: theta, its layout, the relative errors per point (n,) (by the curve's peak), the
    RMS of each curve (c,), the least-squares cost."""

    layout: Layout
    theta: np.ndarray
    error: np.ndarray
    rms: np.ndarray
    cost: float


def fit_networks(
    curves: Curves, layout: Layout, starts: list[np.ndarray], bounds: tuple[np.ndarray, np.ndarray], steps: int = STEPS
) -> NetworkFit:
    """Least squares from each start (module docstring); the best fit."""
    grids = richardson(curves, steps)
    peak = curves.peak()
    counts = np.bincount(curves.curve, minlength=curves.count)
    w = 1.0 / (peak[curves.curve] * np.sqrt(counts[curves.curve]))

    def residuals(thetas: np.ndarray) -> np.ndarray:
        with np.errstate(over="ignore", invalid="ignore", divide="ignore"):
            try:
                r = (model_stress(layout, thetas, curves, grids) - curves.stress) * w
            except LocalUpdateError:
                return np.full((len(thetas), len(w)), FAILED)
        return np.nan_to_num(r, nan=FAILED, posinf=FAILED, neginf=-FAILED)

    fun, jac = difference_jacobian(residuals, bounds)
    best = None
    for theta0 in starts:
        sol = least_squares(
            fun, np.clip(theta0, *bounds), jac=jac, bounds=bounds, x_scale="jac", max_nfev=MAX_EVALUATIONS
        )
        if best is None or sol.cost < best.cost:
            best = sol
    assert best is not None, "at least one start"
    error = (model_stress(layout, best.x[None], curves, grids)[0] - curves.stress) / peak[curves.curve]
    rms = np.array([np.sqrt(np.mean(error[curves.curve == c] ** 2)) for c in range(curves.count)])
    return NetworkFit(layout, best.x, error, rms, float(best.cost))


def difference_jacobian(
    residuals: Callable[[np.ndarray], np.ndarray], bounds: tuple[np.ndarray, np.ndarray], h: float = 1e-6
) -> tuple[Callable, Callable]:
    """fun(theta) -> r (n,) and jac(theta) -> (n, p) by forward differences, the p + 1 parameter
    sets evaluated in one batch (a step backward where forward leaves the bounds)."""

    def fun(theta: np.ndarray) -> np.ndarray:
        return residuals(theta[None])[0]

    def jac(theta: np.ndarray) -> np.ndarray:
        step = h * np.maximum(1.0, np.abs(theta))
        step = np.where(theta + step > bounds[1], -step, step)
        thetas = theta[None] + np.vstack([np.zeros_like(theta), np.diag(step)])
        r = residuals(thetas)
        return ((r[1:] - r[0]) / step[:, None]).T

    return fun, jac


def linear_fit(family: FitFamily, curves: Curves, sel: np.ndarray, b: np.ndarray) -> np.ndarray:
    """The equilibrium law's linear constants (least squares, sign-bounded) that best give the
    stresses of the points `sel` alone at the nonlinear constants b."""
    from scipy.optimize import lsq_linear

    x = curves.x()[sel]
    n = len(family.linear)
    basis = np.stack([nominal(family.make(e, b), x) for e in np.eye(n)], axis=1)
    lower = np.array([0.0 if s != "free" else -np.inf for s in family.linear_sign])
    return lsq_linear(basis, curves.stress[sel], bounds=(lower, np.full(n, np.inf))).x


def effective_rates(curves: Curves, shift: WLF | None) -> np.ndarray:
    """Each curve's rate times a_T (c,): the rate the networks feel at the reference."""
    if shift is None or curves.temperature is None:
        return curves.rate.copy()
    return curves.rate * shift.shift(curves.temperature)


def starts_and_bounds(
    curves: Curves, layout: Layout, exponents: tuple[float, ...] = (2.0, 5.0)
) -> tuple[list[np.ndarray], tuple[np.ndarray, np.ndarray]]:
    """Starting vectors (one per stress exponent in `exponents`) and the bounds of theta.
    The equilibrium law: half of its fit to the slowest curves; the networks share what the
    fastest curves add to it; A such that the typical overstress q of the middle curves flows at
    their rate; WLF: the universal C1 = 17.44, C2 = 51.6 (C2 beyond the data's pole)."""
    fam = layout.family
    T = curves.temperature
    wlf0 = None
    if layout.wlf:
        assert T is not None and layout.reference is not None
        wlf0 = WLF(17.44, max(51.6, 2.0 * (layout.reference - T.min()) + 10.0), layout.reference)
    rates = effective_rates(curves, wlf0)
    slow, fast = curves.curve_points(rates <= rates.min() * 1.0001), curves.curve_points(rates >= rates.max() / 1.0001)
    data = curves.data()
    nl_starts = fam.nonlinear_starts(data)
    b0 = np.asarray(nl_starts[len(nl_starts) // 2], float)
    eq_slow = linear_fit(fam, curves, slow, b0)
    eq_fast = linear_fit(fam, curves, fast, b0)
    lin0 = 0.5 * eq_slow
    mu_eq = fam.make(lin0, b0).shear_modulus
    mu_n = max(fam.make(eq_fast, b0).shear_modulus - mu_eq, 0.5 * mu_eq) / layout.networks
    order = np.argsort(rates)
    middle = curves.curve_points(np.isin(np.arange(curves.count), order[len(order) // 2]))
    x = curves.x()[middle]
    over = np.abs(curves.stress[middle] - nominal(fam.make(lin0, b0), x)) * curves.stretch[middle]
    q0 = max(float(np.median(over)), 1e-3 * float(np.abs(curves.stress).max()))
    rate0 = float(np.median(rates))
    positive = np.array(fam.linear_sign) == "positive"
    eq_theta = np.concatenate([np.where(positive, np.log(np.maximum(lin0, 1e-12)), lin0), b0])
    starts = []
    for m in exponents:
        theta = list(eq_theta)
        for k in range(layout.networks):
            A = rate0 / (q0**m * 0.3**-0.5) * 10.0 ** (2.0 * (k - (layout.networks - 1) / 2.0))
            theta += [np.log(mu_n), np.log(A), -0.5, m]
        if wlf0 is not None:
            theta += [np.log(wlf0.C1), wlf0.C2]
        starts.append(np.array(theta))
    peak = float(np.abs(curves.stress).max())
    n_lin = len(fam.linear)
    lo_eq = np.where(positive, np.log(peak) - 30.0, np.where(np.array(fam.linear_sign) == "free", -np.inf, 0.0))
    nl_lo, nl_hi = fam.nonlinear_bounds(data)
    lo = [*lo_eq, *nl_lo]
    hi = [*np.where(positive, np.log(peak) + 10.0, np.inf), *nl_hi]
    lA = [float(s[n_lin + len(b0) + 1]) for s in starts]
    for _ in range(layout.networks):
        lo += [np.log(peak) - 30.0, min(lA) - 60.0, -1.0, 1.0]
        hi += [np.log(peak) + 10.0, max(lA) + 60.0, 0.0, M_MAX]
    if wlf0 is not None:
        assert T is not None and layout.reference is not None
        lo += [np.log(0.1), layout.reference - T.min() + 1e-3 * max(float(np.ptp(T)), 1.0)]
        hi += [np.log(1e3), 1e4]
    return starts, (np.array(lo, float), np.array(hi, float))
