"""Gravity ([gravity], model.gravity.GravityTerm): the weight of the revolved body, and the
exact hanging bar of an incompressible neo-Hookean solid."""

import numpy as np
import pytest
from test_fuzz import toml
from test_fuzz_files import call

from axiform import Model, NeoHooke, rectangle, select_nodes
from axiform.case.schema import build, parse
from axiform.fem.curves import Curve
from axiform.model.gravity import GravityTerm
from axiform.model.protocol import EvaluationContext
from axiform.solve.solver import solve

MU, L, A = 1.0, 10.0, 0.25  # shear modulus, length and radius of the bar
TOP_STRETCH = 1.5
RHO_G = MU * (TOP_STRETCH - TOP_STRETCH**-2) / L  # the weight per unit volume that stretches the top so


def bar_case(element: str = "q8", divisions=(2, 80), steps: int = 10) -> dict:
    """A rod r < A, 0 < z < L, held at its top (uz) and on its axis (ur), hanging under its own
    weight (rho = 1, g = -RHO_G); mixed formulation, kappa / mu = 1e4."""
    return {
        "mesh": {"kind": "rectangle", "r": [0.0, A], "z": [0.0, L], "divisions": list(divisions), "element": element},
        "material": {"model": "neo-hooke", "C1": MU / 2, "kappa": 1e4 * MU, "density": 1.0},
        "gravity": {"g": -RHO_G},
        "fix": [{"at": {"z": L}, "dofs": ["uz"]}, {"at": {"r": 0.0}, "dofs": ["ur"]}],
        "solver": {"control": "load", "steps": steps},
    }


def exact_stretch(Z: float) -> float:
    """lambda at the height Z above the free end: mu (lambda - lambda^-2) = rho g Z."""
    s = RHO_G * Z / MU
    lam = 1.0 + s / 3.0
    for _ in range(50):  # Newton on lambda^3 - s lambda^2 - 1 = 0
        lam -= (lam**3 - s * lam**2 - 1.0) / (3 * lam**2 - 2 * s * lam)
    return lam


def exact_elongation() -> float:
    """The integral of (lambda - 1) over the bar's length: with dZ = mu (1 + 2 lambda^-3) /
    (rho g) dlambda, mu / (rho g) [lambda^2 / 2 - lambda - 2 / lambda + 1 / lambda^2] from 1 to
    the top's stretch."""

    def F(x):
        return x * x / 2 - x - 2 / x + 1 / x**2

    return MU / RHO_G * (F(TOP_STRETCH) - F(1.0))


@pytest.mark.parametrize("element", ["q4", "q8", "sfr"])
def test_the_weight_is_rho_g_times_the_revolved_volume(element):
    """The nodal forces add up to rho g pi (b^2 - a^2) h on the uz dofs, nothing on ur (or on
    an SFR's rotations); they follow their curve: f(t) F, rate f'(t) F, nothing where both
    are zero."""
    mesh = rectangle((0.5, 2.0), (0.0, 3.0), (3, 4), element)
    curve = Curve([(0.0, 0.0), (1.0, 0.0), (3.0, 1.0)])
    term = GravityTerm(mesh, -9.81, 2.5, curve)
    f = term.force.reshape(mesh.n_nodes, -1)
    assert f[:, 1].sum() == pytest.approx(-9.81 * 2.5 * np.pi * (2.0**2 - 0.5**2) * 3.0, rel=1e-12)
    assert not f[:, 0].any() and not f[:, 2:].any()
    part = term.evaluate(np.zeros(term.n_full), 2.0, None, EvaluationContext())
    assert np.array_equal(part.load, 0.5 * term.force) and np.array_equal(part.dr_dt, -0.5 * term.force)
    idle = term.evaluate(np.zeros(term.n_full), 0.5, None, EvaluationContext())  # f = f' = 0: nothing
    assert idle.r is None and idle.load is None


def test_a_hanging_bar_stretches_as_the_exact_solution():
    """The slender bar (L / a = 40) under its weight: at the height Z above its free end the
    nominal stress is rho g Z and mu (lambda - lambda^-2) = rho g Z (the top at lambda = 1.5).
    The elongation, the integral of lambda - 1 over Z, within 0.5 % of the exact one; the
    stretch at mid-height within 0.5 % (measured: 0.017 % and 0.002 %); the reaction at the top
    is the bar's weight."""
    built = build(parse(bar_case()))
    model = built.model
    res = solve(model, built.control, built.options)
    assert res.status == "finished", res.message
    u = res.last.u.reshape(-1, model.dpn)
    axis = select_nodes(model.mesh, {"r": 0.0})
    Z = model.mesh.points[axis, 1]
    order = np.argsort(Z)
    Z, uz = Z[order], u[axis[order], 1]
    elongation = uz[-1] - uz[0]  # the top held, the free end gone down
    assert elongation == pytest.approx(exact_elongation(), rel=5e-3)
    stretch = 1.0 + np.gradient(uz, Z)
    mid = np.argmin(np.abs(Z - L / 2))
    assert stretch[mid] == pytest.approx(exact_stretch(Z[mid]), rel=5e-3)
    top = model.dof(select_nodes(model.mesh, {"z": L}), "uz")
    # the weight less the residual left at the free dofs (Newton's tolerance, 1e-8 of the forces)
    assert res.last.r_full[top].sum() == pytest.approx(RHO_G * np.pi * A**2 * L, rel=1e-6)


def test_gravity_without_a_density_is_refused_naming_the_key(tmp_path):
    case = bar_case()
    del case["material"]["density"]
    path = tmp_path / "bar.toml"
    path.write_text(toml(case))
    code, out, err = call(["check", str(path)])
    assert code == 2 and "material.density" in err, err


def test_the_thermal_density_defaults_to_the_materials(tmp_path):
    """A [thermal] table without density takes the material's; without either, the error
    names thermal.density."""
    case = bar_case()
    case["temperature"] = {"initial": 20.0}
    case["thermal"] = {"conductivity": 0.2, "specific_heat": 1.9e8}
    assert build(parse(case)).model.conduction.rho(np.array([20.0]))[0] == 1.0
    del case["material"]["density"], case["gravity"]
    with pytest.raises(ValueError, match="thermal.density"):
        build(parse(case))


def test_the_model_keeps_its_weight_as_one_term():
    """Model.add takes the term as built; finalize puts it among the system's terms."""
    mesh = rectangle((0.0, 1.0), (0.0, 2.0), (2, 4), "q4")
    model = Model(mesh, NeoHooke(0.5, 100.0))
    model.fix(select_nodes(mesh, {"z": 2.0}), ["uz"])
    weight = GravityTerm(mesh, -1.0, 1.0)
    model.add(weight)
    system = model.finalize()
    assert weight in system.terms
    ev = system.evaluate(np.zeros(system.n_free), 1.0)
    assert np.array_equal(ev.f_ext_full, weight.force)
