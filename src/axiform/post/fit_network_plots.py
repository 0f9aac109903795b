"""fit_network_<mode>.png of `axiform fit --model network` (app/fit_network.py): for one mode,
every curve's data as markers and the fitted law along it as a line, one colour per curve
(rate, and temperature), the RMS error of each in the legend; the errors beneath."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ..materials.network_fit import MODES, Curves
from .figures import colormap, new_figure, save

STYLES = ("-", "--", ":", "-.")
MARKERS = ("o", "s", "^", "D")


def plot_mode(
    curves: Curves, model: Curves, error: np.ndarray, rms: np.ndarray, mode: int, labels: list[str], path: Path
) -> None:
    """curves: the data; model: the fitted law's stress along each curve (its points on a fine
    grid of stretches, the same curve numbers); error (n,) the fit's error at each data point
    (a fraction of its curve's peak stress); rms (c,) each curve's RMS error (a fraction of
    its peak stress); mode: the index into MODES drawn; labels (c,) each curve's name."""
    chosen = np.flatnonzero(curves.mode == mode)
    T = curves.temperature if curves.temperature is not None else np.zeros(curves.count)
    order = chosen[np.lexsort((curves.rate[chosen], T[chosen]))]
    rates, temps = np.unique(curves.rate[chosen]), np.unique(T[chosen])
    fig = new_figure((7.0, 6.4))
    ax, res = fig.subplots(2, 1, sharex=True, height_ratios=[2.6, 1.0])
    cmap = colormap("viridis")
    for c in order:
        # one colour per rate; with several temperatures one colour per temperature, a line
        # style and marker per rate
        by_T = len(temps) > 1
        r, k = int(np.searchsorted(rates, curves.rate[c])), int(np.searchsorted(temps, T[c]))
        shade, n = (k, len(temps)) if by_T else (r, len(rates))
        color = cmap(0.85 * shade / max(n - 1, 1))
        style, marker = (STYLES[r % len(STYLES)], MARKERS[r % len(MARKERS)]) if by_T else ("-", "o")
        data = curves.curve == c
        line = model.curve == c
        ax.plot(curves.stretch[data], curves.stress[data], marker, mfc="none", ms=5, color=color)
        ax.plot(
            np.r_[1.0, model.stretch[line]],  # from the unloaded start
            np.r_[0.0, model.stress[line]],
            style,
            lw=1.6,
            color=color,
            label=f"{labels[c]}: RMS {100 * rms[c]:.2f} %",
        )
        res.plot(curves.stretch[data], 100 * error[data], marker, ls=style, ms=3, lw=0.8, color=color)
    ax.plot([], [], "o", mfc="none", color="0.3", label="data (markers); fit (lines)")
    ax.axhline(0.0, color="0.8", lw=0.8)
    ax.set_ylabel("nominal stress (units of the data)")
    ax.set_title(f"Networks fitted: {MODES[mode]} tension at constant stretch rates")
    ax.legend(loc="lower right", fontsize=9)
    ax.grid(alpha=0.3)
    res.axhline(0.0, color="0.6", lw=0.8)
    res.set_xlabel(f"stretch λ in the loading direction ({MODES[mode]})")
    res.set_ylabel("fit − data\n(% of the curve's peak)")
    res.grid(alpha=0.3)
    save(fig, path, dpi=120)
