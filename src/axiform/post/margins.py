"""Fixed margins for the results folder's pictures, worked out from the texts they hold: the
room of each axes' tick labels (the labels its locator and formatter give, measured by the
advance widths of the default font), of its axis labels and of the figure's title.

matplotlib's constrained layout finds the same room by laying out every text of the figure
once before drawing it (a third of a picture's time); these estimates need no text drawn.
A margin is a little wider than the text it holds (an unknown character counts as a wide
one), never narrower."""

from __future__ import annotations

from typing import Any

PT = 1.0 / 72.0  # inches per point
# advance widths (em) of DejaVu Sans, matplotlib's default font, for the characters of numbers;
# any other character counts as WIDE, the widest of the font's (W, m, %)
ADVANCE = {**dict.fromkeys("0123456789", 0.636), ".": 0.318, ",": 0.318, " ": 0.318}
ADVANCE |= {"\u2212": 0.838, "+": 0.838, "-": 0.361, "e": 0.615, "x": 0.592, "(": 0.390, ")": 0.390}
WIDE = 1.0
LINE = 1.2  # a line of text is 1.2 font sizes high
EDGE = 0.08  # inches between a text and the figure's edge


def text_width(text: str, size_pt: float) -> float:
    """Width in inches of the widest line of `text` at `size_pt` points."""
    return max((sum(ADVANCE.get(c, WIDE) for c in line) for line in text.split("\n")), default=0.0) * size_pt * PT


def _points(size: float | str) -> float:
    """A font size of matplotlib's rcParams (10, "medium"...) in points."""
    from matplotlib.font_manager import FontProperties

    return float(FontProperties(size=size).get_size_in_points())


def tick_texts(axis) -> tuple[list[str], str]:
    """The major tick labels an axis will draw within its view, and its offset text ("1e6"),
    from its locator and formatter (no text is laid out)."""
    lo, hi = sorted(axis.get_view_interval())
    pad = 1e-10 * max(abs(lo), abs(hi), 1.0)
    locs = [v for v in axis.get_major_locator()() if lo - pad <= v <= hi + pad]
    formatter = axis.get_major_formatter()
    labels = formatter.format_ticks(locs) if locs else []
    return labels, formatter.get_offset() if hasattr(formatter, "get_offset") else ""


def room(ax) -> dict[str, float]:
    """Inches an axes needs outside its frame: left (y tick labels and the y label), bottom
    (x tick labels and the x label), top (the y offset text and half a tick label), right
    (half the last x tick label)."""
    from matplotlib import rcParams

    ax.get_xlim(), ax.get_ylim()  # the view, autoscaled
    tick, label = _points(rcParams["ytick.labelsize"]), _points(rcParams["axes.labelsize"])
    ticks = (rcParams["ytick.major.size"] + rcParams["ytick.major.pad"]) * PT
    ylabels, yoffset = tick_texts(ax.yaxis)
    xlabels, _ = tick_texts(ax.xaxis)
    lines_y = ax.get_ylabel().count("\n") + 1 if ax.get_ylabel() else 0
    lines_x = ax.get_xlabel().count("\n") + 1 if ax.get_xlabel() else 0
    return {
        "left": ticks
        + max((text_width(t, tick) for t in ylabels), default=0.0)
        + (rcParams["axes.labelpad"] * PT + lines_y * LINE * label * PT if lines_y else 0.0)
        + EDGE,
        "bottom": ticks
        + (LINE * tick * PT if xlabels else 0.0)
        + (rcParams["axes.labelpad"] * PT + lines_x * LINE * label * PT if lines_x else 0.0)
        + EDGE,
        "top": (LINE * tick * PT if yoffset else 0.0) + 0.5 * LINE * tick * PT,
        "right": 0.5 * text_width(xlabels[-1], tick) if xlabels else 0.0,
    }


def title_room(fig) -> float:
    """Inches from the top of the figure to the bottom of its title (suptitle at y = 0.98)."""
    from matplotlib import rcParams

    text = fig.get_suptitle()
    if not text:
        return EDGE
    size = next((t.get_fontsize() for t in fig.texts if t.get_text() == text), _points(rcParams["figure.titlesize"]))
    return 0.02 * fig.get_size_inches()[1] + (text.count("\n") + 1) * LINE * size * PT + EDGE


def grid_margins(fig, axes: Any) -> None:
    """Place the axes of a regular grid (an (nrows, ncols) array; those removed or hidden are
    left out of the sums) with margins that hold their texts and the figure's title."""
    import numpy as np

    grid = np.asarray(axes, dtype=object)
    nrows, ncols = grid.shape
    shown = [ax for ax in grid.flat if ax.get_figure() is fig and ax.get_visible()]
    if not shown:
        return
    need = [room(ax) for ax in shown]
    width, height = fig.get_size_inches()
    left = max(r["left"] for r in need)
    right = max(r["right"] for r in need) + EDGE
    bottom = max(r["bottom"] for r in need)
    top = title_room(fig) + max(r["top"] for r in need)
    wgap, hgap = left + right, bottom + max(r["top"] for r in need) + EDGE
    aw = (width - left - right - (ncols - 1) * wgap) / ncols
    ah = (height - top - bottom - (nrows - 1) * hgap) / nrows
    fig.subplots_adjust(
        left=left / width,
        right=1.0 - right / width,
        bottom=bottom / height,
        top=1.0 - top / height,
        wspace=wgap / aw if ncols > 1 else 0.0,
        hspace=hgap / ah if nrows > 1 else 0.0,
    )
