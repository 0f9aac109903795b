"""`axiform fit --model prony|wlf` (docs/guide.md): the series' moduli against the
project's Prony convention and the complex modulus, a known 3-term series recovered from its
relaxation modulus and from its DMA moduli, known WLF constants recovered (and moved to
another reference by the exact change of reference), the command's files and their snippets
accepted by the case schema, bad input refused with exit 2 naming the column or option."""

import json
import re
import tomllib
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st
from test_fuzz_files import _settings, call, csv_texts, judge, seeded, spoil_text

from axiform.case.material import MaterialSpec
from axiform.case.temperature import TemperatureSpec
from axiform.cli import main
from axiform.materials.viscoelastic import Prony, Viscoelastic
from axiform.materials.viscoelastic_fit import (
    decades,
    dynamic_moduli,
    fit_dynamic,
    fit_relaxation,
    fit_wlf,
    relaxation_modulus,
    time_grid,
    wlf_shift,
    zero_crossing,
)

E0, G, TAU = 12.0, np.array([0.3, 0.25, 0.2]), np.array([0.02, 0.7, 40.0])
TIMES = np.geomspace(1e-3, 1e3, 25)
DMA_TAU = np.array([0.005, 0.1, 3.0])
FREQUENCIES = np.geomspace(1e-2, 1e2, 20)
C1, C2, T_REF = 17.44, 51.6, 110.0
TEMPERATURES = np.arange(100.0, 181.0, 10.0)
EXAMPLES = Path(__file__).resolve().parents[1] / "examples" / "data"


def write_csv(path: Path, header: str, *columns) -> Path:
    rows = "\n".join(",".join(repr(float(v)) for v in row) for row in zip(*columns, strict=False))
    path.write_text(f"# test data\n{header}\n{rows}\n")
    return path


def test_series_moduli_against_the_convention_and_the_complex_modulus():
    """E(t) = E0 g(t) of materials.viscoelastic.Prony; E' + i E'' = E_inf + sum E_i i w tau /
    (1 + i w tau), the Fourier transform of the relaxation modulus."""
    assert np.allclose(
        relaxation_modulus(E0, G, TAU, TIMES), E0 * Prony(tuple(G), tuple(TAU)).relaxation(TIMES), rtol=1e-14
    )
    iwt = 2j * np.pi * FREQUENCIES[:, None] * DMA_TAU
    complex_modulus = E0 * (1 - G.sum()) + (E0 * G * iwt / (1 + iwt)).sum(-1)
    storage, loss = dynamic_moduli(E0, G, DMA_TAU, FREQUENCIES)
    assert np.allclose(storage, complex_modulus.real, rtol=1e-14)
    assert np.allclose(loss, complex_modulus.imag, rtol=1e-14)


def test_default_terms_and_grid():
    assert decades(1e-3, 1e3) == 6 and decades(1.0, 2.0) == 1 and decades(1e-6, 1e6) == 8
    assert np.allclose(np.log10(time_grid(1e-3, 1e3, 6)), [-2.5, -1.5, -0.5, 0.5, 1.5, 2.5], rtol=1e-13)


@pytest.mark.parametrize("terms", [3, 6])
def test_relaxation_modulus_of_three_terms_recovered(terms):
    """3 terms, or the default 6 (one per decade): the 3 surplus ones carry no modulus and go."""
    fit = fit_relaxation(TIMES, relaxation_modulus(E0, G, TAU, TIMES), terms)
    assert fit.dropped == terms - 3
    assert fit.E0 == pytest.approx(E0, rel=1e-9)
    assert np.allclose(fit.g, G, rtol=1e-8)
    assert np.allclose(fit.tau, TAU, rtol=1e-8)
    assert fit.long_term == pytest.approx(E0 * (1 - G.sum()), rel=1e-9)
    assert np.abs(fit.residual).max() < 1e-9


def test_dma_moduli_of_three_terms_recovered():
    fit = fit_dynamic(FREQUENCIES, *dynamic_moduli(E0, G, DMA_TAU, FREQUENCIES), 3)
    assert fit.dropped == 0
    assert fit.E0 == pytest.approx(E0, rel=1e-10)
    assert np.allclose(fit.g, G, rtol=1e-9)
    assert np.allclose(fit.tau, DMA_TAU, rtol=1e-9)
    assert fit.residual.shape == (2 * len(FREQUENCIES),) and np.abs(fit.residual).max() < 1e-12


def test_wlf_constants_recovered_and_moved_to_another_reference():
    """At T_ref = 130 the same shift is WLF with C2' = C2 + 20, C1' = C1 C2 / C2', offset the
    data's log10 a_T at 130."""
    y = wlf_shift(TEMPERATURES, C1, C2, T_REF)
    assert zero_crossing(TEMPERATURES, y) == T_REF
    fit = fit_wlf(TEMPERATURES, y, T_REF, offset=False)
    assert (fit.C1, fit.C2, fit.offset) == (pytest.approx(C1, rel=1e-10), pytest.approx(C2, rel=1e-10), 0.0)
    moved = fit_wlf(TEMPERATURES, y, 130.0, offset=True)
    assert moved.C2 == pytest.approx(C2 + 20.0, rel=1e-10)
    assert moved.C1 == pytest.approx(C1 * C2 / (C2 + 20.0), rel=1e-10)
    assert moved.offset == pytest.approx(wlf_shift(130.0, C1, C2, T_REF), rel=1e-10)
    assert np.abs(moved.residual).max() < 1e-12


def test_zero_crossing_interpolates():
    assert zero_crossing(np.array([0.0, 10.0, 20.0]), np.array([1.0, 0.5, -1.5])) == pytest.approx(12.5, rel=1e-14)
    assert zero_crossing(np.array([0.0, 10.0]), np.array([-1.0, -2.0])) is None


def spec_with_law(text: str, modulus: float) -> MaterialSpec:
    """The [material] snippet completed with the neo-Hooke law of its commented initial modulus."""
    table = tomllib.loads(text)["material"]
    assert set(table) == {"viscoelastic"}
    assert f"# C1 = {modulus / 6:.6g}" in text
    return MaterialSpec.model_validate(table | {"model": "neo-hooke", "C1": modulus / 6, "kappa": 1000.0})


@pytest.mark.parametrize("kind", ["relaxation", "dma"])
def test_prony_command_writes_a_valid_material(tmp_path, capsys, kind):
    if kind == "relaxation":
        data = write_csv(tmp_path / "d.csv", "time,modulus", TIMES, relaxation_modulus(E0, G, TAU, TIMES))
        tau = TAU
    else:
        data = write_csv(
            tmp_path / "d.csv", "frequency,storage,loss", FREQUENCIES, *dynamic_moduli(E0, G, DMA_TAU, FREQUENCIES)
        )
        tau = DMA_TAU
    out = tmp_path / "fit"
    assert main(["fit", str(data), "--model", "prony", "--terms", "3", "--out", str(out)]) == 0
    assert "Prony series of 3 terms" in capsys.readouterr().out
    law = spec_with_law((out / "material.toml").read_text(), E0).build()
    assert isinstance(law, Viscoelastic)
    assert np.allclose(law.prony.g, G, rtol=1e-7) and np.allclose(law.prony.tau, tau, rtol=1e-7)
    assert law.law.shear_modulus == pytest.approx(E0 / 3, rel=1e-6)
    summary = json.loads((out / "fit.json").read_text())
    assert summary["model"] == "prony" and summary["terms"] == 3
    assert summary["instantaneous_modulus"] == pytest.approx(E0, rel=1e-9)
    assert summary["long_term_modulus"] == pytest.approx(E0 * (1 - G.sum()), rel=1e-9)
    assert all(v < 1e-9 for v in summary["rms_relative_error"].values())
    assert (out / "fit_prony.png").stat().st_size > 10_000


def test_wlf_command_writes_the_temperature_table(tmp_path):
    data = write_csv(
        tmp_path / "shift.csv", "temperature,log10_shift", TEMPERATURES, wlf_shift(TEMPERATURES, C1, C2, T_REF)
    )
    out = tmp_path / "fit"
    assert main(["fit", str(data), "--model", "wlf", "--out", str(out)]) == 0
    table = tomllib.loads((out / "material.toml").read_text())["temperature"]
    assert table["reference"] == T_REF
    assert table["shift"]["wlf"] == {"C1": pytest.approx(C1, rel=1e-7), "C2": pytest.approx(C2, rel=1e-7)}
    shift = TemperatureSpec.model_validate(table | {"initial": 150.0}).build_shift()
    assert np.allclose(np.log10(shift.shift(TEMPERATURES)), wlf_shift(TEMPERATURES, C1, C2, T_REF), atol=1e-6)
    summary = json.loads((out / "fit.json").read_text())
    assert summary["reference_from"] == "data"
    assert summary["pole_margin"] == pytest.approx(C2 + TEMPERATURES[0] - T_REF, rel=1e-9)
    assert (out / "fit_wlf.png").stat().st_size > 10_000


def test_example_data_fit(tmp_path):
    """The shipped examples: the relaxation curve within its 1 % noise, the shifts' WLF
    constants near those they were drawn from."""
    assert main(["fit", str(EXAMPLES / "relaxation.csv"), "--model", "prony", "--out", str(tmp_path / "p")]) == 0
    summary = json.loads((tmp_path / "p" / "fit.json").read_text())
    assert summary["rms_relative_error"]["modulus"] < 0.015
    assert main(["fit", str(EXAMPLES / "wlf_shift.csv"), "--model", "wlf", "--out", str(tmp_path / "w")]) == 0
    summary = json.loads((tmp_path / "w" / "fit.json").read_text())
    assert summary["C1"] == pytest.approx(C1, rel=0.05) and summary["C2"] == pytest.approx(C2, rel=0.1)


RELAX = "time,modulus\n0.1,10\n1,8\n10,6\n100,5\n"
BAD = [
    (
        "header",
        "time,stress\n0.1,10\n",
        ["--model", "prony"],
        r"line 1: the header must be time,modulus or "
        r"frequency,storage,loss",
    ),
    ("text", "time,modulus\n0.1,10\n1,x\n", ["--model", "prony"], r"line 3: modulus 'x' is not a number"),
    (
        "magnitude",
        "time,modulus\n1e-300,10\n1,8\n10,6\n",
        ["--model", "prony"],
        r"line 2: time 1e-300 is beyond the magnitude",
    ),
    ("zero time", "time,modulus\n0,10\n1,8\n10,6\n", ["--model", "prony"], r"line 2: time must be > 0"),
    ("negative modulus", "time,modulus\n0.1,10\n1,-8\n10,6\n", ["--model", "prony"], r"line 3: modulus must be > 0"),
    ("zero loss", "frequency,storage,loss\n1,5,0.1\n2,6,0\n", ["--model", "prony"], r"line 3: loss must be > 0"),
    ("time order", "time,modulus\n0.1,10\n10,8\n1,6\n", ["--model", "prony"], r"line 4: time must increase"),
    (
        "frequency order",
        "frequency,storage,loss\n1,5,1\n1,6,1\n",
        ["--model", "prony"],
        r"line 3: frequency must increase",
    ),
    (
        "creep compliance",
        "time,modulus\n0.1,1\n1,2\n10,3\n",
        ["--model", "prony"],
        r"line 4: modulus rises from 1 at the first time to 3 at the last",
    ),
    (
        "storage falls",
        "frequency,storage,loss\n1,5,1\n2,4,1\n",
        ["--model", "prony"],
        r"line 3: storage falls from 5 at the first frequency to 4 at the last",
    ),
    ("too few points", RELAX, ["--model", "prony", "--terms", "2"], r"--terms 2: 5 parameters .* holds 4 values"),
    ("one point", "time,modulus\n0.1,10\n", ["--model", "prony"], r"1 values, fewer than the 3 parameters"),
    ("terms", RELAX, ["--model", "prony", "--terms", "9"], r"--terms must be 1 to 8"),
    ("reference for prony", RELAX, ["--model", "prony", "--reference", "100"], r"--reference is for --model wlf"),
    ("kappa for prony", RELAX, ["--model", "prony", "--kappa", "100"], r"--kappa is for the hyperelastic laws"),
    (
        "terms for wlf",
        "temperature,log10_shift\n100,1\n110,0\n",
        ["--model", "wlf", "--terms", "2"],
        r"--terms is for --model prony",
    ),
    ("wlf header", "T,log10_shift\n100,1\n", ["--model", "wlf"], r"the header must be temperature,log10_shift"),
    (
        "shift order",
        "temperature,log10_shift\n100,1\n110,0\n120,0.5\n",
        ["--model", "wlf"],
        r"line 4: log10_shift must decrease as the temperature rises",
    ),
    (
        "temperature order",
        "temperature,log10_shift\n110,1\n100,0\n",
        ["--model", "wlf"],
        r"line 3: temperature must increase",
    ),
    (
        "no zero",
        "temperature,log10_shift\n100,-1\n110,-2\n120,-3\n",
        ["--model", "wlf"],
        r"log10_shift does not reach 0 .* --reference",
    ),
    (
        "wlf points",
        "temperature,log10_shift\n100,1\n110,0\n",
        ["--model", "wlf", "--reference", "105"],
        r"2 rows, fewer than the 3 parameters",
    ),
]


@pytest.mark.parametrize("name, text, args, message", BAD, ids=[b[0] for b in BAD])
def test_bad_input_exits_2_naming_the_key(tmp_path, capsys, name, text, args, message):
    data = tmp_path / "data.csv"
    data.write_text(text)
    assert main(["fit", str(data), *args, "--out", str(tmp_path / "o")]) == 2
    err = capsys.readouterr().err
    assert re.search(message, err), err
    assert not (tmp_path / "o").exists()


def test_two_files_refused(tmp_path, capsys):
    data = write_csv(tmp_path / "d.csv", "time,modulus", TIMES, relaxation_modulus(E0, G, TAU, TIMES))
    assert main(["fit", str(data), str(data), "--model", "prony", "--out", str(tmp_path / "o")]) == 2
    assert "--model prony fits one data file, got 2" in capsys.readouterr().err


def test_no_admissible_series_or_shift_exits_1(tmp_path, capsys):
    """A melt's curve relaxing to nothing has no long-term modulus, a constant one no
    relaxation; shifts steeper at their coldest point than any WLF curve drive the fit into
    the pole."""
    melt = write_csv(tmp_path / "melt.csv", "time,modulus", TIMES, 10.0 * np.exp(-TIMES / 0.5) + 1e-9)
    assert main(["fit", str(melt), "--model", "prony", "--out", str(tmp_path / "o1")]) == 1
    assert "no long-term modulus" in capsys.readouterr().err
    flat = write_csv(tmp_path / "flat.csv", "time,modulus", TIMES, np.full(TIMES.size, 3.0))
    assert main(["fit", str(flat), "--model", "prony", "--out", str(tmp_path / "o3")]) == 1
    assert "no relaxation" in capsys.readouterr().err
    steep = write_csv(tmp_path / "steep.csv", "temperature,log10_shift", [100, 101, 110, 130, 150], [40, 1, 0, -2, -3])
    assert main(["fit", str(steep), "--model", "wlf", "--out", str(tmp_path / "o2")]) == 1
    assert "C2 + T - T_ref must stay > 0" in capsys.readouterr().err
    # a reference below the data whose shifts want the pole above it: C2 would be <= 0
    assert main(["fit", str(steep), "--model", "wlf", "--reference", "50", "--out", str(tmp_path / "o4")]) == 1
    assert "must stay > 0 over the data and at T_ref" in capsys.readouterr().err


FUZZ_FILES = [
    ("relaxation", ["time", "modulus"], [["0.1", "10"], ["1", "8"], ["10", "6"], ["100", "5"]], []),
    ("dma", ["frequency", "storage", "loss"], [["0.1", "5", "1"], ["1", "7", "2"], ["10", "9", "1"]], []),
    ("wlf", ["temperature", "log10_shift"], [["100", "2"], ["110", "0"], ["120", "-1.5"]], []),
    ("wlf", ["temperature", "log10_shift"], [["100", "2"], ["110", "0"], ["120", "-1.5"]], ["--reference", "115"]),
]


@_settings
@given(st.data())
def _fuzz_viscoelastic(folder, data):
    name, header, rows, extra = data.draw(st.sampled_from(FUZZ_FILES))
    csv = folder / f"{name}.csv"
    csv.write_bytes(spoil_text(data.draw, data.draw(csv_texts(header, rows))))
    model = "wlf" if name == "wlf" else "prony"
    terms = data.draw(st.sampled_from([[], [], ["--terms", "1"], ["--terms", "2"]])) if model == "prony" else []
    code, out, err = call(["fit", str(csv), "--model", model, *terms, *extra, "--out", str(folder / "o")])
    judge(code, out, err, (str(csv),))


def test_fuzzed_data_never_crash(tmp_path, monkeypatch):
    """Hypothesis's broken files (tests/test_fuzz_files.py): exit 0, 1 or 2, no traceback, an
    exit 2 naming the file or the option."""
    import axiform.app.fit_viscoelastic as command

    for plot in ("plot_relaxation", "plot_dynamic", "plot_wlf"):  # the PNGs: not the reader
        monkeypatch.setattr(command, plot, lambda *args: None)
    seeded(_fuzz_viscoelastic)(tmp_path)
