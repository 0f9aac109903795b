"""Shared pieces of the benchmarks: the test model, a deformed state, the Timing record, the
machine description and the results file.  Not a benchmark itself."""

from __future__ import annotations

import os
import platform
from pathlib import Path
from typing import NamedTuple

import numpy as np

from axiform import Model, MooneyRivlin, rectangle
from axiform.fem.mesh import edges_on_nodes

RESULTS = Path(__file__).resolve().parent / "results"
MATERIAL = MooneyRivlin(80.0, 20.0, 1e4)


def divisions_for_elements(n_elements: int) -> tuple[int, int]:
    """A square-ish (nr, nz) grid with about n_elements cells."""
    nr = max(2, int(round(np.sqrt(n_elements))))
    nz = max(2, int(round(n_elements / nr)))
    return nr, nz


def divisions_for_dofs(element: str, n_dofs: int) -> tuple[int, int]:
    """A square (n, n) grid whose full dof count is about n_dofs."""
    if element == "q8":  # 3 n^2 + 4 n + 1 nodes
        n = max(2, int(round(np.sqrt(n_dofs / 6.0))))
    elif element == "sfr":
        n = max(2, int(round(np.sqrt(n_dofs / 3.0)))) - 1
    else:
        n = max(2, int(round(np.sqrt(n_dofs / 2.0)))) - 1
    return n, n


TOP_DISPLACEMENT = -0.05  # the prescribed axial displacement of the ring's top face


def build_model(
    element: str,
    divisions: tuple[int, int],
    pressure: float = 5.0,
    top_displacement: float | None = TOP_DISPLACEMENT,
    pressed: float = 0.5,
    finalize: bool = True,
) -> Model:
    """The benchmark body: a thick ring r in [1, 2], z in [0, 1], on a roller at z = 0, a
    follower pressure on the lower half of the inner face r = 1 and, if asked, a prescribed
    axial displacement of the top face (a non-empty K_fp block).

    The pressed patch ends at a free node (r = 1, z = 0.5): there the load stiffness of the
    follower pressure does not cancel, so K_ff is really non-symmetric (a pressure on a
    whole face between two supported ends gives a symmetric assembled K_ff: pressed=1).
    finalize=False leaves `model.finalize()` to the caller (to time it)."""
    mesh = rectangle((1.0, 2.0), (0.0, 1.0), divisions, element)
    model = Model(mesh, MATERIAL, formulation="displacement")
    model.fix(mesh.node_sets["bottom"], ["uz"])
    if top_displacement is not None:
        model.prescribe(mesh.node_sets["top"], ["uz"], top_displacement)
    left = mesh.node_sets["left"]
    model.pressure(edges_on_nodes(mesh, left[mesh.points[left, 1] <= pressed + 1e-12]), pressure)
    return model.finalize() if finalize else model


def deformed_state(
    model: Model, seed: int = 0, lam: float = 0.5, noise: float = 0.01, top_displacement: float = TOP_DISPLACEMENT
) -> tuple[np.ndarray, float]:
    """Free unknowns u_f of a homogeneous stretch (matching the prescribed top displacement)
    plus a small random perturbation (noise x the element size), so that F != I and every
    Gauss point differs, with J well away from 0."""
    mesh = model.mesh
    rng = np.random.default_rng(seed)
    P = mesh.points
    h = mesh.size()
    u = np.zeros((mesh.n_nodes, model.dpn))
    top = lam * top_displacement  # the top face's prescribed uz at load factor lam
    u[:, 0] = 0.04 * (P[:, 0] - 1.0) + 0.01 + noise * h * rng.standard_normal(mesh.n_nodes)
    u[:, 1] = top * P[:, 1] + noise * h * rng.standard_normal(mesh.n_nodes)
    if model.dpn == 3:
        u[:, 2] = 0.01 * rng.standard_normal(mesh.n_nodes)
    return u.ravel()[model.dofmap.free_dof].copy(), lam


class Timing(NamedTuple):
    """One measurement.  On a shared machine the CPU time of a single-threaded computation is
    steadier than its wall time (time slices lost to other processes do not count), so the
    tables use it and also give the wall time."""

    wall: float  # s, wall clock
    cpu: float  # s, CPU time of this process (all its threads)


def load_average() -> str:
    try:
        return ", ".join(f"{x:.1f}" for x in os.getloadavg())
    except OSError:
        return "?"


def machine() -> str:
    """One line: CPU model, cores, memory, Python / NumPy / SciPy versions and the BLAS."""
    cpu = platform.processor() or "unknown CPU"
    try:
        with open("/proc/cpuinfo") as f:
            for line in f:
                if line.startswith("model name"):
                    cpu = line.split(":", 1)[1].strip()
                    break
    except OSError:
        pass
    mem = ""
    try:
        with open("/proc/meminfo") as f:
            kb = int(f.readline().split()[1])
            mem = f", {kb / 2**20:.0f} GiB RAM"
    except (OSError, ValueError, IndexError):
        pass
    import scipy

    blas = "?"
    try:
        cfg = np.show_config(mode="dicts")
        blas = cfg["Build Dependencies"]["blas"]["name"]
    except Exception:  # noqa: BLE001  (older NumPy)
        pass
    return (
        f"{cpu}, {os.cpu_count()} cores{mem}; Python {platform.python_version()}, "
        f"NumPy {np.__version__} ({blas}), SciPy {scipy.__version__}"
    )


def write_result(name: str, text: str) -> Path:
    RESULTS.mkdir(parents=True, exist_ok=True)
    path = RESULTS / f"{name}.md"
    path.write_text(text)
    return path


def table(header: list[str], rows: list[list[str]]) -> str:
    out = ["| " + " | ".join(header) + " |", "|" + "|".join("---:" if i else "---" for i in range(len(header))) + "|"]
    out += ["| " + " | ".join(str(c) for c in r) + " |" for r in rows]
    return "\n".join(out) + "\n"
