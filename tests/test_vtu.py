"""VTU files written without meshio read back by meshio bit for bit, Q4 and Q8 (the layout
ParaView reads), an empty field included."""

import meshio
import numpy as np
import pytest

from axiform import rectangle
from axiform.vtu import write_vtu


@pytest.mark.parametrize("element, cell_type", [("q4", "quad"), ("q8", "quad8")])
def test_meshio_reads_back_every_array(tmp_path, element, cell_type):
    mesh = rectangle((1.0, 2.0), (0.0, 3.0), (40, 30), element)  # > 32 kB arrays: several blocks
    rng = np.random.default_rng(0)
    data = {"displacement": rng.standard_normal((mesh.n_nodes, 3)), "von_mises": rng.standard_normal(mesh.n_nodes),
            "cauchy_stress": rng.standard_normal((mesh.n_nodes, 4)), "zero": np.zeros(mesh.n_nodes)}
    write_vtu(tmp_path / "a.vtu", mesh.points, mesh.cells, data)
    m = meshio.read(tmp_path / "a.vtu")
    assert np.array_equal(m.points[:, :2], mesh.points) and not m.points[:, 2].any()
    assert m.cells[0].type == cell_type and np.array_equal(m.cells[0].data, mesh.cells)
    assert list(m.point_data) == list(data)
    for name, values in data.items():
        assert np.array_equal(m.point_data[name], values), name
