"""The registry of hyperelastic laws (materials/registry.py): a law defined here, registered
with one line, is a case-file model (parsed, checked, built and solved) with no other edit."""

from dataclasses import dataclass

import numpy as np
import pytest

from axiform.case.schema import CaseError, build, parse
from axiform.materials import InvariantLaw, Key, LawEntry, registry
from axiform.materials.registry import positive, register
from axiform.solve.solver import solve


@dataclass(frozen=True)
class HalfMuNeoHooke(InvariantLaw):
    """W_iso = mu / 2 (I1_bar - 3) plus kappa/2 (J - 1)^2: neo-Hooke written in its shear modulus."""

    mu: float
    kappa: float

    @property
    def shear_modulus(self) -> float:
        return self.mu

    def psi(self, I1b, I2b):
        return 0.5 * self.mu * (I1b - 3.0)

    def psi_derivatives(self, I1b, I2b, tangent):
        return 0.5 * self.mu + 0.0 * I1b, None, (0.0 * I1b if tangent else None), None, None


def from_case(c, kappa, mu0):
    return HalfMuNeoHooke(c["mu"] if c["mu"] is not None else mu0("mu"), kappa)


@pytest.fixture
def registered():
    """Registers the law for one test, then takes it out of the registry again."""
    register(LawEntry("neo-hooke-mu", HalfMuNeoHooke, (Key("mu", positive, "must be > 0"),), from_case, "mu"))
    yield
    del registry.LAWS["neo-hooke-mu"]


def bore(material):
    """A thick bore r = 1..2 under an inner pressure, plane strain (uz fixed), one load step."""
    return {
        "mesh": {"kind": "rectangle", "r": [1.0, 2.0], "z": [0.0, 1.0], "divisions": [3, 1], "element": "q8"},
        "material": material,
        "fix": [{"at": {"z": 0.0}, "dofs": ["uz"]}, {"at": {"z": 1.0}, "dofs": ["uz"]}],
        "pressure": [{"on": {"r": 1.0}, "value": 0.2}],
        "solver": {"control": "load", "steps": 1},
    }


def solved(material):
    built = build(parse(bore(material)))
    res = solve(built.model, built.control, built.options)
    assert res.status == "finished", res.message
    return built, res.last.u


def test_a_registered_law_runs_from_the_case_file(registered):
    """The new law with mu = 0.8 gives the displacements of neo-Hooke with C1 = 0.4."""
    built, u = solved({"model": "neo-hooke-mu", "mu": 0.8, "kappa": 200.0})
    assert isinstance(built.case.material.build(), HalfMuNeoHooke)
    _, reference = solved({"model": "neo-hooke", "C1": 0.4, "kappa": 200.0})
    assert np.abs(u).max() > 1e-2
    np.testing.assert_allclose(u, reference, rtol=0, atol=1e-12 * np.abs(reference).max())


def test_a_registered_law_is_checked_like_the_others(registered):
    """Its range, its keys and its shear key from E and nu come from its entry."""
    with pytest.raises(CaseError, match=r"material\.mu: must be > 0, got -1"):
        parse(bore({"model": "neo-hooke-mu", "mu": -1.0, "kappa": 200.0}))
    with pytest.raises(CaseError, match=r'material\.C1: does not belong to model = "neo-hooke-mu" \(its keys: mu,'):
        parse(bore({"model": "neo-hooke-mu", "mu": 1.0, "C1": 0.5, "kappa": 200.0}))
    with pytest.raises(CaseError, match=r'material\.mue: unknown key; did you mean "mu"\?'):
        parse(bore({"model": "neo-hooke-mu", "mu": 1.0, "mue": 0.5, "kappa": 200.0}))
    law = parse(bore({"model": "neo-hooke-mu", "E": 3.0, "nu": 0.45})).material.build()
    assert law.shear_modulus == pytest.approx(3.0 / 2.9, rel=1e-14)


def test_an_unregistered_name_is_refused_with_the_registered_ones():
    with pytest.raises(CaseError, match=r"material\.model: Input should be 'neo-hooke', .* or 'arruda-boyce';"):
        parse(bore({"model": "neo-hooke-mu", "mu": 1.0, "kappa": 200.0}))


def test_fit_takes_the_registered_laws_with_a_fit_family(registered, capsys):
    """`fit --model` lists and takes the laws of the registry that have a fit family: the new
    law (without one) is neither listed nor taken."""
    from axiform.cli import build_parser, main

    parser, p_fit = build_parser()
    text = " ".join(p_fit.format_help().split())
    fitted = [name for name, entry in registry.LAWS.items() if entry.fit is not None]
    assert f"the law: {', '.join(fitted)}; or prony, wlf" in text and "neo-hooke-mu" not in text
    with pytest.raises(SystemExit) as exc:
        main(["fit", "data.csv", "--model", "neo-hooke-mu"])
    assert exc.value.code == 2 and "invalid choice: 'neo-hooke-mu'" in capsys.readouterr().err
