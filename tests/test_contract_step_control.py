"""Step control on cases its first tests did not hold (§ 17: steps that cut and grow back):
under arc length with `growth = 1.0` a cut step's arc is sub-stepped and the nominal arc
then resumes (it kept the cut size to the end: 85 steps for 20), and a run resumed inside
such a sub-stepped arc takes the same steps as the uninterrupted one."""

from __future__ import annotations

import copy

import numpy as np
import pytest
from test_restart import ARC, PUNCH

from axiform.case.schema import build, parse
from axiform.io.checkpoint import load as load_checkpoint
from axiform.io.checkpoint import save as save_checkpoint
from axiform.solve.solver import solve

# the SFR plate of test_restart under arc length to w = 8, in 20 steps of at most 4 Newton
# iterations (its first arcs are cut) and no growth after easy steps
CUT_ARC = copy.deepcopy(ARC)
CUT_ARC["solver"].update(steps=20, max_iterations=4, growth=1.0)


def arc_run(case=CUT_ARC, resume=None):
    built = build(parse(case))
    return solve(built.model, built.control, built.options, resume=resume)


def test_an_arc_cut_without_growth_comes_back_to_the_nominal_arc():
    """The cut arcs are made up by their sub-steps, then the nominal arc resumes: 33 steps
    for 20 (before: 85, every arc after the first cut at the cut size)."""
    result = arc_run()
    assert result.status == "finished", result.message
    assert result.cuts > 0
    assert result.n_steps <= 2 * 20
    goals = [s.checkpoint["path"]["goal"] for s in result.steps]
    first = goals.index(next(g for g in goals if g is not None))
    assert None in goals[first:]  # it sub-stepped, then came back to the nominal arc


def test_a_run_resumed_inside_a_sub_stepped_arc_takes_the_same_steps(tmp_path):
    full = arc_run()
    inside = [s for s in full.steps if s.checkpoint["path"]["goal"] is not None]
    assert inside
    k = inside[0].number
    save_checkpoint(tmp_path, inside[0].checkpoint, {})
    state, _ = load_checkpoint(tmp_path)
    rest = arc_run(resume=state)
    assert rest.status == "finished", rest.message
    assert [s.number for s in rest.steps] == [s.number for s in full.steps[k:]]
    for a, b in zip(rest.steps, full.steps[k:], strict=True):
        assert a.lam == pytest.approx(b.lam, rel=1e-10) and a.iterations == b.iterations
        np.testing.assert_allclose(a.u, b.u, rtol=1e-10, atol=1e-12 * np.abs(b.u).max())


def test_an_arc_without_growth_follows_a_nominal_arc_that_grows():
    """The sticky punch of test_restart pressed in after a hold, under arc length in 8 steps
    without growth: the nominal arc is worked out anew after every step, and where it grows a
    nominal arc is sub-stepped at the old size, then the new one taken (13 steps, none cut:
    the first size was kept to the end)."""
    case = copy.deepcopy(PUNCH)
    case["contact"][0]["motion"] = {"uz": -0.8, "curve": [[0.0, 0.0], [0.5, 0.0], [1.0, 1.0]]}
    case["solver"] = {"control": "arc-length", "steps": 8, "growth": 1.0}
    result = arc_run(case)
    assert result.status == "finished", result.message
    assert result.cuts == 0 and result.n_steps <= 11
    assert result.last.lam == 1.0
