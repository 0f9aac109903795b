"""GiD post-process files (.post.msh, .post.res, ASCII), as the paper used GiD."""

from __future__ import annotations

from pathlib import Path

import numpy as np


def write_mesh(path: str | Path, points: np.ndarray, cells: np.ndarray) -> None:
    """The meridian mesh: quadrilaterals with 4 or 8 nodes (GiD's node order is ours)."""
    with open(path, "w") as fh:
        fh.write(f'MESH "axiform" dimension 2 ElemType Quadrilateral Nnode {cells.shape[1]}\n')
        fh.write("Coordinates\n")
        for i, (r, z) in enumerate(points, start=1):
            fh.write(f"{i} {r:.10g} {z:.10g}\n")
        fh.write("End Coordinates\nElements\n")
        for i, c in enumerate(cells + 1, start=1):
            fh.write(f"{i} " + " ".join(map(str, c)) + "\n")
        fh.write("End Elements\n")


def start_results(path: str | Path) -> None:
    Path(path).write_text("GiD Post Results File 1.0\n")


def append_results(path: str | Path, step: float, fields: dict[str, np.ndarray]) -> None:
    """One load step of nodal results: 1-column arrays as scalars, 2-3 columns as vectors,
    the Cauchy stress (rr, zz, tt, rz) as a plane matrix."""
    with open(path, "a") as fh:
        for name, values in fields.items():
            values = np.asarray(values)
            if values.ndim == 1:
                kind, comps = "Scalar", None
            elif name == "cauchy_stress":
                kind, comps = "PlainDeformationMatrix", '"Srr", "Szz", "Srz", "Stt"'
                values = values[:, [0, 1, 3, 2]]
            elif values.shape[1] <= 3:
                kind, comps = "Vector", ", ".join(f'"{name}_{k}"' for k in "xyz"[: values.shape[1]])
            else:
                continue
            fh.write(f'Result "{name}" "Load Analysis" {step:g} {kind} OnNodes\n')
            if comps:
                fh.write(f"ComponentNames {comps}\n")
            fh.write("Values\n")
            rows = values.reshape(len(values), -1)
            for i, row in enumerate(rows, start=1):
                fh.write(f"{i} " + " ".join(f"{v:.8g}" for v in row) + "\n")
            fh.write("End Values\n")
