"""The results folder's three pictures are laid out by fixed margins (post.margins), without a
layout engine's pass over every text before drawing, and what they draw stays inside the
figure and off the other panels: the plate's folder, and load curves of wide and huge numbers
in a grid."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from matplotlib.backends.backend_agg import FigureCanvasAgg

from axiform.app.run import run
from axiform.post.load_curve_plot import load_curve_figure
from axiform.post.margins import text_width
from axiform.post.plots import FolderInfo, read_history
from axiform.post.results_folder import last_vtu, surfaces_of
from axiform.post.section_plot import deformed_figure
from axiform.post.thickness_plot import thickness_figure

PLATE = Path(__file__).resolve().parents[1] / "examples" / "hughes_carnoy_plate.toml"


@pytest.fixture(scope="module")
def plate(tmp_path_factory) -> Path:
    out = tmp_path_factory.mktemp("plate")
    assert run(str(PLATE), str(out), quiet=True, overrides=["output.plots=false", "solver.steps=8"]) == 0
    return out


def overlaps(a, b) -> bool:
    return a.x0 < b.x1 - 0.5 and b.x0 < a.x1 - 0.5 and a.y0 < b.y1 - 0.5 and b.y0 < a.y1 - 0.5


def assert_laid_out(fig) -> None:
    """No layout engine; every axes' drawing (frame, ticks, labels, offset text) within the
    figure and off every other axes' frame; the title above every axes' drawing."""
    assert fig.get_layout_engine() is None
    renderer = FigureCanvasAgg(fig).get_renderer()
    fig.draw(renderer)
    page = fig.bbox
    boxes = {ax: ax.get_tightbbox(renderer) for ax in fig.axes if ax.get_visible()}
    for ax, box in boxes.items():
        assert page.x0 - 0.5 <= box.x0 and box.x1 <= page.x1 + 0.5, (ax.get_xlabel(), box, page)
        assert page.y0 - 0.5 <= box.y0 and box.y1 <= page.y1 + 0.5, (ax.get_ylabel(), box, page)
        for other in boxes:
            if other is not ax:
                assert not overlaps(box, other.bbox), (ax.get_ylabel(), other.get_ylabel())
    title = next(t for t in fig.texts if t.get_text() == fig.get_suptitle()).get_window_extent(renderer)
    assert title.y1 <= page.y1 + 0.5
    for box in boxes.values():
        assert not overlaps(title, box)


def test_the_plates_three_pictures_fit(plate):
    info, history = FolderInfo.read(plate), read_history(plate / "history.csv")
    assert_laid_out(load_curve_figure(plate / "history.csv", info))
    assert_laid_out(thickness_figure(plate / "thickness.csv", info, history))
    vtu = last_vtu(plate)
    assert_laid_out(deformed_figure(vtu, info, "von_mises", surfaces_of(vtu), history))


@pytest.mark.parametrize("scale", [1.0, -123456.7, 2.5e7, 3e-6])
def test_load_curves_of_wide_numbers_fit(tmp_path, scale):
    """Four monitors (a 2 x 2 grid) of values from tiny to huge (an offset text above the
    axis), a long y label."""
    lam = np.linspace(0.1, 1.0, 12)
    names = ["a_rather_long_monitor_name_of_a_force", "b", "c", "d"]
    rows = [[k + 1, float(x), 3, *(float(scale * x**p) for p in (1, 2, 3, 0.5))] for k, x in enumerate(lam)]
    summary = {
        "title": "wide numbers",
        "units": {"pressure": "MPa", "force": "N"},
        "load": {"quantity": "pressure", "value": 1.0, "name": "pressure"},
        "monitor_quantities": dict.fromkeys(names, "force"),
        "applied": [{"quantity": "pressure", "value": 1.0, "name": "pressure"}],
    }
    (tmp_path / "summary.json").write_text(json.dumps(summary))
    lines = ["step,load_factor,iterations," + ",".join(names)] + [",".join(map(repr, r)) for r in rows]
    (tmp_path / "history.csv").write_text("\n".join(lines) + "\n")
    fig = load_curve_figure(tmp_path / "history.csv", FolderInfo.read(tmp_path))
    assert len([ax for ax in fig.axes if ax.get_visible()]) == 4
    assert_laid_out(fig)


def test_a_text_width_is_never_less_than_drawn():
    """The margins' estimate against the width matplotlib lays the text out at (10 pt): never
    less, and close for the texts of tick labels."""
    from matplotlib.figure import Figure

    fig = Figure(dpi=72)
    renderer = FigureCanvasAgg(fig).get_renderer()
    for text in (
        "\u22126000",
        "0.0035",
        "1e6",
        "12345.678",
        "\u22121.5e+07",
        "thickness ratio t / t0",
        "WWW mm\u00b2%",
    ):
        drawn = fig.text(0, 0, text, fontsize=10).get_window_extent(renderer).width / 72.0
        assert drawn <= text_width(text, 10.0), text
        if not any(c.isalpha() and c != "e" for c in text):
            assert text_width(text, 10.0) <= 1.15 * drawn + 0.02, text
