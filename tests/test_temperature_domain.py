"""Every temperature a case can reach within the shift's domain: the moulds'
and films' temperatures x their curves checked before any work (exit 2 naming the key), the
Arrhenius shift on absolute temperatures ([units] temperature), a run that stops naming the
pole where a temperature leaves the domain all the same; the heat inputs refused with their
keys, and the warnings of the units' plausibility."""

import re
import tomllib

import numpy as np
import pytest
import tomli_w
from test_heat_case import CASE, MOULD

from axiform import solve
from axiform.case.schema import build, parse
from axiform.cli import main
from axiform.materials.temperature import WLF, Arrhenius, TemperatureDomainError

WLF_SHIFT = {"reference": 150.0, "shift": {"wlf": {"C1": 17.44, "C2": 51.6}}}  # the pole at 98.4


def case_with(tmp_path, edit) -> str:
    """The slab of test_heat_case (a film at 25 on its top face) edited by edit(data)."""
    data = tomllib.loads(CASE)
    edit(data)
    path = tmp_path / "case.toml"
    path.write_text(tomli_w.dumps(data))
    return str(path)


def check(capsys, path) -> tuple[int, str]:
    code = main(["check", path])
    return code, capsys.readouterr().err


def warm(data, ambient=120.0, **shift):
    data["temperature"] |= WLF_SHIFT | shift
    data["convection"][0]["ambient"] = ambient


@pytest.mark.parametrize(
    "edit, key",
    [
        (lambda d: warm(d, 25.0), r"convection\[0\]\.ambient: 25 is at or below the WLF pole T_ref - C2 = 98\.4"),
        (
            lambda d: (warm(d), d.update(contact=[MOULD])),  # the mould at 25
            r"contact\[0\]\.temperature: 25 is at or below the WLF pole",
        ),
        (
            lambda d: (
                warm(d),
                d.update(contact=[MOULD | {"temperature": 120.0, "temperature_curve": [[0, 1], [10, 0.5]]}]),
            ),
            r"contact\[0\]\.temperature: 60 \(120 x its curve at t = 10\) is at or below the WLF pole",
        ),
        (
            lambda d: (warm(d), d["convection"][0].update(curve=[[0.0, 1.0], [38.0, 0.5]])),  # 0.75 at the end, 19
            r"convection\[0\]\.ambient: 90 \(120 x its curve at t = 19\) is at or below",
        ),
        (
            lambda d: (
                d["temperature"].update(initial=400.0, reference=400.0, shift={"arrhenius": {"activation": 8e3}}),
                d["convection"][0].update(ambient=-10.0),
            ),
            r"convection\[0\]\.ambient: -10 is at or below absolute zero",
        ),
        (
            lambda d: (
                d["temperature"].update(reference=0.0, shift={"arrhenius": {"activation": 8e3}}),
                d.update(units={"temperature": "K"}),
            ),
            r"temperature\.reference: the reference temperature 0 is 0 K",
        ),
        (
            lambda d: (
                d["temperature"].update(reference=-300.0, shift={"arrhenius": {"activation": 8e3}}),
                d.update(units={"temperature": "C"}),
            ),
            r"temperature\.reference: .* is -26\.85 K",
        ),
        (
            lambda d: (
                d["temperature"].update(reference=150.0, shift={"arrhenius": {"activation": 8e3}}),
                d["convection"][0].update(ambient=-280.0),
                d.update(units={"temperature": "C"}),
            ),
            r"convection\[0\]\.ambient: -280 is at or below absolute zero \(-273\.15",
        ),
        (
            lambda d: (
                d["temperature"].update(reference=150.0, shift={"arrhenius": {"activation": 8e3}}),
                d.update(units={"temperature": "F"}),
            ),
            r"units\.temperature: an Arrhenius shift needs absolute temperatures",
        ),
    ],
)
def test_a_temperature_beyond_the_shift_is_refused_before_any_work(tmp_path, capsys, edit, key):
    code, err = check(capsys, case_with(tmp_path, edit))
    assert code == 2 and re.search(key, err), err


def test_a_conductance_gap_without_a_conductance_is_refused(tmp_path, capsys):
    mould = {k: v for k, v in MOULD.items() if k not in ("conductance", "temperature")}
    code, err = check(capsys, case_with(tmp_path, lambda d: d.update(contact=[mould | {"conductance_gap": 0.1}])))
    assert code == 2 and re.search(r"contact\[0\]: conductance_gap needs conductance", err), err


def test_a_curve_beyond_the_end_of_the_run_is_not_reached(tmp_path, capsys):
    """A mould at 120 whose curve falls to 0.1 only after the run's end (target 19): valid."""
    mould = MOULD | {"temperature": 120.0, "temperature_curve": [[0.0, 1.0], [19.0, 1.0], [30.0, 0.1]]}
    code, err = check(capsys, case_with(tmp_path, lambda d: (warm(d), d.update(contact=[mould]))))
    assert code == 0, err


def test_arrhenius_in_celsius_shifts_as_in_kelvin():
    """[units] temperature = "C": the shift of 100 C at a reference of 150 C is that of
    373.15 K at 423.15 K; and at or below absolute zero a_T is refused, naming the place."""
    celsius, kelvin = Arrhenius(8.0e3, 150.0, 273.15), Arrhenius(8.0e3, 423.15)
    assert celsius.shift(np.array([100.0, 20.0])) == pytest.approx(kelvin.shift(np.array([373.15, 293.15])), rel=1e-14)
    with pytest.raises(TemperatureDomainError, match="at element 1 is at or below absolute zero"):
        celsius.shift(np.array([[20.0, 30.0], [-300.0, 10.0]]))
    assert kelvin.describe().startswith("absolute zero (0;")  # not "-0"
    assert celsius.describe().startswith("absolute zero (-273.15;")
    with pytest.raises(TemperatureDomainError, match=r"-5 at node 2 is at or below the WLF pole T_ref - C2 = 98\.4"):
        WLF(17.44, 51.6, 150.0).shift(np.array([120.0, 110.0, -5.0]))


def test_a_run_whose_wall_leaves_the_domain_stops_naming_the_pole():
    """A film far below the pole given past the case's checks (through the API): the run
    stops (not a relaxation at a_T = 1e-47 to the end) with the pole and the element."""
    data = tomllib.loads(CASE)
    warm(data)
    data["material"]["viscoelastic"] = {"g": [0.5], "tau": [1.0]}
    built = build(parse(data))
    built.model.conduction.films[0].ambient = lambda t: -200.0
    result = solve(built.model, built.control, built.options)
    assert result.status == "stopped"
    assert re.search(r"at element \d+ is at or below the WLF pole T_ref - C2 = 98\.4", result.message), result.message


@pytest.mark.parametrize(
    "key, value, message",
    [
        ("conductivity", 0.0, "must be > 0"),
        ("density", -1.0, "must be > 0"),
        ("specific_heat", [[100.0, 1.0e9], [200.0, 0.0]], "> 0"),
        ("conductivity", [["hot", 0.2]], "must be a number"),
        ("conductivity", [[True, 0.2]], "must be a number"),
        ("conductivity", [[100.0, 0.2], [90.0, 0.3]], "increase"),
    ],
)
def test_heat_properties_are_range_checked_naming_the_key(tmp_path, capsys, key, value, message):
    code, err = check(capsys, case_with(tmp_path, lambda d: d["thermal"].update({key: value})))
    assert code == 2 and f"thermal.{key}" in err and message in err, err


@pytest.mark.parametrize(
    "edit, key",
    [
        (lambda d: d["convection"][0].update(h=0.0), "convection[0].h"),
        (lambda d: d.update(contact=[MOULD | {"conductance": 0.0}]), "contact[0].conductance"),
        (lambda d: d.update(contact=[MOULD | {"conductance_gap": -0.1}]), "contact[0].conductance_gap"),
    ],
)
def test_film_and_contact_coefficients_are_range_checked_naming_the_key(tmp_path, capsys, edit, key):
    code, err = check(capsys, case_with(tmp_path, edit))
    assert code == 2 and key in err, err


def test_a_table_out_of_reach_of_every_temperature_is_warned(tmp_path, capsys):
    """A constant of the law tabled at 110 to 150 (Celsius) in a case at 423 (kelvin): a
    warning naming the table; the same table in reach: none."""

    def tabled(initial):
        def edit(d):
            d["material"]["C1"] = [[110.0, 0.6], [150.0, 0.5]]
            d["temperature"]["initial"] = initial
            d["convection"][0]["ambient"] = initial - 20.0

        return edit

    code, err = check(capsys, case_with(tmp_path, tabled(423.0)))
    assert code == 0 and re.search(r"warning: material\.C1: the table's temperatures \(110 to 150\) lie outside", err)
    code, err = check(capsys, case_with(tmp_path, tabled(150.0)))
    assert code == 0 and "material.C1" not in err, err


def test_a_modulus_in_pa_in_an_mpa_case_is_warned(tmp_path, capsys):
    def pascal(d):
        d["material"].update(C1=0.5e6, kappa=1.0e9)
        d["units"] = {"pressure": "MPa", "length": "mm"}

    code, err = check(capsys, case_with(tmp_path, pascal))
    assert code == 0 and re.search(r"warning: material: a shear modulus of 1e\+06 MPa is above 10000 MPa", err), err
    code, err = check(capsys, case_with(tmp_path, lambda d: d.update(units={"pressure": "MPa"})))
    assert code == 0 and "shear modulus" not in err, err


def test_an_error_of_the_initial_field_without_a_shift_names_the_initial_field(monkeypatch):
    """The key blamed for a temperature field the model refuses, in a case without shift, is
    temperature.initial (not a shift the case does not have)."""
    from axiform.case.base import CaseError
    from axiform.model.model import Model

    def refuse(self, T, shift=None):
        raise ValueError("every temperature must be a finite number")

    monkeypatch.setattr(Model, "heat", refuse)
    with pytest.raises(CaseError, match=r"^temperature\.initial: every temperature must be a finite number"):
        build(parse(tomllib.loads(CASE)))
