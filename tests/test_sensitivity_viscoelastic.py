"""Sensitivities along the load path (axiform.design.sensitivity) with a viscoelastic law: a tube
inflated in process time (t from 0 to 1) by a cavity under volume or pressure control, its
Prony series relaxing over 0.1 and 1 (times comparable to the process), so that the
residual of every step depends on the history h_i committed before it.  The derivatives of
the final thickness, of every displacement and of the cavity pressure to the thickness
table, against central differences of whole forward solves; and the same derivatives with
the history held at its base value (dh/ds ignored), or of the elastic law, which are wrong
by far more than the tolerance.  And the tube cooled by a film while it is blown, its
relaxation times shifted by the temperature (WLF): the shadows' temperatures are advanced by
heat conduction after each step as the solver's are (System.settle)."""

import copy

import numpy as np
import pytest

from axiform.case.schema import build, parse
from axiform.design.sensitivity import sensitivity, thickness_derivative
from axiform.post.thickness import thickness_table
from axiform.solve.linsolve import factorize
from axiform.solve.solver import solve

REL = 1e-6  # measured: 2e-9 (volume control) to 5e-8 (pressure control)
PRONY = {"g": [0.5, 0.3], "tau": [0.1, 1.0]}
TUBE = {
    "title": "viscoelastic tube",
    "mesh": {
        "kind": "layered",
        "element": "q4",
        "start": [10.0, 0.0],
        "profile": [{"line": {"to": [10.0, 12.0], "divisions": 6}}],
        "thickness": [[0.0, 1.0], [6.0, 1.2], [12.0, 0.9]],
        "layers": 1,
    },
    "material": {"model": "neo-hooke", "C1": 0.1, "kappa": 100.0, "viscoelastic": PRONY},
    "fix": [{"at": {"set": "start"}, "dofs": ["uz"]}, {"at": {"set": "end"}, "dofs": ["uz"]}],
    # the differences need the same path: steps of a fixed length (no growth)
    "solver": {"target": 1.0, "steps": 8, "growth": 1.0},
}
# the gas ramps up over the whole process: to 1.76 times the tube's volume, or to a
# pressure under which the relaxing tube creeps (its outer radius at t = 1: 17.5, the elastic
# tube's 12.2)
CAVITY = {"volume": {"control": "volume", "volume": 6000.0}, "pressure": {"control": "pressure", "pressure": 0.01}}


def tube(control: str, formulation: str, element: str, viscoelastic: bool = True) -> dict:
    tree = copy.deepcopy(TUBE)
    tree["mesh"].update(formulation=formulation, element=element)
    tree["cavity"] = [{"name": "gas", "boundary": {"set": "inner"}} | CAVITY[control]]
    if not viscoelastic:
        del tree["material"]["viscoelastic"]
    return tree


def builder(tree):
    def model(x):
        t = copy.deepcopy(tree)
        t["mesh"]["thickness"] = [[row[0], float(v)] for row, v in zip(tree["mesh"]["thickness"], x, strict=False)]
        return build(parse(t)).model

    return model


def design(tree) -> np.ndarray:
    return np.array([row[1] for row in tree["mesh"]["thickness"]])


def differentiate(tree):
    built = build(parse(tree))
    sens = sensitivity(builder(tree), design(tree), built.control, built.options)
    assert sens.status == "finished"
    return sens, built


def forward(model, built, times):
    """The final thickness, displacements (n_full,) and cavity pressure of a whole solve."""
    result = solve(model, built.control, built.options)
    assert [s.lam for s in result.steps] == pytest.approx(times, abs=1e-12)  # the same path
    u = result.last.u
    return (
        thickness_table(model.mesh, u.reshape(-1, model.dpn)[:, :2])["thickness"],
        u,
        model.finalize().cavity_states(result.last.state)[0].pressure,
    )


def history_held(tree, sens) -> np.ndarray:
    """d(final thickness)/ds (stations, m) with dh/ds ignored: the last step's residual
    differentiated at the base's committed history h_{N-1}(s), not at h_{N-1}(s +- h)."""
    model, make, s = sens.model, builder(tree), sens.design
    before, last = sens.solve.steps[-2], sens.solve.steps[-1]
    dR = np.empty((model.n_free, s.size))
    for k in range(s.size):
        e = np.zeros(s.size)
        e[k] = 1e-6 * s[k]
        dR[:, k] = (
            make(s + e).evaluate(last.u_f, last.lam, before.state, tangent=False).r
            - make(s - e).evaluate(last.u_f, last.lam, before.state, tangent=False).r
        ) / (2 * e[k])
    K = model.evaluate(last.u_f, last.lam, before.state).K
    du_f = -np.asarray(factorize(K)(dR)).reshape(model.n_free, s.size)
    dm = model.dofmap
    du = np.concatenate([du_f[: dm.nf], np.zeros((dm.np, s.size))])[dm.eq]
    du2 = du.reshape(model.mesh.n_nodes, model.dpn, -1)[:, :2]
    return thickness_derivative(model, last.u.reshape(-1, model.dpn)[:, :2], sens.dx_ds, du2)


def agree_with_differences(tree: dict, sens, built, pressure: bool = False) -> None:
    """The derivatives of the wall's thickness and of every displacement of the last step
    (and of the cavity pressure, an unknown of the bordered system) against central
    differences of whole solves at s +- 1e-4 s, one design variable at a time."""
    times = [step.lam for step in sens.solve.steps]
    make, s = builder(tree), sens.design
    for k in range(s.size):
        e = np.zeros(s.size)
        e[k] = 1e-4 * s[k]
        (tp, up, pp), (tm, um, pm) = (forward(make(x), built, times) for x in (s + e, s - e))
        fd = (tp - tm) / (2 * e[k])
        assert np.abs(sens.dthickness_ds[:, k] - fd).max() <= REL * np.abs(fd).max(), k
        fd = (up - um) / (2 * e[k])
        assert np.abs(sens.du_ds[-1][:, k] - fd).max() <= REL * np.abs(fd).max(), k
        if pressure:
            assert sens.dp_ds[-1][0, k] == pytest.approx((pp - pm) / (2 * e[k]), rel=REL)


@pytest.mark.parametrize(
    "control, formulation, element",
    [
        ("volume", "mixed", "q4"),
        ("pressure", "mixed", "q4"),
        ("volume", "displacement", "q8"),
        ("pressure", "displacement", "sfr"),
    ],
)
def test_derivatives_carry_the_history_of_the_prony_series(control, formulation, element):
    tree = tube(control, formulation, element)
    sens, built = differentiate(tree)
    assert np.abs(sens.model.solid_state(sens.solve.last.state)["h"]).max() > 0
    agree_with_differences(tree, sens, built, pressure=control == "volume")
    # the history matters: held at its base value, or without the series, the derivative is off
    scale = np.abs(sens.dthickness_ds).max()
    assert np.abs(history_held(tree, sens) - sens.dthickness_ds).max() > 1e-2 * scale
    elastic, _ = differentiate(tube(control, formulation, element, viscoelastic=False))
    assert np.abs(elastic.dthickness_ds - sens.dthickness_ds).max() > 5e-3 * scale


def test_derivatives_carry_the_temperature_that_conduction_advances():
    """The tube of two layers, from 150 (the reference) cooled through its outer face by a film
    to 25 during the process (to 63 to 94 at t = 1), its relaxation times shifted by WLF (C1 =
    2, C2 = 130: 4 times longer at 120; the pole at 20, below the film): the wall's thickness changes how it cools, so
    the temperature of each step depends on the design.  Against central differences of
    whole solves as above (measured 4e-9; 0.1 to 0.6 when the shadows' temperature was
    not advanced); the derivative of the same tube kept at 150 differs by far more."""
    tree = tube("pressure", "mixed", "q4")
    tree["mesh"]["layers"] = 2
    tree["temperature"] = {"initial": 150.0, "reference": 150.0, "shift": {"wlf": {"C1": 2.0, "C2": 130.0}}}
    warm = copy.deepcopy(tree)
    tree["thermal"] = {"conductivity": 0.2, "density": 1.0e-9, "specific_heat": 1.9e8}
    tree["convection"] = [{"on": {"set": "outer"}, "h": 0.2, "ambient": 25.0}]
    sens, built = differentiate(tree)
    T = sens.solve.last.state.temperature
    assert T.max() < 100.0 and T.max() - T.min() > 20.0
    agree_with_differences(tree, sens, built)
    kept, _ = differentiate(warm)
    assert np.abs(kept.dthickness_ds - sens.dthickness_ds).max() > 0.1 * np.abs(sens.dthickness_ds).max()
