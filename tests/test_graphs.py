"""axiform.fem.graphs.connected_components against SciPy's, on random graphs and a mesh."""

import numpy as np
import pytest
import scipy.sparse as sp
from scipy.sparse.csgraph import connected_components as scipy_components

from axiform import rectangle
from axiform.fem.graphs import connected_components


@pytest.mark.parametrize("seed", range(6))
def test_random_graphs(seed):
    rng = np.random.default_rng(seed)
    n = int(rng.integers(1, 400))
    m = int(rng.integers(0, 2 * n))
    graph = sp.coo_matrix((np.ones(m), (rng.integers(0, n, m), rng.integers(0, n, m))), shape=(n, n))
    count, labels = connected_components(graph)
    ref_count, ref_labels = scipy_components(graph, directed=False)
    assert count == ref_count
    assert np.array_equal(labels, ref_labels)


def test_two_meshes_side_by_side():
    a = rectangle((0.0, 1.0), (0.0, 1.0), (7, 5), "q8")
    cells = np.vstack([a.cells, a.cells + a.n_nodes])
    rows = np.repeat(cells[:, 0], cells.shape[1])
    n = 2 * a.n_nodes
    graph = sp.coo_matrix((np.ones(rows.size), (rows, cells.ravel())), shape=(n, n))
    count, labels = connected_components(graph)
    assert count == 2
    assert np.array_equal(labels, np.repeat([0, 1], a.n_nodes))
