"""Newton under load control with contact: which corrections are shortened."""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from axiform.model.evaluation import Evaluation
from axiform.solve.controls import NewtonOptions
from axiform.solve.linsolve import LinearSolver
from axiform.solve.newton import newton_load, still_descending


class Bent:
    """Two unknowns, R = (u1 - 1 - u1^2 / 8, u2 + 2 u1^2), K at u = 0 the identity: the first
    correction du = (1, 0) raises ||R|| from 1 to 2.004, while du . R stays negative along it
    (-1 at its start, -1/8 at its end).  Counts its evaluations; `contacts` makes Newton treat
    it as a model with contact."""

    contacts = (object(),)
    dpn = 2
    rigid_modes = np.zeros((2, 0))

    def __init__(self):
        self.points: list[np.ndarray] = []

    def evaluate(self, u, lam, history, predicting=False):
        self.points.append(u.copy())
        u1, u2 = u
        r = np.array([u1 - 1.0 - 0.125 * u1 * u1, u2 + 2.0 * u1 * u1])
        K = sp.csr_matrix(np.array([[1.0 - 0.25 * u1, 0.0], [4.0 * u1, 1.0]]))
        return Evaluation(r, np.zeros(2), K, r.copy(), np.zeros(2), 1.0, nf=2)


def test_a_correction_still_descending_at_its_full_length_is_not_shortened():
    model = Bent()
    newton_load(model, None, np.zeros(2), 1.0, NewtonOptions(tolerance=1e-10), 0.0, LinearSolver())
    # the start, the full correction, then the next iterate from it: no halved point (0.5, 0)
    assert np.allclose(model.points[1], [1.0, 0.0])
    assert not any(np.allclose(p, [0.5, 0.0]) for p in model.points)
    assert np.allclose(model.points[-1], [4.0 - 2.0 * np.sqrt(2.0), -2.0 * (4.0 - 2.0 * np.sqrt(2.0)) ** 2], atol=1e-8)


def test_still_descending_needs_a_descent_at_both_ends():
    du = np.array([1.0, 0.0])
    assert still_descending(du, np.array([-1.0, 0.0]), np.array([-0.5, 3.0]))
    assert not still_descending(du, np.array([-1.0, 0.0]), np.array([0.5, 0.0]))  # overshot along du
    assert not still_descending(du, np.array([1.0, 0.0]), np.array([-0.5, 0.0]))  # du no descent at its start
