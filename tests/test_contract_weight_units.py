"""A load that, in the units given, would invert the first step is warned about, naming it:
the body's weight too, where the density is typed in kg/m^3 (1000) in a case in mm, t, s
(1e-9 t/mm^3): 1e12 times too heavy."""

from __future__ import annotations

import copy

import pytest
from test_fuzz import BASE, toml
from test_fuzz_files import call


@pytest.mark.parametrize("density, warned", [(1000.0, True), (1.0e-9, False)])
def test_a_weight_in_other_units_is_warned(tmp_path, density, warned):
    case = copy.deepcopy(BASE)
    case["material"]["density"] = density
    case["gravity"] = {"g": -9810.0}
    case["units"] = {"length": "mm", "pressure": "MPa", "time": "s"}
    (tmp_path / "case.toml").write_text(toml(case))
    code, out, err = call(["check", str(tmp_path / "case.toml")])
    assert code == 0, err
    said = "warning: gravity.g: -9810 (material.density 1000) would invert elements within one nominal step"
    assert (said in err) == warned, err
