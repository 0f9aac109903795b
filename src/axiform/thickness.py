"""Wall thickness along a layered body, from the through-thickness fibres of corner nodes
(mesh.fibres, set by the rectangle and layered generators): the fibre's chord projected on
the normal of the current mid-surface, so that a sheared fibre (near a clamp) is not taken
for a thick wall."""

from __future__ import annotations

import numpy as np

from .mesh import Mesh


def thickness_table(mesh: Mesh, u: np.ndarray) -> dict[str, np.ndarray] | None:
    """Per station: reference arc length s, initial and current thickness, their ratio, and
    the current r, z of the fibre's middle.  None for meshes without fibres."""
    if mesh.fibres is None:
        return None
    f = mesh.fibres
    t0, _ = _normal_thickness(mesh.points, f)
    t, mid = _normal_thickness(mesh.points + u, f)
    return {"s": mesh.fibre_s, "r": mid[:, 0], "z": mid[:, 1], "thickness": t,
            "initial_thickness": t0, "ratio": t / t0}


def _normal_thickness(x: np.ndarray, fibres: np.ndarray):
    bottom, top = x[fibres[:, 0]], x[fibres[:, -1]]
    mid = 0.5 * (bottom + top)
    tangent = np.gradient(mid, axis=0)
    normal = np.column_stack([-tangent[:, 1], tangent[:, 0]])
    normal /= np.linalg.norm(normal, axis=1)[:, None]
    return np.abs(np.einsum("ij,ij->i", top - bottom, normal)), mid


def write_thickness_csv(path, table: dict[str, np.ndarray], step: int, load_factor: float) -> None:
    names = ["s", "r", "z", "thickness", "initial_thickness", "ratio"]
    header = f"# step {step}, load_factor {load_factor!r}\n" + ",".join(names)
    np.savetxt(path, np.column_stack([table[n] for n in names]), delimiter=",", header=header,
               comments="", fmt="%.10g")
