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
