"""Checks of a contact pair over a run: nodes of the body that passed through the surface
(behind it deeper than the pair's search depth, where the pair no longer sees them: a body
whose slaves are on its face away from the mould sinks through the mould, held at most by
that face), and boundary nodes that are not its slaves behind it (a face the pair does not
hold crossing the surface: the side of a part that barrels and folds onto a plate)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

# how far behind the surface a node is still projected by the check, in spans of the body
# (the pair's own search stops at its depth)
REACH = 10.0


@dataclass(frozen=True)
class PassedThrough:
    """Nodes of the body behind the surface beyond the search depth: how many, the deepest
    one's depth and its position (r, z)."""

    count: int
    deepest: float
    at: tuple[float, float]


def passed_through(pair, x: np.ndarray, t: float) -> PassedThrough | None:
    """The nodes of the body at positions x (n_nodes, 2) at time t that lie behind the pair's
    surface by more than its search depth, on a piece they project onto and in front of
    none (surfaces' `local`: the piece with the largest gap); None where there is none."""
    span = float(np.ptp(pair.mesh.points, axis=0).max())
    behind, g = _behind(pair, x, t, REACH * span + pair.depth, pair.depth)
    if not behind.any():
        return None
    k = int(np.argmin(np.where(behind, g, np.inf)))
    return PassedThrough(int(behind.sum()), float(-g[k]), (float(x[k, 0]), float(x[k, 1])))


def _behind(pair, x: np.ndarray, t: float, reach: float, beyond: float) -> tuple[np.ndarray, np.ndarray]:
    """Which points x (k, 2) at time t lie behind the pair's surface by more than `beyond`
    (0: at all), projected up to `reach` behind it, on a piece they project onto and in front
    of none (surfaces' `local`: the piece with the largest gap) (k, bool); their gaps (k,)."""
    rel = x - pair.surface.offset(t)
    proj = pair.surface.local(rel, rel, depth=reach, method=pair.search)
    return proj.active & (proj.kind == 1) & (proj.g < -beyond), proj.g


def unheld(pair) -> np.ndarray:
    """The boundary nodes of the body that are not slaves of the pair (k,)."""
    return np.setdiff1d(np.unique(pair.mesh.boundary_edges), pair.nodes)


def unheld_behind(pair, nodes: np.ndarray, x: np.ndarray, t: float) -> tuple[np.ndarray, np.ndarray]:
    """Those of `nodes` (k,) (the pair's `unheld`) that lie behind its surface at positions
    x (n_nodes, 2) at time t, within the pair's search depth (deeper: `passed_through`), on a
    piece they project onto and in front of none: their indices and depths (none: empty)."""
    if nodes.size == 0:
        return nodes, np.zeros(0)
    behind, g = _behind(pair, x[nodes], t, pair.depth, 0.0)
    return nodes[behind], -g[behind]
