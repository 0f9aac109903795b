"""Quasi-linear viscoelasticity (materials.viscoelastic): a Prony series on the isochoric
stress of a law, its history per quadrature point committed with converged steps."""

import numpy as np
import pytest
from conftest import RELAXING_BAR

from axiform import LoadControl, Model, NeoHooke, NewtonOptions, rectangle, select_nodes, solve
from axiform.fem.curves import Curve
from axiform.materials.viscoelastic import Prony, Viscoelastic

PRONY = Prony((0.4, 0.3), (0.05, 0.5))
RAMP = 1e-6  # the step of strain takes this long (2e-5 of the shortest relaxation time)
CUTS = NewtonOptions(min_step=1e-9)  # steps may be cut back within the ramp


def bar(material, element: str, formulation: str, stretch: float = 1.3) -> tuple[Model, np.ndarray]:
    """A homogeneous bar (r 0..1, z 0..1) stretched to `stretch` along z in RAMP, then held to
    t = 1: the axis and the bottom held, the lateral face free."""
    mesh = rectangle((0.0, 1.0), (0.0, 1.0), (2, 2), element)
    model = Model(mesh, material, formulation=formulation)
    model.fix(select_nodes(mesh, {"r": 0.0}), ["ur"])
    model.fix(select_nodes(mesh, {"z": 0.0}), ["uz"])
    top = select_nodes(mesh, {"z": 1.0})
    ramp = [[RAMP * k / 8, k / 8] for k in range(9)]  # in 8 steps: the curve's knots
    model.prescribe(top, ["uz"], stretch - 1.0, Curve(ramp + [[1.0, 1.0]]))
    return model.finalize(), model.dof(top, "uz")


@pytest.mark.parametrize(
    "element, formulation", [("q4", "displacement"), ("q8", "mixed"), ("sfr", "mixed"), ("q4", "mixed")]
)
def test_a_step_of_stretch_relaxes_as_the_prony_series(element, formulation):
    """The force on the bar's end after a step of stretch: F(t) = F_elastic g(t), g(t) = 1 -
    sum g_i (1 - exp(-t / tau_i)), within 0.1 % at every step (kappa / mu = 1e4), whatever
    the step: the update is exact while the stretch is held."""
    law = NeoHooke(0.5, 1.0e4)
    elastic_model, top = bar(law, element, formulation)
    elastic = solve(elastic_model, LoadControl(1.0, 4), CUTS)
    F0 = elastic.last.r_full[top].sum()
    model, top = bar(Viscoelastic(law, PRONY), element, formulation)
    forces, times = [], []

    def record(step):
        forces.append(step.r_full[top].sum())
        times.append(step.lam)

    res = solve(model, LoadControl(1.0, 20), CUTS, on_step=record)
    assert res.status == "finished", res.message
    times, forces = np.array(times), np.array(forces)
    held = times >= RAMP * (1 - 1e-9)
    times, forces = times[held], forces[held]
    assert times[0] == pytest.approx(RAMP) and len(times) >= 10
    assert F0 > 0.5  # the stretch is a large one
    assert np.abs(forces / (F0 * PRONY.relaxation(times)) - 1).max() < 1e-3
    assert forces[-1] / F0 < 0.4  # relaxed towards the long-term 1 - 0.7


@pytest.mark.parametrize("element, formulation", [("q8", "mixed"), ("q4", "displacement"), ("sfr", "mixed")])
def test_the_tangent_matches_differences_of_the_residual(element, formulation):
    """From a committed state with history (two steps of a ramp), at a perturbed state later
    in time: the tangent against central differences of the residual."""
    from conftest import difference_tangent

    model, top = bar(Viscoelastic(NeoHooke(0.5, 50.0), PRONY), element, formulation)
    res = solve(model, LoadControl(0.1, 2), CUTS)
    held = res.last.state
    assert np.abs(model.solid_state(held)["h"]).max() > 0
    u_f = res.last.u_f + 1e-3 * np.random.default_rng(5).standard_normal(model.n_free)
    t = res.last.lam + 0.03
    ev = model.evaluate(u_f, t, held)
    K = ev.K.toarray()
    num, _ = difference_tangent(model, u_f, t, 1e-6, held)
    assert np.abs(K - num).max() < 1e-6 * np.abs(K).max()


def test_checkpoints_carry_the_history():
    model, _ = bar(Viscoelastic(NeoHooke(0.5, 1.0e3), PRONY), "q4", "mixed")
    res = solve(model, LoadControl(0.2, 4), CUTS)
    again = model.restore(res.last.state.to_dict())
    for key, value in model.solid_state(res.last.state).items():
        assert np.array_equal(model.solid_state(again)[key], value)


CASE = RELAXING_BAR


@pytest.mark.parametrize(
    "edit, message",
    [
        (("g = [0.4, 0.3]", "g = [0.7, 0.4]"), "material.viscoelastic: .*sum < 1"),
        (("tau = [0.05, 0.5]", "tau = [0.05, -0.5]"), "material.viscoelastic: .*tau_i > 0"),
        (("g = [0.4, 0.3]", "g = [0.4]"), "material.viscoelastic: .*as many g as tau"),
        (("steps = 10", 'steps = 10\ncontrol = "arc-length"'), "solver.control: .*viscoelastic"),
    ],
)
def test_a_bad_series_or_control_is_refused_naming_the_key(tmp_path, capsys, edit, message):
    import re

    from axiform.cli import main

    case = tmp_path / "bar.toml"
    case.write_text(CASE.replace(*edit))
    assert main(["check", str(case)]) == 2
    assert re.search(message, capsys.readouterr().err)


def test_the_written_stress_relaxes(tmp_path):
    """The VTU stress of the last step is the relaxed one (the history subtracted): von Mises
    at t = 1 over that of the first step near g(1) / g(0.001)."""
    import meshio

    from axiform.cli import main

    case = tmp_path / "bar.toml"
    case.write_text(CASE)
    out = tmp_path / "out"
    assert main(["run", str(case), "--out", str(out), "-q", "--set", "output.plots=false"]) == 0
    steps = sorted((out / "fields").glob("step_*.vtu"))
    first, last = (meshio.read(f).point_data["von_mises"].mean() for f in (steps[0], steps[-1]))
    assert last / first == pytest.approx(PRONY.relaxation(1.0) / PRONY.relaxation(0.001), rel=2e-2)


def test_max_dt_caps_every_step(tmp_path):
    """[solver] max_dt: no step of the process longer than it (the steps would grow to 0.1)."""
    import tomllib

    from axiform.case.schema import build, parse

    data = tomllib.loads(CASE)
    data["solver"]["max_dt"] = 0.03
    built = build(parse(data))
    res = solve(built.model, built.control, built.options)
    assert res.status == "finished"
    times = np.array([0.0] + [s.lam for s in res.steps])
    assert np.diff(times).max() <= 0.03 * (1 + 1e-12) and res.n_steps >= 1 / 0.03
    data["solver"]["control"] = "arc-length"
    with pytest.raises(Exception, match="max_dt"):
        parse(data)
