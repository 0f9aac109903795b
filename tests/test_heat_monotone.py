"""The discrete maximum principle of the heat scheme (fem.heat): no point warmer
than the warmest initial or boundary temperature, none colder than the coldest, on coarse and
fine meshes of thin walls (elements far from square), Q4 and Q8, straight and skewed, with
films and a mould, over steps much shorter than an element's diffusion time (where a
consistent capacity, or the full bilinear conduction of a long element, overshoots)."""

import numpy as np
import pytest
import scipy.sparse as sp

from axiform import rectangle, select_edges
from axiform.fem.elements import Q4, gauss_quad, jacobian
from axiform.fem.heat import Conductance, Conduction, Film, constant

K, RHO, C = 0.16, 1.05e-9, 1.9e9  # polystyrene in mm, t, s: a diffusivity of 0.08 mm^2/s
MESHES = [(25, 2), (100, 2), (10, 4), (50, 8), (200, 16)]


def sheet(divisions, element, skew=0.0):
    """A sheet r 0..50, z 0.5..2.5 (a thin wall), its nodes moved by z skew r / 50 (the
    elements then lean, their corners no longer square)."""
    mesh = rectangle((0.0, 50.0), (0.5, 2.5), divisions, element)
    mesh.points[:, 1] += skew * mesh.points[:, 0] / 50.0 * (mesh.points[:, 1] - 0.5) / 2.0
    return mesh


def cooled(mesh, mould=40.0, ambient=25.0, h_mould=2.0):
    """The sheet on a mould (a conductance through its lower face where r < 20) with a film
    on its upper face."""
    below = np.flatnonzero((np.abs(mesh.points[:, 1] - 0.5) < 1e-9) & (mesh.points[:, 0] < 20.0))
    area = 2.0 * np.pi * (mesh.points[below, 0] + 0.1) * 0.5

    film = Film(select_edges(mesh, {"set": "top"}), 1e-3, lambda t: ambient)
    touch = Conductance(h_mould, lambda t: mould, lambda state: (below, area))
    return Conduction(mesh, constant(K), constant(RHO), constant(C), [film], [touch])


def extremes(conduction, T, dt, steps):
    """The largest and smallest temperature over `steps` backward Euler steps of dt."""
    high, low = T.max(), T.min()
    x = conduction.mesh.points
    for k in range(steps):
        T = conduction.step(T, dt, x, (k + 1) * dt)
        high, low = max(high, T.max()), min(low, T.min())
    return high, low


@pytest.mark.parametrize("element", ["q4", "q8", "sfr"])
@pytest.mark.parametrize("divisions", MESHES)
@pytest.mark.parametrize("skew", [0.0, 1.5])
def test_a_sheet_on_a_cold_mould_stays_between_its_temperatures(element, divisions, skew):
    """A 150 C sheet on a 40 C mould under a 25 C film: every node between 25 and 150 at
    every step (to round-off), steps of 0.01 s (an element of 0.25 mm takes 0.8 s to
    diffuse)."""
    conduction = cooled(sheet(divisions, element, skew))
    high, low = extremes(conduction, np.full(conduction.n, 150.0), 0.01, 40)
    assert high <= 150.0 * (1 + 1e-12) and low >= 25.0 * (1 - 1e-12)
    assert low < 149.0  # it did cool


@pytest.mark.parametrize("element", ["q4", "q8"])
def test_a_hot_film_on_a_graded_field_makes_no_new_extremes(element):
    """An initial field from 100 to 160 along r, a 200 C film on part of the top face and a
    60 C mould below: between 60 and 200 at every step, also on a deformed configuration."""
    mesh = sheet((40, 4), element, skew=0.8)
    T0 = 100.0 + 60.0 * mesh.points[:, 0] / 50.0
    film = Film(select_edges(mesh, {"set": "top"})[:10], 5e-3, lambda t: 200.0)
    below = np.flatnonzero(np.abs(mesh.points[:, 1] - 0.5) < 1e-9)
    touch = Conductance(1.0, lambda t: 60.0, lambda state: (below, np.full(below.size, 0.3)))
    conduction = Conduction(mesh, constant(K), constant(RHO), constant(C), [film], [touch])
    x = mesh.points * [1.4, 0.6]  # stretched and thinned
    T, high, low = T0.copy(), T0.max(), T0.min()
    for k in range(30):
        T = conduction.step(T, 0.005 * (k + 1), x, 0.0)
        high, low = max(high, T.max()), min(low, T.min())
    assert high <= 200.0 * (1 + 1e-12) and low >= 60.0 * (1 - 1e-12)


@pytest.mark.parametrize("element", ["q4", "q8"])
@pytest.mark.parametrize("skew", [0.0, 1.5])
def test_the_conduction_matrix_has_no_positive_coupling_and_rows_summing_to_zero(element, skew):
    """K (n, n): no positive entry off the diagonal (an M-matrix with the capacity), rows
    summing to zero (a uniform field conducts nothing), symmetric."""
    mesh = sheet((25, 2), element, skew)
    conduction = cooled(mesh)
    Km = conduction.conduction(mesh.points, np.full(mesh.n_nodes, 150.0)).toarray()
    off = Km - np.diag(np.diag(Km))
    scale = np.abs(Km).max()
    assert off.max() <= 0.0
    assert np.abs(Km.sum(axis=1)).max() < 1e-12 * scale
    assert np.abs(Km - Km.T).max() < 1e-12 * scale


def full_bilinear(mesh, x):
    """The full (consistent) bilinear conduction matrix int k grad N . grad N^T dv (n, n)."""
    xi, w = gauss_quad(2)
    _, dNdx, detj, xq = jacobian(Q4, x[mesh.cells], xi)
    Ke = np.einsum("eq,eqid,eqjd->eij", K * 2 * np.pi * xq[..., 0] * detj * w, dNdx, dNdx)
    rows, cols = np.repeat(mesh.cells, 4, axis=1).ravel(), np.tile(mesh.cells, (1, 4)).ravel()
    return sp.csr_matrix((Ke.ravel(), (rows, cols)), shape=(mesh.n_nodes,) * 2)


def test_a_field_along_one_direction_of_rectangles_is_conducted_as_by_the_full_matrix():
    """On rectangles of aspect ratio 2.5 (the full K has positive couplings there) a field
    that varies along r only, or along z only, gives K T as the full bilinear K does: no
    artificial conduction in the direction of the flow."""
    mesh = rectangle((10.0, 60.0), (0.0, 2.0), (20, 4), "q4")
    conduction = cooled(mesh)
    lumped = conduction.conduction(mesh.points, np.zeros(mesh.n_nodes))
    full = full_bilinear(mesh, mesh.points)
    assert full.max() > 0  # positive couplings in the full matrix
    for field in (mesh.points[:, 1] ** 2, np.log(mesh.points[:, 0]), mesh.points[:, 0] ** 3):
        scale = (abs(full) @ np.abs(field)).max()  # the size of the terms summed
        assert np.abs(lumped @ field - full @ field).max() < 1e-13 * scale


@pytest.mark.slow
def test_the_cup_on_its_cold_mould_stays_between_the_oven_and_the_mould():
    """examples/cup_cold_mould.toml cut down (25 x 2 elements of 2 x 1 mm, 30 nominal steps,
    the plug's first 0.3 s: the flange touches the 60 C mould from 0.1 s): at every step
    every node between 60 and 150 C (it reached 165.6 C on the full run with the consistent
    capacity and the full bilinear conduction)."""
    import tomllib
    from pathlib import Path

    from axiform import solve
    from axiform.case.schema import build, parse

    examples = Path(__file__).resolve().parents[1] / "examples"
    data = tomllib.loads((examples / "cup_cold_mould.toml").read_text())
    data["mesh"]["divisions"] = [25, 2]
    data["solver"] |= {"steps": 15, "target": 0.3}
    built = build(parse(data), examples)
    seen = []
    result = solve(
        built.model,
        built.control,
        built.options,
        on_step=lambda s: seen.append((s.state.temperature.min(), s.state.temperature.max())),
    )
    assert result.status == "finished", result.message
    low, high = min(lo for lo, _ in seen), max(hi for _, hi in seen)
    assert 60.0 <= low < 140.0 and high <= 150.0 * (1 + 1e-12)
