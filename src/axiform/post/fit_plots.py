"""fit_<mode>.png of `axiform fit` (axiform.app.fit): the test data and the fitted law."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ..materials.homogeneous import MODES, Data, FitResult, nominal_stress
from .figures import new_figure, save


def plot_fit(result: FitResult, data: Data, mode: str, path: Path) -> None:
    """Data as markers, the model as a line, for one mode (one of MODES)."""
    sel = data.mode == MODES.index(mode)
    lam = data.stretch[sel]
    grid = np.linspace(min(lam.min(), 1.0), lam.max() * 1.02, 300)
    fig = new_figure((6.4, 4.6), layout=None)
    ax = fig.add_subplot()
    ax.plot(lam, data.stress[sel], "o", mfc="none", color="k", label="data")
    ax.plot(grid, nominal_stress(result.law, mode, grid), "-", color="C3", label=f"{result.model} fit")
    ax.axhline(0.0, color="0.8", lw=0.8)
    ax.set_xlabel(f"stretch λ in the loading direction ({mode})")
    ax.set_ylabel("nominal stress (units of the data)")
    name = f"{result.model} ({result.terms} terms)" if result.terms else result.model
    ax.set_title(f"{name}, {mode}: RMS relative error {100 * result.rms[mode]:.2f} %")
    ax.legend(loc="upper left")
    ax.grid(alpha=0.3)
    fig.tight_layout()
    save(fig, path, dpi=120)
