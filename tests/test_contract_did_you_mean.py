""" "Did you mean" within the law's own keys takes in every key [material] accepts: the
material's `density` (for [gravity] and [thermal]) is offered for a misspelling of it and
listed where nothing is close."""

from __future__ import annotations

import copy

import pytest
from test_fuzz import BASE, toml
from test_fuzz_files import call


@pytest.mark.parametrize(
    "key, said",
    [
        ("densty", 'material.densty: unknown key; did you mean "density"?'),
        ("rho", "this table takes model, C1, C2, kappa, E, nu, viscoelastic, network, freeze, density"),
    ],
)
def test_a_misspelt_density_is_answered_with_the_density(tmp_path, key, said):
    case = copy.deepcopy(BASE)
    case["material"][key] = 1.0e-9
    (tmp_path / "case.toml").write_text(toml(case))
    code, out, err = call(["check", str(tmp_path / "case.toml")])
    assert code == 2 and said in err, err
