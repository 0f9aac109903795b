"""Newton's line search with contact (solve/newton.py): a correction that raises the residual is
halved up to three times; where none of the halves lowers it either, the one of the four with
the least residual is taken.  A scalar residual r(u) = u - 1 + c u^2 from u = 0 (K = 1, the
correction 1) has r = c, c/4 - 1/2, c/16 - 3/4, c/64 - 7/8 at the whole, the half, the quarter
and the eighth: with c = 200 every one is above |r(0)| = 1 and the eighth (2.25) is the least."""

from types import SimpleNamespace

import numpy as np
import pytest

import axiform.solve.newton as newton
from axiform.solve.controls import NewtonOptions

C = 200.0


def evaluation(u: np.ndarray) -> SimpleNamespace:
    """The Evaluation's fields Newton reads, for r(u) = u - 1 + C u^2 (one unknown)."""
    r = u - 1.0 + C * u * u
    return SimpleNamespace(
        r=r,
        K=np.array([[1.0 + 2.0 * C * u[0]]]),
        force_norm=float(np.abs(r).max()),
        force_scale=1.0,
        noise=0.0,
        constraint_error=0.0,
    )


@pytest.fixture
def iterates(monkeypatch):
    """Every u Newton evaluates, in order (the model's evaluation and factorization replaced
    by the scalar problem's)."""
    seen: list[float] = []

    def evaluate(model, history, u_f, lam, predicting=False):
        seen.append(float(u_f[0]))
        return evaluation(u_f)

    monkeypatch.setattr(newton, "evaluate_checked", evaluate)
    monkeypatch.setattr(newton, "factorize_checked", lambda K, linear: lambda b: np.linalg.solve(K, b))
    return seen


def test_the_least_residual_of_the_halvings_is_taken(iterates):
    model = SimpleNamespace(contacts=[object()])
    u, lam, its, residuals, ev = newton.newton_load(model, None, np.zeros(1), 1.0, NewtonOptions(), 0.0, None)
    assert iterates[:5] == [0.0, 1.0, 0.5, 0.25, 0.125]  # the start, the whole and its three halves
    assert iterates[5] > 0.0 and residuals[1] == pytest.approx(C / 64 - 7 / 8)  # from the eighth on
    assert u[0] == pytest.approx((-1.0 + np.sqrt(1.0 + 4.0 * C)) / (2.0 * C), rel=1e-8)
    assert its <= 6  # quadratic from the eighth; the whole (r = 200) took 9


def test_without_contact_the_whole_correction_is_taken(iterates):
    model = SimpleNamespace(contacts=[])
    newton.newton_load(model, None, np.zeros(1), 1.0, NewtonOptions(), 0.0, None)
    assert iterates[:3] == [0.0, 1.0, pytest.approx(1.0 - C / (1.0 + 2.0 * C))]  # Newton from the whole: no halving
