"""Files of a results folder written whole or not at all: an atomic replace, a VTU file of the
mesh with point data, the ParaView series of the VTU files, the mould outlines and the contact
table as CSV text."""

from __future__ import annotations

import csv
import io
import os
from contextlib import contextmanager
from pathlib import Path

import numpy as np


@contextmanager
def atomic(path: str | Path):
    """Yield a temporary path beside `path` to write; on success it replaces `path` in one
    rename, so a reader (or a run killed at any moment) sees the old file or the new one,
    never a part."""
    path = Path(path)
    tmp = path.with_name(f".{path.name}.tmp")
    try:
        yield tmp
        os.replace(tmp, path)
    finally:
        tmp.unlink(missing_ok=True)


def write_atomic(path: str | Path, text: str) -> None:
    with atomic(path) as tmp:
        tmp.write_text(text)


def write_vtu(path: Path, mesh, data: dict[str, np.ndarray]) -> None:
    """One VTU file of the mesh (r, z, 0) with the point data `data`, atomically.  Run by
    ResultsWriter's writer thread: meshio's XML and zlib (which lets go of the GIL) then
    overlap the solve of the next step (about 2 ms of a step's 5 on the plate Q8 4 x 40)."""
    import meshio  # here: 0.1 s to import, for VTU files only

    cell_type = "quad8" if mesh.element.nodes == 8 else "quad"
    pts = np.column_stack([mesh.points, np.zeros(mesh.n_nodes)])
    with atomic(path) as tmp:
        meshio.write(tmp, meshio.Mesh(pts, [(cell_type, mesh.cells)], point_data=data), file_format="vtu")


def series_times(entries: list[tuple[int, float, str]]) -> list[float]:
    """The `timestep` of each entry (step, t, file) of fields.pvd: the process time t of its
    step when the times increase strictly along the series (a reader orders the frames by
    it); else (arc length past a limit point, where the load factor goes back) the step numbers."""
    times = [t for _, t, _ in entries]
    if all(a < b for a, b in zip(times, times[1:], strict=False)):
        return times
    return [float(step) for step, _, _ in entries]


def write_pvd(path: Path, entries: list[tuple[int, float, str]]) -> None:
    """fields.pvd, atomically: a ParaView collection of the VTU files of the entries (step, t,
    file), in their order, with their timesteps (series_times)."""
    from xml.etree import ElementTree as ET  # here: a run without VTU files does without it

    root = ET.Element("VTKFile", type="Collection", version="0.1")
    coll = ET.SubElement(root, "Collection")
    for (_, _, name), t in zip(entries, series_times(entries), strict=False):
        ET.SubElement(coll, "DataSet", timestep=repr(t), part="0", file=name)
    with atomic(path) as tmp:
        ET.ElementTree(root).write(tmp)


def mould_outlines(pairs, lam: float) -> str:
    """The rigid surfaces at load factor lam as CSV text: pair, r, z per outline point."""
    text = io.StringIO()
    table = csv.writer(text, lineterminator="\n")
    table.writerow(["pair", "r", "z"])
    for k, pair in enumerate(pairs):
        pts = pair.surface.polyline() + pair.surface.offset(lam)
        table.writerows([k, f"{r:.10g}", f"{z:.10g}"] for r, z in pts)
    return text.getvalue()


CONTACT_COLUMNS = ("pair", "node", "r", "z", "gap", "pressure", "status", "first_contact")


def contact_table(reports: list[dict], x: np.ndarray, status_names: dict[int, str]) -> str:
    """contact.csv as text: a row per slave node of every pair's report (ContactPair.report:
    node, gap, pressure, status, first_contact, each (m,)) at the current nodes x (n, 2); gap
    and first_contact empty where NaN.  Each column formatted at once, the rows written by
    `csv.writer`."""
    out = io.StringIO()
    writer = csv.writer(out, lineterminator="\n")
    writer.writerow(CONTACT_COLUMNS)
    for k, rep in enumerate(reports):
        node = np.asarray(rep["node"], dtype=np.int64)
        r = [f"{a:.10g}" for a in x[node, 0].tolist()]
        z = [f"{b:.10g}" for b in x[node, 1].tolist()]
        gap = ["" if g != g else f"{g:.6g}" for g in np.asarray(rep["gap"], float).tolist()]
        pressure = [f"{p:.6g}" for p in np.asarray(rep["pressure"], float).tolist()]
        status = [status_names[s] for s in np.asarray(rep["status"]).astype(int).tolist()]
        first = ["" if t != t else repr(t) for t in np.asarray(rep["first_contact"], float).tolist()]
        writer.writerows(zip([k] * len(node), node.tolist(), r, z, gap, pressure, status, first, strict=True))
    return out.getvalue()
