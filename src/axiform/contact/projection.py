"""The result of the local search of a rigid surface (Projection), per point: the contact
point, normal, tangent, gap, surface coordinate and curvature terms; and the choice of one
candidate pair per point (best_per_node)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass
class Projection:
    """Local search result for every slave node (rows); `active` marks nodes with a contact
    point (they may still have g >= 0: the law decides)."""

    active: np.ndarray
    g: np.ndarray
    n: np.ndarray
    t: np.ndarray
    s: np.ndarray
    kappa: np.ndarray
    m: np.ndarray
    point: np.ndarray
    s_prev: np.ndarray  # surface coordinate of the last converged position on the same piece
    kind: np.ndarray  # 0 none, 1 segment or circle, 2 cavity corner (vertex), 3 crossing

    @classmethod
    def empty(cls, n: int) -> Projection:
        z = np.zeros(n)
        return cls(
            np.zeros(n, bool),
            z.copy(),
            np.zeros((n, 2)),
            np.zeros((n, 2)),
            z.copy(),
            z.copy(),
            np.ones(n),
            np.zeros((n, 2)),
            z.copy(),
            np.zeros(n, np.int8),
        )

    def rows(self, sl: slice) -> Projection:
        """The projections of the rows sl (views)."""
        return Projection(
            self.active[sl],
            self.g[sl],
            self.n[sl],
            self.t[sl],
            self.s[sl],
            self.kappa[sl],
            self.m[sl],
            self.point[sl],
            self.s_prev[sl],
            self.kind[sl],
        )


def best_per_node(i: np.ndarray, score: np.ndarray, rank: np.ndarray) -> np.ndarray:
    """For pairs sorted by node i: the index of the last pair of each node among those with
    the node's largest score and, among them, its largest rank."""
    new = np.empty(len(i), bool)
    new[0] = True
    np.not_equal(i[1:], i[:-1], out=new[1:])
    start = np.flatnonzero(new)
    group = np.cumsum(new) - 1
    top = score == np.maximum.reduceat(score, start)[group]
    rank = np.where(top, rank, -np.inf)
    pick = np.flatnonzero(top & (rank == np.maximum.reduceat(rank, start)[group]))
    gp = group[pick]
    last = np.empty(len(pick), bool)
    np.not_equal(gp[1:], gp[:-1], out=last[:-1])
    last[-1] = True
    return pick[last]
