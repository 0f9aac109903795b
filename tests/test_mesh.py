"""Meshes: structured rectangles, gmsh import through meshio, selectors, mesh checks."""

import numpy as np
import pytest

from axiform import read_gmsh, rectangle, select_edges, select_nodes
from axiform.fem.mesh import MeshError
from axiform.fem.selectors import SelectorError


@pytest.mark.parametrize("element, nodes", [("q4", 4 * 3), ("sfr", 4 * 3), ("q8", 4 * 3 + 3 * 3 + 4 * 2)])
def test_rectangle_counts_and_sets(element, nodes):
    mesh = rectangle((0.0, 3.0), (0.0, 2.0), (3, 2), element)
    assert mesh.n_cells == 6 and mesh.n_nodes == nodes
    assert len(mesh.boundary_edges) == 2 * (3 + 2)
    assert set(mesh.edge_sets) == {"left", "right", "bottom", "top"}
    assert len(mesh.edge_sets["top"]) == 3
    assert np.allclose(mesh.points[mesh.node_sets["right"], 0], 3.0)
    mesh.check()
    # areas: sum of |detJ| w equals the rectangle area (through the axisymmetric volume)
    from axiform.fem.elements import gradient_operator

    _, dV = gradient_operator(mesh.element, mesh.points[mesh.cells])
    assert dV.sum() == pytest.approx(np.pi * 3.0**2 * 2.0)


def test_q8_mid_side_nodes_are_mid_side():
    mesh = rectangle((1.0, 2.0), (0.0, 1.0), (2, 2), "q8")
    c = mesh.cells
    for k, (a, b) in zip(range(4, 8), [(0, 1), (1, 2), (2, 3), (3, 0)], strict=False):
        assert np.allclose(mesh.points[c[:, k]], 0.5 * (mesh.points[c[:, a]] + mesh.points[c[:, b]]))


def test_boundary_edges_run_counter_clockwise():
    mesh = rectangle((0.0, 1.0), (0.0, 1.0), (2, 2), "q4")
    e = mesh.boundary_edges
    t = mesh.points[e[:, 1]] - mesh.points[e[:, 0]]
    n = np.column_stack([t[:, 1], -t[:, 0]])  # outward normal
    mid = 0.5 * (mesh.points[e[:, 0]] + mesh.points[e[:, 1]])
    assert (np.einsum("ij,ij->i", n, mid - 0.5) > 0).all()


def test_selectors():
    mesh = rectangle((0.0, 7.5), (0.0, 0.5), (20, 2), "q8")
    assert len(select_nodes(mesh, {"r": 7.5})) == 5
    assert len(select_nodes(mesh, {"r": 7.5 + 1e-7})) == 5  # tolerance relative to the mesh size
    assert len(select_nodes(mesh, {"r": 0.0, "z": 0.5})) == 1
    assert len(select_nodes(mesh, {"box": [[0.0, 0.0], [0.375, 0.5]]})) == 5 + 3 + 5
    assert len(select_nodes(mesh, {"set": "top"})) == 41
    assert len(select_nodes(mesh, {"z": 0.5}, corners_only=True)) == 21
    assert len(select_edges(mesh, {"z": 0.0})) == 20
    assert len(select_edges(mesh, {"set": "left"})) == 2
    with pytest.raises(SelectorError, match=r"fix\[3\]\.at: selector \{r = 8.0\} matches no node"):
        select_nodes(mesh, {"r": 8.0}, "fix[3].at")
    with pytest.raises(SelectorError, match="no node set named 'rim'"):
        select_nodes(mesh, {"set": "rim"})
    with pytest.raises(SelectorError, match="matches no boundary edge"):
        select_edges(mesh, {"r": 3.75})


def test_inverted_and_negative_radius_meshes_are_refused():
    mesh = rectangle((0.0, 1.0), (0.0, 1.0), (2, 2), "q4")
    mesh.cells[3] = mesh.cells[3, ::-1]
    with pytest.raises(MeshError, match=r"inverted or degenerate element\(s\) \[3\]"):
        mesh.check()
    mesh = rectangle((0.0, 1.0), (0.0, 1.0), (2, 2), "q4")
    mesh.points[:, 0] -= 0.5
    with pytest.raises(MeshError, match="r < 0"):
        mesh.check()


def make_gmsh_plate(path, order=1):
    gmsh = pytest.importorskip("gmsh")
    gmsh.initialize(["-v", "0"])
    try:
        gmsh.model.add("plate")
        s = gmsh.model.occ.addRectangle(0.0, 0.0, 0.0, 7.5, 0.5)
        gmsh.model.occ.synchronize()
        lines = {}
        for dim, tag in gmsh.model.getBoundary([(2, s)], oriented=False):
            x, y, _ = gmsh.model.occ.getCenterOfMass(dim, tag)
            name = "rim" if abs(x - 7.5) < 1e-9 else "axis" if abs(x) < 1e-9 else "bottom" if abs(y) < 1e-9 else "top"
            lines[name] = tag
        for name, tag in lines.items():
            gmsh.model.addPhysicalGroup(1, [tag], name=name)
        gmsh.model.addPhysicalGroup(2, [s], name="plate")
        gmsh.option.setNumber("Mesh.MeshSizeMax", 0.25)
        gmsh.option.setNumber("Mesh.RecombineAll", 1)
        gmsh.option.setNumber("Mesh.Algorithm", 8)
        gmsh.option.setNumber("Mesh.SecondOrderIncomplete", 1)
        gmsh.model.mesh.generate(2)
        if order == 2:
            gmsh.model.mesh.setOrder(2)
        gmsh.write(str(path))
    finally:
        gmsh.finalize()


@pytest.mark.parametrize("order, element", [(1, "q4"), (1, "sfr"), (2, "q8")])
def test_gmsh_import_with_physical_groups(tmp_path, order, element):
    path = tmp_path / "plate.msh"
    make_gmsh_plate(path, order)
    mesh = read_gmsh(path, element)
    mesh.check()
    assert mesh.element.name == element
    assert {"rim", "axis", "bottom", "top", "plate"} <= set(mesh.node_sets)
    assert np.allclose(mesh.points[mesh.node_sets["rim"], 0], 7.5)
    assert len(mesh.edge_sets["bottom"]) > 0
    e = mesh.boundary_edges[mesh.edge_sets["bottom"]]
    assert np.allclose(mesh.points[e, 1], 0.0)
    from axiform.fem.elements import gradient_operator

    _, dV = gradient_operator(mesh.element, mesh.points[mesh.cells])
    assert dV.sum() == pytest.approx(np.pi * 7.5**2 * 0.5, rel=1e-10)


def test_gmsh_quad8_cannot_be_read_as_q4(tmp_path):
    path = tmp_path / "plate.msh"
    make_gmsh_plate(path, 2)
    with pytest.raises(MeshError, match="cannot be used as element 'q4'"):
        read_gmsh(path, "q4")
