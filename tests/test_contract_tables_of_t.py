"""A table of T out of reach of every temperature a case reaches is warned about (a kelvin /
Celsius mix-up) whichever table of the law it is: the modulus G_f(T) of [material.freeze]
too, which out of reach would freeze nothing, silently."""

from __future__ import annotations

import re

from test_temperature_domain import case_with, check

FROZEN = {"modulus": [[100.0, 20.0], [150.0, 0.0]]}  # Celsius


def freezing(initial: float):
    """The slab of test_heat_case with a frozen network tabled in Celsius, at `initial` and a
    film 20 below it."""

    def edit(d):
        d["material"]["freeze"] = dict(FROZEN)
        d["temperature"]["initial"] = initial
        d["convection"][0]["ambient"] = initial - 20.0

    return edit


def test_a_freeze_modulus_out_of_reach_is_warned(tmp_path, capsys):
    code, err = check(capsys, case_with(tmp_path, freezing(423.15)))
    assert code == 0, err
    assert re.search(r"warning: material\.freeze\.modulus: the table's temperatures \(100 to 150\) lie outside", err)


def test_a_freeze_modulus_in_reach_is_not_warned(tmp_path, capsys):
    code, err = check(capsys, case_with(tmp_path, freezing(150.0)))
    assert code == 0 and "material.freeze" not in err, err


def test_a_freeze_modulus_in_pa_in_an_mpa_case_is_warned(tmp_path, capsys):
    """G_f(T) is a shear modulus as the law's: 2e7 (Pa typed for 20 MPa) is warned, naming the key."""

    def pascal(d):
        freezing(150.0)(d)
        d["material"]["freeze"] = {"modulus": [[100.0, 2.0e7], [150.0, 0.0]]}
        d["units"] = {"pressure": "MPa"}

    code, err = check(capsys, case_with(tmp_path, pascal))
    assert code == 0 and re.search(
        r"warning: material\.freeze\.modulus: a shear modulus of 2e\+07 MPa is above 10000 MPa", err
    ), err
    code, err = check(capsys, case_with(tmp_path, lambda d: (freezing(150.0)(d), d.update(units={"pressure": "MPa"}))))
    assert code == 0 and "shear modulus" not in err, err


def test_a_freezing_law_under_a_cooling_program_is_not_said_to_ignore_its_temperature(tmp_path, capsys):
    """[material.freeze] with a prescribed cooling ([temperature] change) and no other use of
    the temperature: the frozen network is born from it, so no "changes nothing" warning."""

    def cooled(d):
        d.pop("thermal")
        d.pop("convection")
        d["material"]["freeze"] = dict(FROZEN)
        d["temperature"]["change"] = [[0.0, 0.0], [19.0, -40.0]]
        d["pressure"] = [{"on": {"z": 2.0}, "value": 0.01}]

    code, err = check(capsys, case_with(tmp_path, cooled))
    assert code == 0 and "changes nothing" not in err, err


def test_a_freezing_law_at_a_constant_temperature_is_said_to_ignore_it(tmp_path, capsys):
    def constant(d):
        d.pop("thermal")
        d.pop("convection")
        d["material"]["freeze"] = dict(FROZEN)
        d["pressure"] = [{"on": {"z": 2.0}, "value": 0.01}]

    code, err = check(capsys, case_with(tmp_path, constant))
    assert code == 0 and "warning: temperature: " in err and "changes nothing" in err, err
