"""Every element: patch tests (homogeneous deformation with hoop stretch, distorted meshes),
the tangent (material and follower pressure) against a difference of the residual, and
quadratic convergence of Newton."""

import numpy as np
import pytest
from conftest import clamped_plate, difference_tangent, distorted_rectangle

from axiform import DisplacementControl, Model, MooneyRivlin, rectangle, select_edges, select_nodes, solve
from axiform.materials import InvertedElementError
from axiform.solve.solver import LoadControl, NewtonOptions

LAW = MooneyRivlin(0.4, 0.1, 5.0)


def homogeneous(points, a=0.3, d=-0.2, w0=0.05):
    """U = a R, W = d Z + w0: F = diag(1+a, 1+a, 1+d) in (r, theta, z), hoop stretch 1+a."""
    return np.column_stack([a * points[:, 0], d * points[:, 1] + w0])


def full_vector(model, uw):
    u = np.zeros((model.mesh.n_nodes, model.dpn))
    u[:, :2] = uw
    return u.ravel()


@pytest.mark.parametrize("distortion", [0.0, 0.3])
def test_patch_residual_vanishes_inside(element, formulation, distortion):
    mesh = distorted_rectangle((0.5, 2.0), (0.0, 1.0), (4, 4), element, distortion, seed=3)
    model = Model(mesh, LAW, formulation=formulation).finalize()
    u = full_vector(model, homogeneous(mesh.points))
    fe, _ = model.solid.evaluate(u, tangent=False)
    f = np.bincount(model.solid.dofs.ravel(), weights=fe.ravel(), minlength=model.n_full).reshape(-1, model.dpn)
    inside = np.setdiff1d(np.arange(mesh.n_nodes), np.unique(mesh.boundary_edges))
    scale = np.abs(f).max()
    assert scale > 1e-3  # the boundary carries the traction of the homogeneous stress
    assert np.abs(f[inside]).max() < 1e-10 * scale
    # the stress is the same at every quadrature point
    x = model.solid.gradient(u)
    assert np.allclose(x, [1.3, 0, 0, 0.8, 1.3], atol=1e-12)


def test_patch_solved_with_boundary_prescribed(element, formulation):
    """Boundary displacements prescribed from the homogeneous field, interior solved by Newton:
    the interior nodes land exactly on the field (SFR: with zero fibre rotations)."""
    mesh = distorted_rectangle((0.5, 2.0), (0.0, 1.0), (4, 4), element, 0.3, seed=4)
    model = Model(mesh, LAW, formulation=formulation)
    boundary = np.unique(mesh.boundary_edges)
    exact = homogeneous(mesh.points)
    for n in boundary:
        model.prescribe([n], ["ur"], exact[n, 0])
        model.prescribe([n], ["uz"], exact[n, 1])
    model = model.finalize()
    res = solve(model, LoadControl(1.0, 4), NewtonOptions(tolerance=1e-12))
    assert res.status == "finished"
    u = res.last.u.reshape(-1, model.dpn)
    assert np.abs(u[:, :2] - exact).max() < 1e-10
    if model.dpn == 3:
        assert np.abs(u[:, 2] - u[0, 2]).max() < 1e-10  # theta uniform: no displacement


def test_rigid_axial_translation_is_force_free(element, formulation):
    mesh = distorted_rectangle((0.0, 2.0), (0.0, 1.0), (3, 3), element, 0.2, seed=5)
    model = Model(mesh, LAW, formulation=formulation).finalize()
    u = full_vector(model, np.column_stack([np.zeros(mesh.n_nodes), 0.7 * np.ones(mesh.n_nodes)]))
    fe, _ = model.solid.evaluate(u, tangent=False)
    assert np.abs(fe).max() < 1e-12


def _pressure_model(element, seed, formulation="mixed"):
    mesh = distorted_rectangle((0.3, 2.0), (0.0, 1.0), (3, 3), element, 0.25, seed=seed)
    model = Model(mesh, LAW, formulation=formulation)
    model.fix(select_nodes(mesh, {"z": 0.0}), ["uz"])
    model.pressure(select_edges(mesh, {"r": 0.3}), 0.7)
    model.pressure(select_edges(mesh, {"z": 1.0}), -0.3)
    return model.finalize()


def test_tangent_matches_difference_of_residual(element, formulation):
    """K = dR/du (material + follower pressure) against a central difference of R."""
    model = _pressure_model(element, seed=6, formulation=formulation)
    rng = np.random.default_rng(7)
    u_f = 0.02 * rng.standard_normal(model.n_free)
    lam = 1.3
    ev = model.evaluate(u_f, lam)
    K = ev.K.toarray()
    num, dl = difference_tangent(model, u_f, lam, 1e-6)
    assert np.abs(K - num).max() < 1e-6 * np.abs(K).max()
    assert np.abs(K - K.T).max() > 1e-6 * np.abs(K).max()  # the pressure makes it non-symmetric
    assert np.allclose(ev.dr_dlam, dl, atol=1e-7 * np.abs(dl).max())


def test_pressure_resultant_is_pressure_times_projected_area(element):
    """On the deformed top face z = h of a disc, the axial resultant of p is -p pi r_out^2."""
    mesh = rectangle((0.0, 2.0), (0.0, 0.5), (4, 2), element)
    model = Model(mesh, LAW)
    model.pressure(select_edges(mesh, {"z": 0.5}), 1.0)
    model = model.finalize()
    u = full_vector(model, homogeneous(mesh.points, a=0.2, d=0.1))
    f, _ = model.external_load(u, 1.0)
    fz = f.reshape(-1, model.dpn)[:, 1].sum()
    assert fz == pytest.approx(-np.pi * (2.0 * 1.2) ** 2, rel=1e-12)


def test_newton_converges_quadratically(element, formulation):
    """Large-strain inflation of the clamped plate, 1 in of centre deflection per step.  With
    e_k = r_k / r_1 the residual relative to the first iteration's, quadratic convergence means
    the number of digits doubles: log e_(k+1) / log e_k -> 2 (linear convergence gives -> 1)."""
    model = clamped_plate(element, formulation)
    c = int(model.dof(select_nodes(model.mesh, {"r": 0.0, "z": 0.5})[0], "uz"))
    res = solve(model, DisplacementControl(c, 6.0, 6))
    assert res.status == "finished"
    assert res.last.u[c] == pytest.approx(6.0)
    rates = []
    for s in res.steps:
        e = np.array(s.residuals[1:]) / s.residuals[1]  # residuals[0]: before the first solve
        print(s.number, " ".join(f"{v:.1e}" for v in e))
        if len(e) >= 3:
            rates.append(np.log(e[-1]) / np.log(e[-2]))
    print("rates", np.round(rates, 2))
    assert len(rates) >= 6
    assert np.median(rates) > 1.7 and min(rates) > 1.4


def test_inverted_state_is_refused():
    mesh = rectangle((0.0, 1.0), (0.0, 1.0), (2, 2), "q4")
    model = Model(mesh, LAW).finalize()
    u = full_vector(model, np.column_stack([np.zeros(mesh.n_nodes), -2.0 * mesh.points[:, 1]]))
    with pytest.raises(InvertedElementError):
        model.solid.evaluate(u)


def test_sfr_zero_mode_removed_on_every_body():
    """Two separate SFR bodies: each has its own uniform-theta mode; the model fixes one theta
    on each, and the supported tangent is regular."""
    from axiform.fem.mesh import Mesh

    a = rectangle((0.0, 1.0), (0.0, 1.0), (2, 2), "sfr")
    b = rectangle((2.0, 3.0), (0.0, 1.0), (2, 2), "sfr")
    mesh = Mesh(np.vstack([a.points, b.points]), np.vstack([a.cells, b.cells + a.n_nodes]), a.element)
    model = Model(mesh, LAW)
    model.fix(select_nodes(mesh, {"z": 0.0}), ["ur", "uz"])
    model = model.finalize()
    assert len(model.dofmap.prescribed_ref) == 2 * 6 + 2  # ur, uz on 6 base nodes, one theta per body
    K = model.evaluate(np.zeros(model.n_free), 0.0).K.toarray()
    s = np.linalg.svd(K, compute_uv=False)
    assert s[-1] > 1e-10 * s[0]
