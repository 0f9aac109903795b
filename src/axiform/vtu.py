"""VTU files (VTK XML unstructured grid) of the meridian section, written without meshio.

The layout is meshio's default (binary DataArrays, zlib-compressed blocks of 32 kB, base64,
a UInt32 header), so meshio, ParaView and VTK read it alike; the blocks are compressed at
zlib level 1 (the plate Q8 4x40: 1.1 ms a file against meshio's 1.9 ms, 1 % larger).  Not
importing meshio saves 0.05 to 0.1 s of every `axiform run`.
"""

from __future__ import annotations

import base64
import sys
import zlib
from pathlib import Path

import numpy as np

BLOCK = 32768  # bytes of data per compressed block
LEVEL = 1  # zlib's fastest level
VTK_TYPE = {4: 9, 8: 23}  # VTK_QUAD, VTK_QUADRATIC_QUAD by nodes per cell
NUMPY_TO_VTK = {np.dtype(np.float64): "Float64", np.dtype(np.int64): "Int64", np.dtype(np.uint8): "UInt8"}


def _data_array(name: str, values: np.ndarray) -> str:
    """One <DataArray> element: the values' bytes in zlib blocks, base64-encoded after the
    header (number of blocks, block size, size of the last block, compressed sizes)."""
    values = np.ascontiguousarray(values)
    raw = values.tobytes()
    blocks = [zlib.compress(raw[k: k + BLOCK], LEVEL) for k in range(0, len(raw), BLOCK)] or [b""]
    last = len(raw) - (len(blocks) - 1) * BLOCK
    header = np.array([len(blocks), BLOCK, last] + [len(b) for b in blocks], dtype=np.uint32)
    comps = f' NumberOfComponents="{values.shape[1]}"' if values.ndim == 2 else ""
    return (f'<DataArray type="{NUMPY_TO_VTK[values.dtype]}" Name="{name}"{comps} format="binary">'
            f"{base64.b64encode(header.tobytes()).decode()}{base64.b64encode(b''.join(blocks)).decode()}"
            "</DataArray>\n")


def write_vtu(path: str | Path, points: np.ndarray, cells: np.ndarray, point_data: dict[str, np.ndarray]) -> None:
    """Write the section: points (n, 2) in the (r, z) plane (z = 0 out of it), quadrilateral
    cells (e, 4) or (e, 8) in VTK's node order (corners, then mid-sides: axiform's), nodal
    arrays (n,) or (n, k) as float64."""
    n, (e, k) = len(points), cells.shape
    xyz = np.zeros((n, 3))
    xyz[:, :2] = points
    parts = ['<?xml version="1.0"?>\n<VTKFile type="UnstructuredGrid" version="0.1" '
             f'byte_order="{"LittleEndian" if sys.byteorder == "little" else "BigEndian"}" '
             'compressor="vtkZLibDataCompressor">\n<UnstructuredGrid>\n'
             f'<Piece NumberOfPoints="{n}" NumberOfCells="{e}">\n<Points>\n',
             _data_array("Points", xyz), "</Points>\n<Cells>\n",
             _data_array("connectivity", cells.astype(np.int64).ravel()),
             _data_array("offsets", np.arange(k, k * e + 1, k, dtype=np.int64)),
             _data_array("types", np.full(e, VTK_TYPE[k], dtype=np.uint8)), "</Cells>\n<PointData>\n"]
    parts += [_data_array(name, np.asarray(values, dtype=np.float64)) for name, values in point_data.items()]
    parts.append("</PointData>\n</Piece>\n</UnstructuredGrid>\n</VTKFile>\n")
    Path(path).write_text("".join(parts))
