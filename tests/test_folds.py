"""Folded elements: the in-plane Jacobian at the nodes of a deformed element, and the stop
message that names the element."""

import numpy as np
import pytest

from axiform import rectangle
from axiform.fem.folds import folded_nodes


@pytest.mark.parametrize("element", ["q4", "sfr"])
def test_a_corner_pushed_past_the_diagonal_folds_the_element_there(element):
    """A unit square whose corner (2, 2) is moved to (1.25, 1.25), inside the triangle of the
    other three: the bilinear map's Jacobian at a node is that of the two edges meeting
    there, (-0.25, 0.75) and (0.75, -0.25) instead of (-1, 0) and (0, -1), so j = (0.0625 -
    0.5625) / 1 = -0.5 exactly; the other three nodes keep j > 0."""
    mesh = rectangle((1.0, 2.0), (1.0, 2.0), (1, 1), element)
    u = np.zeros(mesh.n_nodes * mesh.element.dofs_per_node)
    corner = int(np.flatnonzero(np.all(mesh.points == [2.0, 2.0], axis=1))[0])
    dpn = mesh.element.dofs_per_node
    u[corner * dpn : corner * dpn + 2] = [-0.75, -0.75]
    folds = folded_nodes(mesh, u)
    assert [(e, n) for e, n, _ in folds] == [(0, corner)]
    assert folds[0][2] == pytest.approx(-0.5, rel=1e-12)
    assert folded_nodes(mesh, np.zeros_like(u)) == []


def test_the_q8_plate_stop_names_the_element_folded_at_the_clamp_corner():
    """The paper's plate, Q8 4 x 40, by arc length towards w = 23: it stops at w = 21.985,
    where the column of elements at the clamp loses its stiffness in one mode (K's second
    eigenvalue falls from 7.3 to 1.0 over 0.003 in of deflection while the pressure falls
    smoothly); the element at the clamp's upper corner has been folded at that corner node
    since w = 8.5, and the message says so."""
    from conftest import clamped_plate

    from axiform import select_nodes
    from axiform.solve.solver import ArcLengthControl, solve

    model = clamped_plate("q8", divisions=(40, 4))
    w = int(model.dof(select_nodes(model.mesh, {"r": 0.0, "z": 0.25})[0], "uz"))
    res = solve(model, ArcLengthControl(target=100.0, steps=20, stop_dof=w, stop_value=23.0))
    assert res.status == "stopped"
    assert 21.9 < res.last.u[w] < 22.0
    assert "element 159 is folded at its node 568 (r, z = 7.5, 0.5;" in res.message
