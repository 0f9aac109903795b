"""Load curves: the applied value of a load, a prescribed displacement, a mould motion or a
cavity target is value x f(t), t the process time (the load factor lambda).

f is piecewise linear through the knots [[t0, f0], [t1, f1], ...] (t increasing) and
constant outside them; without a curve f(t) = t (the proportional load of the paper).
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np


class Curve:
    """f(t) through the knots (t increasing), constant outside; `Curve()` is f(t) = t."""

    t: np.ndarray | None  # knot times (m,), None for f(t) = t
    f: np.ndarray | None  # knot values (m,), None exactly when t is

    def __init__(self, knots: Sequence[Sequence[float]] | None = None):
        if knots is None:
            self.t = self.f = None
            return
        k = np.asarray(knots, float)
        if k.ndim != 2 or k.shape[1] != 2 or len(k) < 1:
            raise ValueError("a curve is a list of [t, f] pairs")
        if not np.isfinite(k).all():
            raise ValueError("a curve's values must be finite")
        if len(k) > 1 and np.any(np.diff(k[:, 0]) <= 0):
            raise ValueError("a curve's times must increase")
        self.t, self.f = k[:, 0], k[:, 1]

    @property
    def proportional(self) -> bool:
        return self.t is None

    def __call__(self, t: float) -> float:
        if self.t is None or self.f is None:
            return float(t)
        return float(np.interp(t, self.t, self.f))

    def slope(self, t: float) -> float:
        """df/dt; at a knot, the slope of the piece that starts there (time runs forward)."""
        if self.t is None or self.f is None:
            return 1.0
        if len(self.t) < 2 or t < self.t[0] or t >= self.t[-1]:
            return 0.0
        i = int(np.searchsorted(self.t, t, side="right")) - 1
        return float((self.f[i + 1] - self.f[i]) / (self.t[i + 1] - self.t[i]))

    def knots(self) -> np.ndarray:
        """The times at which the slope changes (empty for f(t) = t)."""
        return np.empty(0) if self.t is None else self.t.copy()

    def __eq__(self, other) -> bool:
        if not isinstance(other, Curve):
            return NotImplemented
        if self.t is None or self.f is None or other.t is None or other.f is None:
            return self.t is None and other.t is None
        return np.array_equal(self.t, other.t) and np.array_equal(self.f, other.f)

    def __hash__(self) -> int:
        return 0 if self.t is None or self.f is None else hash((self.t.tobytes(), self.f.tobytes()))


PROPORTIONAL = Curve()
