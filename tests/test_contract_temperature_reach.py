"""The temperatures a case can reach are those of its run: without a [solver] target a
load-controlled run ends at t = 1 (the default target), so a film's ambient that falls below
the WLF pole only at t = 5 is never reached (a warning says the curve is cut short); one that
falls there by t = 1 is refused."""

from __future__ import annotations

import re

from test_temperature_domain import case_with, check, warm


def untargeted(curve):
    def edit(d):
        warm(d)  # the film at 120, the pole at 98.4
        del d["solver"]["target"]
        d["convection"][0]["curve"] = curve

    return edit


def test_a_curve_past_the_default_target_is_not_reached(tmp_path, capsys):
    code, err = check(capsys, case_with(tmp_path, untargeted([[0.0, 1.0], [1.0, 1.0], [5.0, 0.5]])))
    assert code == 0, err
    assert "convection[0].curve: the curve runs to t = 5, but the run ends at [solver] target (default 1)" in err


def test_a_curve_within_the_default_target_is_refused(tmp_path, capsys):
    code, err = check(capsys, case_with(tmp_path, untargeted([[0.0, 1.0], [2.0, 0.5], [5.0, 0.5]])))
    assert code == 2 and re.search(r"convection\[0\]\.ambient: 90 \(120 x its curve at t = 1\) is at or below", err)


QUADRATIC = """
[mesh]
kind = "rectangle"
r = [10.0, 11.0]
z = [0.0, 2.0]
divisions = [1, 1]
element = "q8"
[material]
model = "neo-hooke"
C1 = 0.5
kappa = 1.0e3
viscoelastic = { g = [0.5], tau = [1.0] }
[temperature]
initial = { along = "z", table = [[0.0, 100.0], [1.0, 100.0], [2.0, 150.0]] }
reference = 150.0
shift = { wlf = { C1 = 17.44, C2 = 54.0 } }
[[fix]]
at = { z = 0.0 }
dofs = ["uz"]
[[fix]]
at = { r = 10.0 }
dofs = ["ur"]
[[pressure]]
on = { z = 2.0 }
value = 0.01
[solver]
steps = 2
[output]
vtu = false
plots = false
"""


def test_a_field_below_the_pole_between_its_nodes_is_refused_before_any_work(tmp_path, capsys):
    """A Q8 whose nodes lie at 100, 100 and 150 along z (the pole at 96): its quadratic shape
    functions carry the field to 95.6 at a quadrature point, where the law takes it.  The
    case was valid and its run failed at the start with exit 3."""
    path = tmp_path / "case.toml"
    path.write_text(QUADRATIC)
    code, err = check(capsys, str(path))
    assert code == 2 and re.search(r"95\.6\d* at element 0 is at or below the WLF pole T_ref - C2 = 96", err), err
    assert "temperature.initial" in err, err
    path.write_text(QUADRATIC.replace('element = "q8"', 'element = "q4"'))
    code, err = check(capsys, str(path))
    assert code == 0, err  # bilinear: within its nodes' values


def test_a_change_bringing_a_point_between_nodes_below_the_pole_is_refused(tmp_path, capsys):
    """The same Q8, 10 K warmer (its points down to 105.6), cooled by 12 K: every node stays
    above the pole (98 at the coldest), a quadrature point does not (93.6)."""
    text = QUADRATIC.replace("[[0.0, 100.0], [1.0, 100.0], [2.0, 150.0]]", "[[0.0, 110.0], [1.0, 110.0], [2.0, 160.0]]")
    path = tmp_path / "case.toml"
    path.write_text(text.replace("reference = 150.0", "reference = 150.0\nchange = [[0.0, 0.0], [1.0, -12.0]]"))
    code, err = check(capsys, str(path))
    assert code == 2 and re.search(r"temperature\.change: -12 \(its value at t = 1\) brings the coldest", err), err
    assert "105.6" in err, err
