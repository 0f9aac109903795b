"""Mixed u-p-J_bar elements: the thick sphere against the 1D solution of the same law at
kappa/mu = 1e3 and 1e4 (where the displacement Q4 and SFR lock), the choice of the pressure
space, the tangent of every pressure space, and the pressure field."""

import functools

import numpy as np
import pytest
from conftest import difference_tangent, distorted_rectangle
from oracles import SphereBVP

from axiform import LoadControl, Model, MooneyRivlin, select_edges, select_nodes, solve
from axiform.fem.mesh import layered
from axiform.fem.profile import Arc, Profile
from axiform.post.fields import point_fields

A, B, C1, C2, P = 1.0, 1.5, 0.4, 0.1, 0.35  # the sphere of the locking report
MU = 2.0 * (C1 + C2)


@functools.cache
def exact_bore(kappa_over_mu: float) -> float:
    return SphereBVP(MooneyRivlin(C1, C2, kappa_over_mu * MU), A, B).bore_displacement(P, 0.18)


def sphere_bore(element: str, kappa_over_mu: float, formulation: str, pressure_space=None) -> float:
    """A quarter meridian section, layered 16 x 4 along the mid-surface arc: uz = 0 on z = 0,
    ur = 0 on r = 0, follower pressure on the bore; u_r of the bore at z = 0."""
    profile = Profile(((A + B) / 2, 0.0), (Arc((0.0, 0.0), (0.0, (A + B) / 2), 16, True),))
    mesh = layered(profile, B - A, 4, element)
    model = Model(
        mesh, MooneyRivlin(C1, C2, kappa_over_mu * MU), formulation=formulation, pressure_space=pressure_space
    )
    model.fix(select_nodes(mesh, {"set": "start"}), ["uz"])
    model.fix(select_nodes(mesh, {"set": "end"}), ["ur"])
    model.pressure(select_edges(mesh, {"set": "inner"}), P)
    model = model.finalize()
    res = solve(model, LoadControl(1.0, 5))
    assert res.status == "finished", res.message
    node = select_nodes(mesh, {"set": "inner", "z": 0.0})
    return float(res.last.u[model.dof(node, "ur")][0])


@pytest.mark.parametrize("kappa_over_mu", [1e3, 1e4])
def test_thick_sphere_mixed_within_half_a_percent(element, kappa_over_mu):
    """Measured bore errors: Q4 and SFR (P0) -0.395 %, Q8 (P1) +0.001 %, at both kappa/mu."""
    err = sphere_bore(element, kappa_over_mu, "mixed") / exact_bore(kappa_over_mu) - 1
    assert abs(err) < 5e-3, err


def test_thick_sphere_displacement_elements_lock():
    """The paper's elements on the same mesh: Q4 and SFR -79 % at kappa/mu = 1e3 and -98 % at
    1e4 (measured -79.3 %, -97.7 %); the 'displacement' formulation is kept as it was."""
    for kappa_over_mu, bound in ((1e3, -0.7), (1e4, -0.95)):
        for element in ("q4", "sfr"):
            err = sphere_bore(element, kappa_over_mu, "displacement") / exact_bore(kappa_over_mu) - 1
            assert err < bound, (element, kappa_over_mu, err)


def test_sfr_pressure_space_p0_not_p1():
    """Why SFR ships P0: with P1 (three pressure modes on 2x2 Gauss points) it still locks
    (measured at kappa/mu = 1e3 between -21.7 % and -79.3 % depending on the load steps: the
    converged state itself depends on the path, a sign of a badly conditioned element), with
    P0 it is within 0.4 % whatever the steps."""
    exact = exact_bore(1e3)
    assert abs(sphere_bore("sfr", 1e3, "mixed", "p0") / exact - 1) < 5e-3
    assert sphere_bore("sfr", 1e3, "mixed", "p1") / exact - 1 < -0.1


@pytest.mark.parametrize("element,space", [("q4", "p1"), ("q8", "p0"), ("sfr", "p1")])
def test_tangent_of_the_other_pressure_spaces(element, space):
    """The default spaces are checked in test_elements; the others against differences too."""
    from axiform.materials import MooneyRivlin as MR

    mesh = distorted_rectangle((0.3, 2.0), (0.0, 1.0), (3, 3), element, 0.25, seed=11)
    model = Model(mesh, MR(0.4, 0.1, 50.0), formulation="mixed", pressure_space=space)
    model.fix(select_nodes(mesh, {"z": 0.0}), ["uz"])
    model.pressure(select_edges(mesh, {"r": 0.3}), 0.7)
    model = model.finalize()
    u_f = 0.02 * np.random.default_rng(3).standard_normal(model.n_free)
    K = model.evaluate(u_f, 1.1).K.toarray()
    num, _ = difference_tangent(model, u_f, 1.1, 1e-6)
    assert np.abs(K - num).max() < 1e-6 * np.abs(K).max()


def test_pressure_field_of_a_uniform_compression(element, formulation):
    """F = (1 + a) I: the isochoric stress vanishes and p = -tr(sigma)/3 = -kappa (J - 1)."""
    kappa = 50.0
    mesh = distorted_rectangle((0.5, 2.0), (0.0, 1.0), (3, 3), element, 0.2, seed=2)
    model = Model(mesh, MooneyRivlin(0.4, 0.1, kappa), formulation=formulation).finalize()
    a = -0.05
    u = np.zeros((mesh.n_nodes, model.dpn))
    u[:, :2] = a * mesh.points
    fields = point_fields(model, u.ravel())
    expected = -kappa * ((1 + a) ** 3 - 1)
    assert fields["hydrostatic_pressure"] == pytest.approx(np.full(mesh.n_nodes, expected), rel=1e-10)


HYDROSTATIC_BLOCK = """
[mesh]
kind = "rectangle"
r = [0.0, 1.0]
z = [0.0, 1.0]
divisions = [2, 2]
element = "{element}"
formulation = "{formulation}"
[material]
model = "mooney-rivlin"
C1 = 1.0
C2 = 0.5
kappa = 100.0
[[fix]]
at = {{ r = 0.0 }}
dofs = ["ur"]
[[fix]]
at = {{ z = 0.0 }}
dofs = ["uz"]
[[pressure]]
on = {{ r = 1.0 }}
value = 5.0
[[pressure]]
on = {{ z = 1.0 }}
value = 5.0
[solver]
steps = 2
[output]
plots = false
"""


def test_the_vtu_files_hold_the_pressure_field(element, formulation, tmp_path):
    """A block under the same follower pressure on every face: sigma = -5 I, so the VTU point
    data `pressure` (the name the outputs' contract fixes, beside `hydrostatic_pressure`) is 5
    at every node, for every element and formulation."""
    import meshio

    from axiform.cli import main

    case = tmp_path / "block.toml"
    case.write_text(HYDROSTATIC_BLOCK.format(element=element, formulation=formulation))
    assert main(["run", str(case), "--out", str(tmp_path / "out"), "-q"]) == 0
    data = meshio.read(sorted((tmp_path / "out" / "fields").glob("*.vtu"))[-1]).point_data
    assert data["pressure"] == pytest.approx(np.full(len(data["pressure"]), 5.0), rel=1e-8)
    assert np.array_equal(data["pressure"], data["hydrostatic_pressure"])
