"""fit_<mode>.png of `axiform fit` (axiform.app.fit): the test data and the fitted law."""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from .figures import new_figure, save

if TYPE_CHECKING:
    from ..app.fit import Data, FitResult


def plot_fit(
    result: FitResult, data: Data, mode: str, path: Path, modes: tuple[str, ...], stress: Callable[..., np.ndarray]
) -> None:
    """Data as markers, the model as a line, for one mode.  modes: the modes data.mode
    indexes (axiform.app.fit.MODES); stress(law, mode, stretches): the law's nominal stress
    in the loading direction (axiform.app.fit.nominal_stress) - passed in: post/ does not
    import app/."""
    sel = data.mode == modes.index(mode)
    lam = data.stretch[sel]
    grid = np.linspace(min(lam.min(), 1.0), lam.max() * 1.02, 300)
    fig = new_figure((6.4, 4.6), layout=None)
    ax = fig.add_subplot()
    ax.plot(lam, data.stress[sel], "o", mfc="none", color="k", label="data")
    ax.plot(grid, stress(result.law, mode, grid), "-", color="C3", label=f"{result.model} fit")
    ax.axhline(0.0, color="0.8", lw=0.8)
    ax.set_xlabel(f"stretch λ in the loading direction ({mode})")
    ax.set_ylabel("nominal stress (units of the data)")
    name = f"{result.model} ({result.terms} terms)" if result.terms else result.model
    ax.set_title(f"{name}, {mode}: RMS relative error {100 * result.rms[mode]:.2f} %")
    ax.legend(loc="upper left")
    ax.grid(alpha=0.3)
    fig.tight_layout()
    save(fig, path, dpi=120)
