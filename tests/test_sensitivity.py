"""Sensitivities by direct differentiation along the load path (axiform.design.sensitivity) against
central differences of whole forward solves: a free tube blown by a cavity under volume
control, and tubes blown against a conical mould with sticky contact (mixed) and with
Coulomb friction (mixed and displacement); nodes touch at different steps, so the history
counts.  Relative error <= 1e-5 where the path keeps its contact set."""

import copy

import numpy as np
import pytest

from axiform.case.schema import build, parse
from axiform.design.sensitivity import DesignError, differentiate, sensitivity
from axiform.post.thickness import thickness_table
from axiform.solve.solver import ArcLengthControl, NewtonOptions, solve

TUBE = {
    "title": "tube",
    "mesh": {
        "kind": "layered",
        "element": "q4",
        "start": [10.0, 0.0],
        "profile": [{"line": {"to": [10.0, 12.0], "divisions": 6}}],
        "thickness": [[0.0, 1.0], [6.0, 1.2], [12.0, 0.9]],
        "layers": 1,
    },
    "material": {"model": "neo-hooke", "C1": 0.1, "kappa": 100.0},
    "fix": [{"at": {"set": "start"}, "dofs": ["uz"]}, {"at": {"set": "end"}, "dofs": ["uz"]}],
    "cavity": [{"name": "gas", "boundary": {"set": "inner"}, "control": "volume", "volume": 6000.0}],
    "solver": {"steps": 6},
}
# a conical mould that holds the blown tube: the outer face touches it from the bottom up, one
# node after the other (a narrower cone, [[11.5, -3], [14, 15]], holds less than the cavity's
# 6000 with the wall inside it: the mixed element then stops with J <= 0 and the displacement
# element finishes only 0.7 mm into the mould)
MOULD = {"surface": {"polyline": [[10.8, -3.0], [16.0, 15.0]]}, "slaves": {"set": "outer"}}


def tube(formulation="mixed", element="q4", contact=None, volume=6000.0):
    tree = copy.deepcopy(TUBE)
    tree["mesh"].update(formulation=formulation, element=element)
    tree["cavity"][0]["volume"] = volume
    if contact is not None:
        tree["contact"] = [dict(MOULD, **contact)]
    return tree


def builder(tree):
    def model(x):
        t = copy.deepcopy(tree)
        t["mesh"]["thickness"] = [[row[0], float(v)] for row, v in zip(tree["mesh"]["thickness"], x, strict=False)]
        return build(parse(t)).model

    return model


def forward(model, control, options, lams):
    result = solve(model, control, options)
    assert [s.lam for s in result.steps] == pytest.approx(lams, abs=1e-12)  # the same path
    u = result.last.u.reshape(-1, model.dpn)[:, :2]
    table = thickness_table(model.mesh, u)
    held = result.last.state
    return (
        table["thickness"],
        model.cavity_states(held)[0].pressure,
        [p.report(s)["status"] for p, s in zip(model.contacts, model.contact_states(held), strict=False)],
    )


def check_against_forward_differences(tree, rel=1e-5):
    built = build(parse(tree))
    x0 = np.array([row[1] for row in tree["mesh"]["thickness"]])
    make = builder(tree)
    sens = sensitivity(make, x0, built.control, built.options)
    assert sens.status == "finished"
    lams = [s.lam for s in sens.solve.steps]
    assert len(sens.du_ds) == len(lams)
    for k in range(len(x0)):
        h = 1e-4 * x0[k]
        e = np.zeros_like(x0)
        e[k] = h
        tp, pp, cp = forward(make(x0 + e), built.control, built.options, lams)
        tm, pm, cm = forward(make(x0 - e), built.control, built.options, lams)
        for a, b in zip(cp, cm, strict=False):  # the contact set does not change between the two
            assert np.array_equal(a, b)
        fd = (tp - tm) / (2 * h)
        err = np.abs(sens.dthickness_ds[:, k] - fd).max() / np.abs(fd).max()
        assert err <= rel, (k, err)
        dp = (pp - pm) / (2 * h)  # the cavity pressure, an unknown of the bordered system
        assert sens.dp_ds[-1][0, k] == pytest.approx(dp, rel=rel, abs=rel * abs(pp) / x0[k])
    return sens


@pytest.mark.parametrize("formulation", ["mixed", "displacement"])
def test_free_tube_under_volume_control(formulation):
    sens = check_against_forward_differences(tube(formulation))
    # the design moves the nodes across the wall linearly: dX/ds at the knots is +-1/2 of the normal
    assert np.abs(sens.dx_ds).max() == pytest.approx(0.5, rel=1e-6)


def test_sticky_mould_with_nodes_freezing_at_different_steps_mixed():
    sens = check_against_forward_differences(tube("mixed", contact={"sticky": True}))
    pair, held = sens.model.contacts[0], sens.model.contact_states(sens.solve.last.state)[0]
    assert np.unique(held.first_contact[~np.isnan(held.first_contact)]).size >= 3  # froze over several steps
    status = pair.report(held)["status"]
    # the 7 outer nodes all on the mould, 4 of them frozen (5 while the penalty's tie let the
    # frozen wall sink, and left room for the volume nearer the pole)
    assert (status > 0).all() and (status == 3).sum() >= 4
    assert pair.report(held)["penetration"] < 0.05  # the mould holds the tube


def test_steps_cut_and_sub_stepped_within_their_intervals():
    """The sticky tube with at most 6 Newton iterations a step: steps are cut and their
    intervals sub-stepped (the nominal points of the run kept); the derivatives follow the
    path taken, which the designs at +-h take too."""
    tree = tube("mixed", contact={"sticky": True})
    tree["solver"].update(max_iterations=6)
    sens = check_against_forward_differences(tree)
    lams = [s.lam for s in sens.solve.steps]
    assert len(lams) > 6 and {round(k / 6, 12) for k in range(1, 7)} <= {round(x, 12) for x in lams}


@pytest.mark.parametrize("formulation", ["mixed", "displacement"])
def test_coulomb_friction_on_the_mould(formulation):
    # 5800 of gas, not 6000: beyond, the last step drives the wall so far into the cone that
    # the designs at +-1e-4 cut it back at different places (Newton there takes 15 to 27
    # iterations, and a second-order guess overshoots into the mould), so their paths differ
    # (at 5900 and 5950 too once the contact carries its multipliers: 6 steps against 7 or 8)
    tree = tube(formulation, contact={"friction": 0.3}, volume=5800.0)
    # the same path for the differences: no step grows, and the steps where sliding nodes stick
    # (up to 24 Newton iterations in the mixed element) are not cut back
    tree["solver"].update(growth=1.0, max_iterations=30)
    sens = check_against_forward_differences(tree)
    pair, held = sens.model.contacts[0], sens.model.contact_states(sens.solve.last.state)[0]
    assert (pair.report(held)["status"] > 0).sum() >= 4
    assert np.unique(held.first_contact[~np.isnan(held.first_contact)]).size >= 2  # touched at different steps
    assert pair.report(held)["penetration"] < 0.05


def test_design_changing_the_supports_is_refused():
    """A model whose supports depend on the design (here: one more fixed node above s0 = 1)
    cannot be differentiated: DesignError says why."""
    tree = tube()
    built = build(parse(tree))
    plain = builder(tree)

    def make(x):
        t = copy.deepcopy(tree)
        t["mesh"]["thickness"] = [[row[0], float(v)] for row, v in zip(tree["mesh"]["thickness"], x, strict=False)]
        model = build(parse(t)).builder
        if x[0] > 1.0:
            model.fix([0], ["ur"])
        return model

    with pytest.raises(DesignError, match="named sets"):
        sensitivity(make, np.array([1.0, 1.2, 0.9]), built.control, built.options)
    with pytest.raises(ValueError, match="load control"):
        sensitivity(plain, np.array([1.0, 1.2, 0.9]), ArcLengthControl(), NewtonOptions())


def test_a_clamped_end_differentiates_the_held_wall():
    """A tube clamped at its top (every node of the end fibre held): the station there reports
    the held wall's reference thickness, so its derivative is that of the design's own table
    there, not of a wall measured across the bulging element next to it."""
    tree = tube()
    tree["fix"][1]["dofs"] = ["ur", "uz"]
    sens = check_against_forward_differences(tree)
    assert sens.thickness["held"][-1] and not sens.thickness["held"][:-1].any()
    assert sens.dthickness_ds[-1] == pytest.approx([0.0, 0.0, 1.0], abs=1e-9)  # t0 at s = 12 is the third knot


def test_forward_differences_of_the_residual_agree_with_central_ones_to_what_optimize_needs():
    """differences = "forward" (what `axiform optimize` uses: one shadow model a variable,
    against the base model itself) on the sticky tube, whose history counts: the final wall's
    derivatives within 1e-4 of the central ones (measured: 6.4e-5), the same forward solve."""
    tree = tube("mixed", contact={"sticky": True})
    built = build(parse(tree))
    x0 = np.array([row[1] for row in tree["mesh"]["thickness"]])
    central = sensitivity(builder(tree), x0, built.control, built.options)
    forward_ = sensitivity(builder(tree), x0, built.control, built.options, differences="forward")
    assert [s.lam for s in forward_.solve.steps] == [s.lam for s in central.solve.steps]
    scale = np.abs(central.dthickness_ds).max()
    err = np.abs(forward_.dthickness_ds - central.dthickness_ds).max() / scale
    assert 0 < err <= 1e-4, err
    assert np.abs(forward_.dx_ds - central.dx_ds).max() <= 1e-6 * np.abs(central.dx_ds).max()
    with pytest.raises(ValueError, match="differences must be"):
        sensitivity(builder(tree), x0, built.control, built.options, differences="backward")


@pytest.mark.parametrize("differences", ["central", "forward"])
def test_derivatives_after_the_solve_are_those_taken_during_it(differences):
    """differentiate: a solve done first (every step kept), its steps differentiated after it,
    gives the very derivatives of `sensitivity` (which differentiates each step as it
    converges) on the sticky tube with cut steps, whose history counts; a solve that kept
    only some of its steps is refused."""
    tree = tube("mixed", contact={"sticky": True})
    tree["solver"].update(max_iterations=6)
    built = build(parse(tree))
    x0 = np.array([row[1] for row in tree["mesh"]["thickness"]])
    during = sensitivity(builder(tree), x0, built.control, built.options, differences=differences)
    assert during.solve.cuts > 0
    model = builder(tree)(x0).finalize()
    result = solve(model, built.control, built.options)
    after = differentiate(builder(tree), x0, model, result, differences=differences)
    assert after.solve is result and len(after.du_ds) == len(during.du_ds) == result.n_steps
    for a, b in zip(after.du_ds, during.du_ds, strict=True):
        assert np.array_equal(a, b)
    assert np.array_equal(after.dthickness_ds, during.dthickness_ds)
    assert np.array_equal(after.thickness["thickness"], during.thickness["thickness"])
    short = solve(builder(tree)(x0).finalize(), built.control, built.options, keep=1)
    with pytest.raises(ValueError, match="all are needed"):
        differentiate(builder(tree), x0, model, short)
