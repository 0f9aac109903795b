"""Regressions met while building the process examples (the smallest cases that showed them).

1. tests/data/volume_control_line_search.toml: a thin balloon under volume control with a
   mould it never touches.  The contact line search cut every correction that satisfied the
   cavity's constraint to 1/8: 74 steps and 1,005 Newton iterations (20 and 77 without the
   [[contact]] table).  Fixed by taking the full step when no shortened one lowers the
   residual: 20 steps, 66 iterations.
2. tests/data/sheet_resting_on_mould.toml: a sheet lying on a flat mould (gap 0), pressed on
   its centre.  The rounded penalty law pushed nodes at g = 0 away and its zero-force point
   was a double root of the residual (Newton converged linearly, 10-20 iterations a step);
   a coarse sheet flush with its mould did not start.  The law now gives nothing at g >= 0:
   15 steps, 48 iterations; the first Newton correction, with no stiffness at g = 0, drove
   the sheet into the mould (a residual 2e4 times the first) and the first step was cut.
   With the penalty in the tangent of a step's first iteration for the resting nodes
   (ContactPair.predicting): the 10 nominal steps, 35 iterations, 7 in the first.
"""

from pathlib import Path

from axiform.case.schema import build, load
from axiform.solve.solver import solve

DATA = Path(__file__).parent / "data"


def _run(name):
    built = build(load(DATA / name), DATA)
    return solve(built.model, built.control, built.options)


def test_volume_control_with_an_untouched_mould_keeps_full_newton_steps():
    res = _run("volume_control_line_search.toml")
    assert res.status == "finished", res.message
    assert len(res.steps) == 20 and res.newton_iterations <= 100


def test_sheet_resting_on_its_mould():
    res = _run("sheet_resting_on_mould.toml")
    assert res.status == "finished", res.message
    assert len(res.steps) == 10 and res.steps[0].iterations <= 8
    assert res.newton_iterations <= 40
