"""Step control: a failed step is sub-stepped to the end of its own nominal interval and the
nominal grid then resumes (a run that cuts early finishes within 1.25 times its nominal steps
and passes through every nominal point of a run that does not cut), or, after a hard
interval, the size is carried on without crossing a nominal point; the first contact of an
unloaded body is no divergence."""

import copy
import dataclasses
import re

import pytest
from test_restart import PUNCH as RESTART_PUNCH

from axiform.case.base import CaseError
from axiform.case.schema import build, parse
from axiform.solve.solver import solve

# the sticky punch of test_restart (pressed into a disc it touches at t = 0: the disc is
# unloaded at the first step), in 4 nominal steps
PUNCH = {**RESTART_PUNCH, "solver": {"control": "load", "steps": 4}}


def run(**solver):
    case = copy.deepcopy(PUNCH)
    case["solver"].update(solver)
    built = build(parse(case))
    result = solve(built.model, built.control, built.options)
    assert result.status == "finished", result.message
    return result


@pytest.mark.parametrize("growth", [1.0, 1.5])
def test_a_step_cut_early_grows_back_to_the_nominal_grid(growth):
    """The first step needs more than 4 iterations at its nominal size: it is cut, the rest of
    its interval sub-stepped, and the nominal steps resume where its last sub-step was easy,
    whatever the growth (with growth = 1.0 the halved size used to stay for the whole run: 8
    steps for 4)."""
    nominal = [s.lam for s in run(max_iterations=20).steps]
    assert nominal == [0.25, 0.5, 0.75, 1.0]
    cut = run(max_iterations=4, growth=growth)
    lams = [s.lam for s in cut.steps]
    assert min(b - a for a, b in zip([0.0, *lams], lams, strict=False)) < 0.25  # it did cut
    assert cut.n_steps <= 1.25 * len(nominal)
    assert set(nominal) <= set(lams)  # the very same nominal points, to the bit


def test_the_first_contact_of_an_unloaded_body_is_no_divergence():
    """At the first step the disc carries no load and no stress, so the reference force is
    nearly zero while the punch's contact forces are not: the step converges at its nominal
    size (it was failed as diverging, and cut three times)."""
    result = run(steps=2)
    assert [s.lam for s in result.steps] == [0.5, 1.0]


def test_a_hard_interval_carries_its_size_onto_the_grid():
    """Where the last sub-step of a cut interval was not easy (more than easy_iterations), the
    size is carried into the next interval, growing back by `growth` after easy steps, and
    still no step crosses a nominal point (the sizes 1/8 then 3/16 used to cross 0.75)."""
    case = copy.deepcopy(PUNCH)
    case["solver"].update(max_iterations=4, growth=1.5)
    built = build(parse(case))
    result = solve(built.model, built.control, dataclasses.replace(built.options, easy_iterations=2))
    assert result.status == "finished", result.message
    lams = [s.lam for s in result.steps]
    sizes = [b - a for a, b in zip([0.0, *lams], lams, strict=False)]
    assert {0.25, 0.5, 0.75, 1.0} <= set(lams)
    assert any(size < 0.25 for lam, size in zip(lams, sizes, strict=True) if lam > 0.25)  # carried on


def test_solver_stops_are_step_ends():
    """solver.stops: load factors every step lands on besides the curves' knots (what
    `axiform optimize` writes into optimized.toml: the path its designs were measured on)."""
    lams = [s.lam for s in run(stops=[0.1, 0.3, 0.35]).steps]
    assert {0.1, 0.3, 0.35, 1.0} <= set(lams)
    assert max(b - a for a, b in zip([0.0, *lams], lams, strict=False)) <= 0.25 + 1e-12


@pytest.mark.parametrize(
    ("solver", "message"),
    [
        ({"stops": [0.5, 1.5]}, "solver.stops: 1.5 lies beyond the target 1"),
        ({"stops": [-0.5]}, "solver.stops[0]: Input should be greater than 0"),
        ({"control": "arc-length", "stops": [0.5]}, "'stops' belongs to control = \"load\""),
    ],
)
def test_bad_stops_are_refused_naming_the_key(solver, message):
    case = copy.deepcopy(PUNCH)
    case["solver"].update(solver)
    with pytest.raises(CaseError, match=re.escape(message)):
        build(parse(case))


def test_a_ramp_shorter_than_the_steps_is_cut_against_its_own_length():
    """The punch pressed in over t = 0..1, then held to t = 1e4 in 4 steps: the first step (the
    whole press, too hard at 4 iterations) is cut below 1e-4 of the nominal step of 2500 but
    not of the ramp's length 1, and the run finishes (it stopped with the step 'cut below the
    minimum' before any step)."""
    case = copy.deepcopy(PUNCH)
    case["contact"][0]["motion"] = {"uz": -0.8, "curve": [[0.0, 0.0], [1.0, 1.0], [1.0e4, 1.0]]}
    case["solver"].update(target=1.0e4, max_iterations=4)
    built = build(parse(case))
    result = solve(built.model, built.control, built.options)
    assert result.status == "finished", result.message
    lams = [s.lam for s in result.steps]
    sizes = [b - a for a, b in zip([0.0, *lams], lams, strict=False)]
    assert min(sizes) < 1e-4 * 2500.0 and 1.0 in lams and lams[-1] == 1.0e4
