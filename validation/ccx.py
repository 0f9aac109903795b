"""CalculiX (ccx) decks and results for the validation scripts that compare with it: the node and
element cards of an axiform mesh, the element faces of boundary edges, a run in a work
folder with its wall time, and the node tables of the .dat file."""

from __future__ import annotations

import os
import re
import subprocess
import time
from pathlib import Path

import numpy as np

# a node table of the .dat file: "<what> for set <SET> and time <t>", a blank line, the rows
NODE_TABLE = re.compile(
    r"^ *(\S[^\n]*?) for set (\w+) and time\s+([-+0-9.Ee]+)\s*\n\s*\n"
    r"((?:[ \t]*[-+0-9.Ee]+(?:[ \t]+[-+0-9.Ee]+)+[ \t]*\n)+)",
    re.MULTILINE,
)


def id_lines(ids, per: int = 12) -> list[str]:
    """Node or element numbers as the lines of a *NSET / *ELSET card, `per` to a line."""
    ids = [str(int(i)) for i in ids]
    return [", ".join(ids[k : k + per]) for k in range(0, len(ids), per)]


def mesh_cards(mesh, elset: str, nset: str = "NALL") -> list[str]:
    """*NODE (all nodes, set `nset`) and *ELEMENT (CAX4 or CAX8, set `elset`) of an axiform
    mesh: node i is ccx node i + 1, cell e is element e + 1 (the same corner-then-mid-side
    order, counter-clockwise)."""
    etype = {4: "CAX4", 8: "CAX8"}[mesh.cells.shape[1]]
    out = [f"*NODE, NSET={nset}"] + [f"{i + 1}, {r:.15g}, {z:.15g}" for i, (r, z) in enumerate(mesh.points)]
    out += [f"*ELEMENT, TYPE={etype}, ELSET={elset}"]
    out += [f"{e + 1}, " + ", ".join(str(k + 1) for k in c) for e, c in enumerate(mesh.cells)]
    return out


def element_faces(mesh, edges: np.ndarray) -> list[tuple[int, int]]:
    """The (element, face) of ccx, both 1-based, of boundary edges (indices into
    mesh.boundary_edges): face f runs from corner f to corner f + 1 (F1 = 1-2 ... F4 = 4-1)."""
    owner = {}
    for e, cell in enumerate(mesh.cells[:, :4]):
        for f in range(4):
            owner[frozenset((int(cell[f]), int(cell[(f + 1) % 4])))] = (e + 1, f + 1)
    return [owner[frozenset(int(n) for n in mesh.boundary_edges[k, :2])] for k in np.asarray(edges)]


def run(name: str, deck: str, work: Path) -> dict:
    """Run ccx on the deck (work/name.inp), one thread: {"ok", "wall_s" and "cpu_s" (of the
    ccx process), "dat" (the .dat text)}; the .frd and solver scratch files are removed, the
    log kept (name.log)."""
    work.mkdir(parents=True, exist_ok=True)
    (work / f"{name}.inp").write_text(deck)
    for ext in (".dat", ".sta", ".frd", ".cvg", ".12d"):
        (work / f"{name}{ext}").unlink(missing_ok=True)
    env = dict(os.environ, OMP_NUM_THREADS="1", CCX_NPROC_EQUATION_SOLVER="1")
    start, before = time.perf_counter(), os.times()
    proc = subprocess.run(["ccx", "-i", name], cwd=work, capture_output=True, text=True, env=env, check=False)
    wall, after = time.perf_counter() - start, os.times()
    cpu = after.children_user + after.children_system - before.children_user - before.children_system
    (work / f"{name}.log").write_text(proc.stdout[-20000:] + proc.stderr[-5000:])
    dat = (work / f"{name}.dat").read_text() if (work / f"{name}.dat").exists() else ""
    for ext in (".frd", ".12d", ".cvg", ".sta"):
        (work / f"{name}{ext}").unlink(missing_ok=True)
    (work / "spooles.out").unlink(missing_ok=True)
    return {"ok": proc.returncode == 0 and "Job finished" in proc.stdout, "wall_s": wall, "cpu_s": cpu, "dat": dat}


def node_tables(dat: str, what: str) -> dict[float, np.ndarray]:
    """The tables `what` (e.g. "temperatures") of a .dat text by time: time -> (rows,
    columns) with the node number in column 0."""
    out = {}
    for m in NODE_TABLE.finditer(dat):
        if m.group(1).strip().startswith(what):
            out[float(m.group(3))] = np.array(
                [[float(v) for v in line.split()] for line in m.group(4).strip().splitlines()]
            )
    return out


def node_values(table: np.ndarray, n_nodes: int) -> np.ndarray:
    """The first value column of a node table as an array over axiform's nodes (n,)."""
    out = np.full(n_nodes, np.nan)
    out[table[:, 0].astype(int) - 1] = table[:, 1]
    return out
