"""`axiform fit` (docs/guide.md: axiform fit): the incompressible test stresses of every law against
their closed forms, the Drucker check against differences of the energy, fitting recovers the
constants that generated synthetic data, the command on Treloar's data, bad files refused
with exit 2 and the line named."""

import json
import re
import tomllib
from pathlib import Path

import numpy as np
import pytest

from axiform.app.fit import fit
from axiform.case.material import MaterialSpec
from axiform.cli import main
from axiform.materials import ArrudaBoyce, Gent, MooneyRivlin, Ogden, Yeoh
from axiform.materials.arruda_boyce import SERIES
from axiform.materials.homogeneous import (
    MODES,
    STABILITY_STRETCHES,
    Data,
    drucker_stable,
    kinematics,
    nominal_stress,
    stable_range,
)

TRELOAR = Path(__file__).resolve().parents[1] / "examples" / "data" / "treloar.csv"

# (model name, law, constants as the case file names them, terms)
TRUE = [
    ("neo-hooke", MooneyRivlin(0.2, 0.0, 1.0), {"C1": 0.2}, None),
    ("mooney-rivlin", MooneyRivlin(0.16, 0.02, 1.0), {"C1": 0.16, "C2": 0.02}, None),
    ("yeoh", Yeoh(0.18, -0.002, 5e-5, 1.0), {"C10": 0.18, "C20": -0.002, "C30": 5e-5}, None),
    ("ogden", Ogden((0.4, 0.004), (1.5, 4.8), 1.0), {"mu": [0.4, 0.004], "alpha": [1.5, 4.8]}, 2),
    ("gent", Gent(0.35, 90.0, 1.0), {"mu": 0.35, "Jm": 90.0}, None),
    ("arruda-boyce", ArrudaBoyce(0.33, 4.5, 1.0), {"mu": 0.33, "lambda_m": 4.5}, None),
]


def closed_form(law, mode, lam):
    """Incompressible nominal stress, lt the (free) thickness stretch, l2 the lateral one:
    invariant laws P = 2/lam ((lam^2 - lt^2) W1 - (lam^-2 - lt^-2) W2),
    Ogden P = sum 2 mu/alpha (lam^(alpha-1) - lt^alpha / lam)."""
    l2, lt = {"uniaxial": (lam**-0.5, lam**-0.5), "equibiaxial": (lam, lam**-2), "planar": (1.0, 1 / lam)}[mode]
    if isinstance(law, Ogden):
        return sum(2 * m / a * (lam ** (a - 1) - lt**a / lam) for m, a in zip(law.mu, law.alpha, strict=False))
    I1 = lam**2 + l2**2 + lt**2
    W2 = 0.0
    if isinstance(law, MooneyRivlin):
        W1, W2 = law.C1, law.C2
    elif isinstance(law, Yeoh):
        W1 = law.C10 + 2 * law.C20 * (I1 - 3) + 3 * law.C30 * (I1 - 3) ** 2
    elif isinstance(law, Gent):
        W1 = law.mu / 2 / (1 - (I1 - 3) / law.Jm)
    else:
        i = np.arange(1, 6)[:, None]
        W1 = law.mu * np.sum(i * SERIES[:, None] * law.lambda_m ** (2.0 - 2 * i) * I1 ** (i - 1), axis=0)
    return 2 / lam * ((lam**2 - lt**2) * W1 - (lam**-2 - lt**-2) * W2)


@pytest.mark.parametrize("name, law, table, terms", TRUE, ids=[t[0] for t in TRUE])
@pytest.mark.parametrize("mode", MODES)
def test_test_stress_against_closed_form(name, law, table, terms, mode):
    lam = np.array([0.5, 0.8, 1.001, 1.5, 3.0, 6.0])
    assert np.allclose(nominal_stress(law, mode, lam), closed_form(law, mode, lam), rtol=1e-11, atol=1e-15)
    x = kinematics(mode, lam)
    assert np.allclose(x[:, 4] * x[:, 0] * x[:, 3], 1.0, rtol=1e-14)  # incompressible


def hessian_by_differences(law, mode, lam, h=1e-4):
    """D (n, 2, 2): second differences of W_iso(eps1, eps2) at the test's log strains."""
    x0 = kinematics(mode, lam)
    e0 = np.log(x0[:, [0, 4]])

    def W(e):
        x = np.zeros((len(lam), 5))
        x[:, 0], x[:, 4], x[:, 3] = np.exp(e[:, 0]), np.exp(e[:, 1]), np.exp(-e[:, 0] - e[:, 1])
        return law.iso_energy(x)

    D = np.empty((len(lam), 2, 2))
    for i in range(2):
        for j in range(2):
            di, dj = h * np.eye(2)[i], h * np.eye(2)[j]
            D[:, i, j] = (W(e0 + di + dj) - W(e0 + di - dj) - W(e0 - di + dj) + W(e0 - di - dj)) / (4 * h * h)
    return D


@pytest.mark.parametrize(
    "law",
    [
        Yeoh(0.5, -0.05, 0.0, 1.0),
        Ogden((0.5, -0.3), (2.0, 6.0), 1.0),
        MooneyRivlin(0.4, -0.15, 1.0),
        Gent(1.0, 30.0, 1.0),
        ArrudaBoyce(1.0, 3.0, 1.0),
    ],
)
@pytest.mark.parametrize("mode", MODES)
def test_drucker_check_against_differences_of_the_energy(law, mode):
    """Stability where the 2x2 Hessian of W_iso in the log strains is positive definite; the
    first three laws lose it inside 0.1 to 10 (checked away from the switch points)."""
    lam = STABILITY_STRETCHES[::8]
    D = hessian_by_differences(law, mode, lam)
    eig = np.linalg.eigvalsh(D)
    clear = np.isfinite(eig).all(axis=1) & (np.abs(eig).min(axis=1) > 1e-4 * np.abs(eig).max(axis=1))
    assert clear.sum() >= 20
    assert np.array_equal(drucker_stable(law, mode, lam)[clear], (eig[clear] > 0).all(axis=1))


def test_stable_range_is_the_interval_around_one():
    lam = np.array([0.1, 0.5, 1.0, 2.0, 10.0])
    assert stable_range(np.array([False, True, True, True, False]), lam) == (0.5, 2.0)
    assert stable_range(np.array([True, False, True, False, True]), lam) == (1.0, 1.0)
    assert stable_range(np.array([True] * 5), lam) == (0.1, 10.0)
    assert stable_range(np.array([True, True, False, True, True]), lam) is None
    unstable_yeoh = Yeoh(0.5, -0.05, 0.0, 1.0)  # Psi_1 < 0 once I1 - 3 > 5
    lo, hi = stable_range(drucker_stable(unstable_yeoh, "uniaxial", STABILITY_STRETCHES))
    assert 0.1 < lo < 1.0 < hi < 10.0
    assert hi**2 + 2 / hi - 3 < 5.0  # lost before the energy's slope turns negative


def synthetic(law):
    """Exact test data of a law on the three modes, tension and some compression."""
    stretches = {
        "uniaxial": np.r_[0.7, np.linspace(1.1, 6.0, 12)],
        "equibiaxial": np.linspace(1.1, 4.0, 8),
        "planar": np.linspace(1.1, 4.5, 8),
    }
    modes = np.concatenate([np.full(len(v), MODES.index(m)) for m, v in stretches.items()])
    lam = np.concatenate(list(stretches.values()))
    stress = np.concatenate([nominal_stress(law, m, v) for m, v in stretches.items()])
    return Data(modes, lam, stress)


@pytest.mark.parametrize("name, law, table, terms", TRUE, ids=[t[0] for t in TRUE])
def test_fit_recovers_the_constants_of_synthetic_data(name, law, table, terms):
    result = fit(synthetic(law), name, terms or 3, kappa=7.0)
    assert result is not None
    got = result.table
    if name == "ogden":  # the terms may come in any order
        order = np.argsort(got["alpha"])
        got = {"mu": list(np.array(got["mu"])[order]), "alpha": list(np.array(got["alpha"])[order])}
    assert got.keys() == table.keys()
    for key, value in table.items():
        assert np.allclose(got[key], value, rtol=1e-6, atol=1e-9), key
    assert all(r < 1e-8 for r in result.rms.values())
    assert result.law.kappa == 7.0


def test_fit_command_on_treloar_data(tmp_path, capsys):
    out = tmp_path / "fit"
    assert main(["fit", str(TRELOAR), "--model", "mooney-rivlin", "--out", str(out)]) == 0
    printed = capsys.readouterr().out
    text = (out / "material.toml").read_text()
    assert "[material]" in printed and 'model = "mooney-rivlin"' in printed and "Drucker" in printed
    spec = MaterialSpec.model_validate(tomllib.loads(text)["material"])
    law = spec.build()
    summary = json.loads((out / "fit.json").read_text())
    assert summary["model"] == "mooney-rivlin"
    assert summary["parameters"].keys() == {"C1", "C2"}
    assert law.C1 == pytest.approx(summary["parameters"]["C1"], rel=1e-5)
    assert summary["shear_modulus"] == pytest.approx(2 * (law.C1 + law.C2), rel=1e-5)
    assert summary["kappa"] == pytest.approx(1000 * summary["shear_modulus"])
    assert law.kappa == pytest.approx(summary["kappa"], rel=1e-5)
    assert summary["points"] == {"uniaxial": 24, "equibiaxial": 16, "planar": 13}
    assert set(summary["rms_relative_error"]) == set(MODES)
    assert all(0 < v < 0.5 for v in summary["rms_relative_error"].values())
    assert summary["stable_range"] == [0.1, 10.0]  # C1, C2 >= 0: stable everywhere
    for mode in MODES:
        assert (out / f"fit_{mode}.png").stat().st_size > 10_000


def test_fit_ogden_with_kappa(tmp_path):
    out = tmp_path / "fit"
    assert main(["fit", str(TRELOAR), "--model", "ogden", "--terms", "1", "--kappa", "500", "--out", str(out)]) == 0
    spec = MaterialSpec.model_validate(tomllib.loads((out / "material.toml").read_text())["material"])
    law = spec.build()
    assert isinstance(law, Ogden) and len(law.mu) == 1 and law.kappa == 500.0


BAD_CSV = [
    (
        "text in a number",
        "mode,stretch,stress\nuniaxial,1.5,0.3\nuniaxial,2.0,abc\n",
        r"line 3: stress 'abc' is not a number",
    ),
    ("unknown mode", "mode,stretch,stress\nuniaxial,1.5,0.3\nshear,2.0,0.5\n", r"line 3: unknown mode 'shear'"),
    ("header", "lambda,stress\n1.5,0.3\n", r"line 1: the header must be mode,stretch,stress"),
    ("columns", "mode,stretch,stress\nuniaxial,1.5\n", r"line 2: expected 3 values"),
    ("negative stretch", "mode,stretch,stress\nplanar,-1.5,0.3\n", r"line 2: stretch must be > 0"),
    ("no rows", "mode,stretch,stress\n", r"no data rows"),
]


@pytest.mark.parametrize("name, text, message", BAD_CSV, ids=[b[0] for b in BAD_CSV])
def test_bad_data_file_exits_2_naming_the_line(tmp_path, capsys, name, text, message):
    data = tmp_path / "data.csv"
    data.write_text(text)
    assert main(["fit", str(TRELOAR), str(data), "--model", "neo-hooke", "--out", str(tmp_path / "o")]) == 2
    err = capsys.readouterr().err
    assert str(data) in err
    assert re.search(message, err), err
    assert not (tmp_path / "o").exists()


def test_bad_arguments_exit_2(tmp_path, capsys):
    out = str(tmp_path / "o")
    assert main(["fit", str(TRELOAR), "--model", "gent", "--terms", "2", "--out", out]) == 2
    assert main(["fit", str(TRELOAR), "--model", "ogden", "--terms", "7", "--out", out]) == 2
    assert main(["fit", str(TRELOAR), "--model", "gent", "--kappa", "-1", "--out", out]) == 2
    assert main(["fit", str(tmp_path / "missing.csv"), "--model", "gent", "--out", out]) == 2
    with pytest.raises(SystemExit) as exc:
        main(["fit", str(TRELOAR), "--model", "hooke"])
    assert exc.value.code == 2
