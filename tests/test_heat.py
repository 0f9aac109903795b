"""Transient conduction (fem.heat, docs/internals.md: Time, temperature and heat) against exact
answers: a slab with a film on one face (series solution, several Biot numbers), an annulus with a film outside (Bessel
series), the energy balance of a step."""

import numpy as np
import pytest
from scipy import integrate, optimize, special

from axiform import rectangle, select_edges
from axiform.fem.heat import Conduction, Film, constant

K, RHO, C = 0.2, 1.0e-9, 1.9e9  # W/(mm K), t/mm^3, mJ/(t K): diffusivity 0.105 mm^2/s
ALPHA = K / (RHO * C)


def slab_series(z: np.ndarray, fo: float, bi: float, terms: int = 60) -> np.ndarray:
    """(T - T_inf) / (T0 - T_inf) in a slab 0 < z < L insulated at z = 0 with a film at z = L:
    sum C_n exp(-zeta_n^2 Fo) cos(zeta_n z / L), zeta tan zeta = Bi, z given as z / L."""
    out = np.zeros_like(z)
    for n in range(terms):
        zeta = optimize.brentq(lambda s: s * np.tan(s) - bi, n * np.pi + 1e-12, n * np.pi + np.pi / 2 - 1e-12)
        out += 4 * np.sin(zeta) / (2 * zeta + np.sin(2 * zeta)) * np.exp(-(zeta**2) * fo) * np.cos(zeta * z)
    return out


def run(conduction, T0: float, t_end: float, steps: int, x=None) -> np.ndarray:
    T = np.full(conduction.n, T0)
    x = conduction.mesh.points if x is None else x
    for k in range(steps):
        T = conduction.step(T, t_end / steps, x, (k + 1) * t_end / steps)
    return T


@pytest.mark.parametrize("bi", [0.5, 2.0, 10.0])
@pytest.mark.parametrize("element", ["q4", "q8"])
def test_a_slab_cooled_by_a_film_follows_the_series(bi, element):
    """A wall of thickness L = 2 (r 10..11, insulated but at z = L): within 0.5 % of
    T0 - T_inf at Fo = 0.2 and 0.5 (the axisymmetric weights drop out of a flow along z)."""
    L, T0, T_inf = 2.0, 150.0, 25.0
    mesh = rectangle((10.0, 11.0), (0.0, L), (1, 24), element)
    film = Film(select_edges(mesh, {"z": L}), bi * K / L, lambda t: T_inf)
    conduction = Conduction(mesh, constant(K), constant(RHO), constant(C), [film])
    z = mesh.points[:, 1] / L
    for fo in (0.2, 0.5):
        T = run(conduction, T0, fo * L**2 / ALPHA, 200)
        exact = T_inf + (T0 - T_inf) * slab_series(z, fo, bi)
        assert np.abs(T - exact).max() < 5e-3 * (T0 - T_inf)


def annulus_series(r: np.ndarray, t: float, a: float, b: float, h: float, terms: int = 30) -> np.ndarray:
    """(T - T_inf) / (T0 - T_inf) in a long annulus a < r < b insulated at a, film h at b:
    eigenfunctions R(r) = J0(l r) Y1(l a) - Y0(l r) J1(l a) (R'(a) = 0) with -k R'(b) = h R(b),
    coefficients by orthogonality with the weight r."""

    def R(lam, r):
        return special.j0(lam * r) * special.y1(lam * a) - special.y0(lam * r) * special.j1(lam * a)

    def dR(lam, r):
        return -lam * (special.j1(lam * r) * special.y1(lam * a) - special.y1(lam * r) * special.j1(lam * a))

    def condition(lam):
        return K * dR(lam, b) + h * R(lam, b)

    grid = np.linspace(1e-6, 80.0 / (b - a), 20000)
    values = condition(grid)
    roots = [
        optimize.brentq(condition, lo, hi)
        for lo, hi, vl, vh in zip(grid, grid[1:], values, values[1:], strict=False)
        if vl * vh < 0
    ][:terms]
    out = np.zeros_like(r)
    for lam in roots:
        num = integrate.quad(lambda s, lam=lam: s * R(lam, s), a, b, limit=200)[0]
        den = integrate.quad(lambda s, lam=lam: s * R(lam, s) ** 2, a, b, limit=200)[0]
        out += num / den * R(lam, r) * np.exp(-ALPHA * lam**2 * t)
    return out


@pytest.mark.parametrize("element", ["q4", "q8"])
def test_an_annulus_cooled_outside_follows_the_bessel_series(element):
    """A long tube a = 2 < r < b = 6 (insulated inside, top and bottom; a film outside):
    the radial weights 2 pi r make it differ from a slab; within 0.5 % of T0 - T_inf at two
    times."""
    a, b, T0, T_inf, h = 2.0, 6.0, 150.0, 25.0, 0.1
    mesh = rectangle((a, b), (0.0, 1.0), (32, 1), element, wall="r")
    conduction = Conduction(
        mesh, constant(K), constant(RHO), constant(C), [Film(select_edges(mesh, {"r": b}), h, lambda t: T_inf)]
    )
    r = mesh.points[:, 0]
    for fo in (0.2, 0.5):
        t = fo * (b - a) ** 2 / ALPHA
        T = run(conduction, T0, t, 200)
        exact = T_inf + (T0 - T_inf) * annulus_series(r, t, a, b, h)
        assert np.abs(T - exact).max() < 5e-3 * (T0 - T_inf)


def test_a_step_stores_the_heat_that_crosses_the_boundary():
    """Backward Euler conserves heat exactly: C (T' - T) = dt (f - H T') summed over the
    nodes (conduction moves heat, it makes none), to 1e-8 of the heat exchanged, also on a
    deformed (current) configuration."""
    mesh = rectangle((1.0, 4.0), (0.0, 2.0), (6, 4), "q8")
    films = [
        Film(select_edges(mesh, {"z": 2.0}), 0.05, lambda t: 25.0),
        Film(select_edges(mesh, {"r": 1.0}), 0.02, lambda t: 200.0),
    ]
    conduction = Conduction(mesh, constant(K), constant(RHO), constant(C), films)
    rng = np.random.default_rng(2)
    T = 150.0 + 10.0 * rng.standard_normal(mesh.n_nodes)
    x = mesh.points * [1.3, 0.8] + 0.02 * rng.standard_normal(mesh.points.shape)
    dt = 5.0
    T1 = conduction.step(T, dt, x, dt)
    H, f = conduction.boundary(x, dt)
    stored = conduction.heat_content(T1) - conduction.heat_content(T)
    crossed = dt * (f - H @ T1).sum()
    assert abs(stored - crossed) < 1e-8 * abs(crossed)
    assert abs(crossed) > 0
