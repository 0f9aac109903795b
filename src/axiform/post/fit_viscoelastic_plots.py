"""fit_prony.png and fit_wlf.png of `axiform fit --model prony|wlf` (app/fit_viscoelastic.py):
the data and the fitted series or shift, and the residuals beneath."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ..materials.viscoelastic_fit import PronyFit, WLFFit, dynamic_moduli, relaxation_modulus, wlf_shift
from .figures import new_figure, save

DATA, FIT, LOSS = "k", "C3", "C0"


def _figure():
    """A figure with the main axes over a third as tall for the residuals, sharing x."""
    fig = new_figure((6.6, 6.2))
    top, bottom = fig.subplots(2, 1, sharex=True, height_ratios=[2.4, 1.0])
    return fig, top, bottom


def _taus(ax, x: np.ndarray, label: str) -> None:
    """The relaxation times (or 1 / (2 pi tau_i)) x as dotted verticals."""
    for i, v in enumerate(x):
        ax.axvline(v, color="0.7", ls=":", lw=0.9, label=label if i == 0 else None)


def _plain_log(ax) -> None:
    """A log scale on the y axis of `ax` labelled 2, 5, 10, 20 ... rather than 2 x 10^0."""
    from matplotlib.ticker import LogFormatter

    ax.set_yscale("log")
    for set_formatter in (ax.yaxis.set_major_formatter, ax.yaxis.set_minor_formatter):
        set_formatter(LogFormatter(labelOnlyBase=False, minor_thresholds=(2, 0.5)))


def _series_text(fit: PronyFit) -> str:
    return f"{len(fit.g)} terms, E0 = {fit.E0:.4g}, E∞ = {fit.long_term:.4g}"


def plot_relaxation(t: np.ndarray, modulus: np.ndarray, fit: PronyFit, path: Path) -> None:
    """The relaxation modulus (m,) at times t (m,) as markers, the series as a line, log time
    (log modulus where it spans more than a decade); relative residuals in % beneath."""
    fig, ax, res = _figure()
    grid = np.geomspace(t[0], t[-1], 400)
    ax.plot(t, modulus, "o", mfc="none", color=DATA, label="data")
    ax.plot(grid, relaxation_modulus(fit.E0, fit.g, fit.tau, grid), "-", color=FIT, label="Prony series")
    ax.axhline(fit.E0, color=FIT, ls="--", lw=0.8, label="E0 (t = 0) and E∞")
    ax.axhline(fit.long_term, color=FIT, ls="--", lw=0.8)
    _taus(ax, fit.tau, "τ_i")
    ax.set_xscale("log")
    if max(modulus.max(), fit.E0) > 10 * min(modulus.min(), fit.long_term):
        _plain_log(ax)
    ax.set_ylabel("relaxation modulus (units of the data)")
    ax.set_title(f"Prony series: {_series_text(fit)}")
    ax.legend(loc="center right", fontsize=9)
    ax.grid(alpha=0.3, which="both")
    res.plot(t, 100 * fit.residual, "o-", ms=3, color=DATA, lw=0.8)
    res.axhline(0.0, color="0.6", lw=0.8)
    res.set_xlabel("time (units of the data)")
    res.set_ylabel("fit − data (% of data)")
    res.grid(alpha=0.3, which="both")
    save(fig, path, dpi=120)


def plot_dynamic(f: np.ndarray, storage: np.ndarray, loss: np.ndarray, fit: PronyFit, path: Path) -> None:
    """Storage and loss moduli (m,) at frequencies f (m,) in Hz as markers, the series as
    lines, log-log; relative residuals in % beneath."""
    fig, ax, res = _figure()
    grid = np.geomspace(f[0], f[-1], 400)
    s, l = dynamic_moduli(fit.E0, fit.g, fit.tau, grid)
    ax.plot(f, storage, "o", mfc="none", color=DATA, label="storage E′ (data)")
    ax.plot(f, loss, "s", mfc="none", color=LOSS, label="loss E″ (data)")
    ax.plot(grid, s, "-", color=FIT, label="Prony series")
    ax.plot(grid, l, "-", color=FIT)
    _taus(ax, 1.0 / (2.0 * np.pi * fit.tau), "1 / (2π τ_i)")
    ax.set_xscale("log")
    _plain_log(ax)
    ax.set_ylabel("modulus (units of the data)")
    ax.set_title(f"Prony series from DMA: {_series_text(fit)}")
    ax.legend(loc="best", fontsize=9)
    ax.grid(alpha=0.3, which="both")
    m = len(f)
    res.plot(f, 100 * fit.residual[:m], "o-", ms=3, color=DATA, lw=0.8, label="storage")
    res.plot(f, 100 * fit.residual[m:], "s-", ms=3, color=LOSS, lw=0.8, label="loss")
    res.axhline(0.0, color="0.6", lw=0.8)
    res.set_xlabel("frequency (Hz)")
    res.set_ylabel("fit − data (% of data)")
    res.legend(loc="best", fontsize=8)
    res.grid(alpha=0.3, which="both")
    save(fig, path, dpi=120)


def plot_wlf(T: np.ndarray, log_shift: np.ndarray, fit: WLFFit, path: Path) -> None:
    """log10 a_T (m,) at temperatures T (m,) as markers, the WLF curve as a line, the
    reference marked; residuals beneath."""
    fig, ax, res = _figure()
    pad = 0.05 * np.ptp(T)
    lo = max(T.min() - pad, fit.reference - fit.C2 + 0.02 * (np.ptp(T) + fit.C2))  # short of the pole
    grid = np.linspace(lo, T.max() + pad, 400)
    ax.plot(T, log_shift, "o", mfc="none", color=DATA, label="data")
    shifted = f"\n+ {fit.offset:.4g} (the data's log10 a_T at T_ref)" if fit.offset else ""
    ax.plot(
        grid,
        wlf_shift(grid, fit.C1, fit.C2, fit.reference) + fit.offset,
        "-",
        color=FIT,
        label=f"WLF: C1 = {fit.C1:.4g}, C2 = {fit.C2:.4g}{shifted}",
    )
    ax.axvline(fit.reference, color="0.6", ls="--", lw=0.9, label=f"T_ref = {fit.reference:.5g}")
    ax.axhline(0.0, color="0.8", lw=0.8)
    ax.set_ylabel("log10 a_T")
    ax.set_title(f"WLF shift at T_ref = {fit.reference:.5g} (pole at T = {fit.reference - fit.C2:.4g})")
    ax.legend(loc="upper right", fontsize=9)
    ax.grid(alpha=0.3)
    res.plot(T, fit.residual, "o-", ms=3, color=DATA, lw=0.8)
    res.axhline(0.0, color="0.6", lw=0.8)
    res.set_xlabel("temperature (units of the data)")
    res.set_ylabel("fit − data (log10 a_T)")
    res.grid(alpha=0.3)
    save(fig, path, dpi=120)
