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

import tomllib
from pathlib import Path

import numpy as np
import pytest
from scipy import optimize

from axiform import MooneyRivlin
from axiform.case.schema import build, parse
from axiform.solve.solver import solve

DATA = Path(__file__).parent / "data"


def test_volume_control_with_an_untouched_mould_keeps_full_newton_steps():
    """The 20 nominal steps, and the state they reach: the balloon's pressure at its equator's
    stretch l (2.51) against the thin compressible membrane, p = 2 sigma h / r at the
    mid-surface radius (the law's plane-stress equibiaxial state: l3 from P_rr = 0, h = l3 h0,
    sigma = P_tt l / J), within 2e-4 (1e-5 measured)."""
    data = tomllib.loads((DATA / "volume_control_line_search.toml").read_text())
    data["monitor"] = [
        {"name": "p", "cavity": "gas", "quantity": "pressure"},
        {"name": "u", "at": {"r": 1.005, "z": 0.0}, "dof": "ur"},
    ]
    built = build(parse(data), DATA)
    res = solve(built.model, built.control, built.options)
    assert res.status == "finished", res.message
    assert len(res.steps) == 20 and res.newton_iterations <= 100
    p, u = (m.value(res.last) for m in built.monitors)
    law, h0 = MooneyRivlin(1.0, 0.1, 1.0e4), 0.01

    def stress(l3, l):  # nominal stress (5,) of the equator: thickness along r, meridian along z
        return law.stress_tangent(np.array([[l3, 0.0, 0.0, l, l]]))[0][0]

    l3 = 1.0
    for _ in range(30):  # the mid-surface radius (R0 = 1) depends on the thickness
        l = 1.0 + h0 / 2 + u - l3 * h0 / 2
        l3 = optimize.brentq(lambda s, l=l: stress(s, l)[0], 1e-3, 2.0, xtol=1e-14)
    assert 2.4 < l < 2.6
    assert p == pytest.approx(2 * stress(l3, l)[4] * h0 / l**2, rel=2e-4)  # 2 sigma h / r


def test_sheet_resting_on_its_mould():
    """The 10 nominal steps with few iterations, and the state they reach: along z the
    pressure on the pressed centre, p pi r^2 with r the current radius of the pressed face's
    edge (a follower pressure on straight edges), is carried by the mould and the clamped rim,
    to 1e-7 of it (1e-12 measured)."""
    data = tomllib.loads((DATA / "sheet_resting_on_mould.toml").read_text())
    data["monitor"] = [
        {"name": "rim_z", "reaction": {"r": 10.0}, "dof": "uz"},
        {"name": "mould_z", "contact": 0, "quantity": "force-z"},
        {"name": "edge_ur", "at": {"r": 3.0, "z": 1.0}, "dof": "ur"},
    ]
    built = build(parse(data), DATA)
    res = solve(built.model, built.control, built.options)
    assert res.status == "finished", res.message
    assert len(res.steps) == 10 and res.steps[0].iterations <= 8
    assert res.newton_iterations <= 40
    rim_z, mould_z, edge_ur = (m.value(res.last) for m in built.monitors)
    pressed = 0.1 * np.pi * (3.0 + edge_ur) ** 2
    assert mould_z > 0.5 * pressed
    assert rim_z + mould_z - pressed == pytest.approx(0.0, abs=1e-7 * pressed)
