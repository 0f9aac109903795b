"""A 3D copy of the deformed meridian mesh revolved about the z axis, for pictures."""

from __future__ import annotations

import numpy as np


def revolve(points: np.ndarray, cells: np.ndarray, sectors: int, point_data: dict | None = None):
    """Hexahedra (degenerate at r = 0) from the corner nodes of the quadrilaterals, at the
    points given (the deformed ones, for pictures): a meshio Mesh of `sectors` slices over 360 degrees; point data
    is copied to every slice (vectors
    given in (r, z, 0) are turned into (x, y, z))."""
    import meshio

    n = len(points)
    phi = np.linspace(0.0, 2 * np.pi, sectors, endpoint=False)
    c, s = np.cos(phi), np.sin(phi)
    xyz = np.concatenate(
        [np.column_stack([points[:, 0] * ci, points[:, 0] * si, points[:, 1]]) for ci, si in zip(c, s, strict=False)]
    )
    quad = cells[:, :4]
    hexes = []
    for k in range(sectors):
        a, b = k * n, ((k + 1) % sectors) * n
        hexes.append(np.column_stack([quad + a, quad + b])[:, [0, 1, 5, 4, 3, 2, 6, 7]])
    data = {}
    for name, v in (point_data or {}).items():
        v = np.asarray(v)
        if v.ndim == 2 and v.shape[1] == 3 and name == "displacement":
            data[name] = np.concatenate(
                [np.column_stack([v[:, 0] * ci, v[:, 0] * si, v[:, 1]]) for ci, si in zip(c, s, strict=False)]
            )
        else:
            data[name] = np.concatenate([v] * sectors)
    return meshio.Mesh(xyz, [("hexahedron", np.vstack(hexes))], point_data=data)
