"""Connected components of an undirected graph, in NumPy: scipy.sparse.csgraph imports
scipy.sparse.linalg and scipy.linalg with it (0.15 to 0.3 s at every start of `axiform run`,
which needs neither on its PARDISO path)."""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp


def connected_components(graph: sp.spmatrix, directed: bool = False) -> tuple[int, np.ndarray]:
    """(number of components, label of each node (n,)) of the undirected graph of a square
    sparse matrix, labels 0, 1, ... in the order of each component's lowest node (as
    scipy.sparse.csgraph.connected_components numbers them).

    Hooking and pointer jumping: every round hooks each root onto the lowest root across its
    edges, then points every node at its root; a few rounds on meshes."""
    if directed:
        raise ValueError("only undirected graphs")
    g = graph.tocoo()
    i, j = g.row.astype(np.int64), g.col.astype(np.int64)
    parent = np.arange(g.shape[0])
    while True:
        pi, pj = parent[i], parent[j]
        cross = pi != pj
        if not cross.any():
            break
        np.minimum.at(parent, np.maximum(pi, pj)[cross], np.minimum(pi, pj)[cross])
        while True:
            grand = parent[parent]
            if np.array_equal(grand, parent):
                break
            parent = grand
    roots, labels = np.unique(parent, return_inverse=True)
    return len(roots), labels
