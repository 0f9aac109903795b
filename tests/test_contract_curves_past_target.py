"""A curve that runs past [solver] target is warned about whichever table gives it: besides the
loads and the moulds' motions, the body's weight, a film's ambient, a mould's temperature and
the prescribed change of temperature (an oven program cut short as much as a load)."""

from __future__ import annotations

import pytest
from test_heat_case import MOULD
from test_temperature_domain import case_with, check

LATE = [[0.0, 1.0], [19.0, 1.0], [30.0, 0.8]]  # changes after the slab's target, 19


@pytest.mark.parametrize(
    "edit, key",
    [
        (
            lambda d: (d["material"].update(density=1.0e-9), d.update(gravity={"g": -9810.0, "curve": LATE})),
            "gravity.curve",
        ),
        (lambda d: d["convection"][0].update(curve=LATE), "convection[0].curve"),
        (
            lambda d: d.update(contact=[MOULD | {"temperature": 120.0, "temperature_curve": LATE}]),
            "contact[0].temperature_curve",
        ),
        (
            lambda d: (
                d.pop("thermal"),
                d.pop("convection"),
                d["temperature"].update(change=[[0.0, 0.0], [30.0, -9.0]]),
                d.update(pressure=[{"on": {"z": 2.0}, "value": 0.01}]),
            ),
            "temperature.change",
        ),
    ],
)
def test_a_curve_past_the_target_is_warned(tmp_path, capsys, edit, key):
    code, err = check(capsys, case_with(tmp_path, edit))
    assert code == 0, err
    assert f"warning: {key}: the curve runs to t = 30, but the run ends at [solver] target = 19" in err, err


def test_a_curve_constant_after_the_target_is_not_warned(tmp_path, capsys):
    code, err = check(
        capsys, case_with(tmp_path, lambda d: d["convection"][0].update(curve=[[0.0, 1.0], [19.0, 0.9], [30.0, 0.9]]))
    )
    assert code == 0 and "the curve runs to" not in err, err
