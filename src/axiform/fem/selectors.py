"""Node and edge selectors: coordinates matched with a tolerance, a box, or a set name."""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

import numpy as np

from .mesh import Mesh, edges_on_nodes


class SelectorError(ValueError):
    """A selector that matches nothing or is malformed; the message names it."""


def describe(spec: Mapping[str, Any]) -> str:
    return "{" + ", ".join(f"{k} = {v!r}" for k, v in spec.items() if v is not None) + "}"


def select_nodes(
    mesh: Mesh, spec: Mapping[str, Any], where: str = "selector", corners_only: bool = False
) -> np.ndarray:
    """Indices of the nodes matching every given criterion of spec:
    r / z (coordinate within tol, default 1e-3 of the smallest element edge), box
    [[r0, z0], [r1, z1]] (inclusive, same tolerance), set (a named node set of the mesh)."""
    spec = {k: v for k, v in spec.items() if v is not None}
    if not spec.keys() & {"r", "z", "box", "set"}:
        raise SelectorError(f"{where}: give at least one of r, z, box, set")
    tol = spec.get("tol") or 1e-3 * mesh.size()
    mask = np.ones(mesh.n_nodes, dtype=bool)
    if "r" in spec:
        mask &= np.abs(mesh.points[:, 0] - spec["r"]) <= tol
    if "z" in spec:
        mask &= np.abs(mesh.points[:, 1] - spec["z"]) <= tol
    if "box" in spec:
        (r0, z0), (r1, z1) = spec["box"]
        p = mesh.points
        mask &= (p[:, 0] >= min(r0, r1) - tol) & (p[:, 0] <= max(r0, r1) + tol)
        mask &= (p[:, 1] >= min(z0, z1) - tol) & (p[:, 1] <= max(z0, z1) + tol)
    if "set" in spec:
        name = spec["set"]
        if name not in mesh.node_sets:
            known = ", ".join(sorted(mesh.node_sets)) or "none"
            raise SelectorError(f"{where}: no node set named '{name}' in the mesh (sets: {known})")
        inset = np.zeros(mesh.n_nodes, dtype=bool)
        inset[mesh.node_sets[name]] = True
        mask &= inset
    if corners_only:
        corner = np.zeros(mesh.n_nodes, dtype=bool)
        corner[mesh.corner_nodes] = True
        mask &= corner
    nodes = np.flatnonzero(mask)
    if nodes.size == 0:
        raise SelectorError(f"{where}: selector {describe(spec)} matches no node")
    return nodes


def select_edges(mesh: Mesh, spec: Mapping[str, Any], where: str = "selector") -> np.ndarray:
    """Boundary edges (indices into mesh.boundary_edges) all of whose nodes match spec;
    a set name that is an edge set of the mesh selects those edges directly."""
    spec = {k: v for k, v in spec.items() if v is not None}
    if spec.keys() == {"set"} and spec["set"] in mesh.edge_sets:
        edges = mesh.edge_sets[spec["set"]]
    else:
        edges = edges_on_nodes(mesh, select_nodes(mesh, spec, where))
    if edges.size == 0:
        raise SelectorError(f"{where}: selector {describe(spec)} matches no boundary edge")
    return edges
