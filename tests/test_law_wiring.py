"""The solid knows a law only through its interface (materials.protocol): a law of viscous
networks in a model gives, on a homogeneous bar, the numbers of the law at a material point
(elements, mixed or not, and the pictures' stresses); a local update that fails cuts the step."""

import numpy as np
import pytest

from axiform import LoadControl, Model, NeoHooke, NewtonOptions, rectangle, select_nodes, solve
from axiform.fem.curves import Curve
from axiform.materials import LocalUpdateError, cauchy_stress
from axiform.materials.network import BergstromBoyce, Network
from axiform.materials.parallel import NetworkLaw
from axiform.post.fields import point_fields

LAW = NetworkLaw(NeoHooke(0.5, 50.0), [Network(NeoHooke(1.0, 0.0), BergstromBoyce(A=0.5, C=-0.7, m=3.0, E=0.01))])
STRETCH, STEPS, END = 1.8, 16, 1.6  # stretched at 0.5 / s, then held: it relaxes


def program(t):
    return 1.0 + (STRETCH - 1.0) * min(t, END / 2.0) / (END / 2.0)


def point(law, times):
    """The nominal stress P_zZ and x at a material point stretched along z by program(t),
    its lateral stress free (Newton on the lateral stretch with the update's tangent)."""
    state, a, t0, out = law.initial_state(()), 1.0, 0.0, []
    for t in times:
        lam = program(t)
        for _ in range(50):
            x = np.array([a, 0.0, 0.0, lam, a])
            P, A, trial = law.update(x, state, t - t0, None)
            da = -P[0] / (A[0, 0] + A[0, 4])
            a += da
            if abs(da) < 1e-15:
                break
        x = np.array([a, 0.0, 0.0, lam, a])
        P, _, state = law.update(x, state, t - t0, None)
        t0 = t
        out.append((P[3], x, P))
    return out


def bar(law, element, formulation):
    mesh = rectangle((0.0, 1.0), (0.0, 1.0), (2, 2), element)
    model = Model(mesh, law, formulation=formulation)
    model.fix(select_nodes(mesh, {"r": 0.0}), ["ur"])
    model.fix(select_nodes(mesh, {"z": 0.0}), ["uz"])
    top = select_nodes(mesh, {"z": 1.0})
    model.prescribe(top, ["uz"], STRETCH - 1.0, Curve([[0.0, 0.0], [END / 2.0, 1.0], [END, 1.0]]))
    system = model.finalize()
    return system, system.dof(top, "uz")


@pytest.mark.parametrize(
    "element, formulation", [("q4", "displacement"), ("q4", "mixed"), ("q8", "mixed"), ("sfr", "mixed")]
)
def test_a_homogeneous_bar_of_networks_is_the_law_at_a_point(element, formulation):
    """Force on the end / pi against the material point's P_zZ at every step (the same steps):
    to the solver's tolerance; the fields' Cauchy stress at the committed state against the
    point's."""
    system, top = bar(LAW, element, formulation)
    forces, times = [], []

    def record(step):
        forces.append(step.r_full[top].sum() / np.pi)
        times.append(step.lam)

    res = solve(system, LoadControl(END, STEPS), NewtonOptions(tolerance=1e-12), on_step=record)
    assert res.status == "finished", res.message
    assert len(times) == STEPS
    expected = point(LAW, np.array(times))
    P_point = np.array([p for p, _, _ in expected])
    assert P_point.max() > 1.5 and P_point[-1] < 0.92 * P_point.max()  # loaded, then relaxed
    np.testing.assert_allclose(forces, P_point, rtol=1e-8, atol=1e-10)
    sigma = point_fields(system, res.last.u, res.last.state)["cauchy_stress"]
    _, x, P = expected[-1]
    np.testing.assert_allclose(sigma[:, :3], np.tile(cauchy_stress(x, P)[:3], (len(sigma), 1)), atol=1e-8)


@pytest.mark.parametrize("element, formulation", [("q4", "displacement"), ("q8", "mixed")])
def test_the_tangent_of_a_model_of_networks_matches_differences_of_the_residual(element, formulation):
    """From a committed state whose networks have flowed, at a perturbed state a step later:
    the model's tangent against central differences of its residual (the state held)."""
    from conftest import difference_tangent

    system, _ = bar(LAW, element, formulation)
    res = solve(system, LoadControl(0.4, 4), NewtonOptions())
    held = res.last.state
    assert np.abs(system.solid_state(held)["network0"] - [1.0, 0.0, 1.0, 1.0]).max() > 1e-3
    u_f = res.last.u_f + 1e-3 * np.random.default_rng(5).standard_normal(system.n_free)
    t = res.last.lam + 0.05
    K = system.evaluate(u_f, t, held).K.toarray()
    num, _ = difference_tangent(system, u_f, t, 1e-6, held)
    assert np.abs(K - num).max() < 1e-6 * np.abs(K).max()


class Fussy(NetworkLaw):
    """The law of networks whose local update fails over steps longer than 0.06."""

    def update(self, x, state_n, dt, T, volumetric=True, tangent=True):
        if dt > 0.06:
            raise LocalUpdateError(np.arange(3))
        return super().update(x, state_n, dt, T, volumetric, tangent)


def test_a_local_update_that_fails_cuts_the_step():
    law = Fussy(LAW.equilibrium, LAW.networks)
    system, top = bar(law, "q4", "mixed")
    times = []
    res = solve(system, LoadControl(0.4, 4), NewtonOptions(), on_step=lambda step: times.append(step.lam))
    assert res.status == "finished", res.message
    assert times[-1] == pytest.approx(0.4) and np.diff([0.0, *times]).max() <= 0.06
