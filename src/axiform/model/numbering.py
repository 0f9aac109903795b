"""What `Model.finalize` decides from the builder's inputs before the system is made: the
fibre rotations SFR ties or fixes, the contact stabilization of each pair, the prescribed
equations grouped by curve, the rigid translations no support holds.  Pure functions of
their arguments: they write into nothing they are given.
"""

from __future__ import annotations

import copy
from collections.abc import Mapping, Sequence
from typing import TYPE_CHECKING

import numpy as np
import scipy.sparse as sp

from ..fem.constraints import DofMap
from ..fem.curves import PROPORTIONAL, Curve
from ..fem.graphs import connected_components
from ..fem.mesh import Mesh
from .guards import bodies, free_to_slide

if TYPE_CHECKING:
    from ..contact.pair import ContactPair


def sfr_constraints(mesh: Mesh, dpn: int, fixed: dict[int, float], rule: str) -> list[np.ndarray]:
    """Ties (or fixes, added to `fixed`, the caller's copy) of the fibre rotation theta on
    edges whose normal displacement is held at both nodes (rule "tie", "fix" or "free"), and
    a fixed theta where nothing removes the uniform-theta zero-energy mode of a body.
    Returns the ties, pairs of full dofs (2,)."""
    ties = []
    if rule != "free":
        held = np.zeros((mesh.n_nodes, 2), dtype=bool)
        for d in fixed:
            node, k = divmod(d, dpn)
            if k < 2:
                held[node, k] = True
        e = mesh.boundary_edges[:, :2]
        t = mesh.points[e[:, 1]] - mesh.points[e[:, 0]]
        t /= np.linalg.norm(t, axis=1)[:, None]
        both = held[e[:, 0]] & held[e[:, 1]]  # (m, 2): ur, uz held at both ends
        along_z = np.abs(t[:, 0]) < 1e-8
        along_r = np.abs(t[:, 1]) < 1e-8
        normal_held = (both[:, 0] & both[:, 1]) | (along_z & both[:, 0]) | (along_r & both[:, 1])
        for i, j in e[normal_held]:
            a, b = i * dpn + 2, j * dpn + 2
            if rule == "fix":
                fixed.setdefault(int(a), 0.0)
                fixed.setdefault(int(b), 0.0)
            else:
                ties.append(np.array([a, b]))
    # one theta per connected body, unless some theta of that body is already held
    cells = mesh.cells
    rows = np.repeat(cells[:, 0], cells.shape[1])
    graph = sp.coo_matrix((np.ones(rows.size), (rows, cells.ravel())), shape=(mesh.n_nodes, mesh.n_nodes))
    _, body = connected_components(graph, directed=False)
    held_bodies = {body[d // dpn] for d in fixed if d % dpn == 2}
    for b in np.unique(body[cells[:, 0]]):
        if b not in held_bodies:
            node = int(cells[body[cells[:, 0]] == b][0, 0])
            fixed[int(node * dpn + 2)] = 0.0
    return ties


def stabilized(mesh: Mesh, dpn: int, fixed: Mapping[int, float], pairs: Sequence[ContactPair]) -> list[ContactPair]:
    """The contact pairs as the system uses them: where a pair leaves its stabilization to
    the model (None), a copy of it with STABILIZATION where its slaves lie on a body that no
    prescribed uz holds (held only by contact) and none elsewhere; the other pairs as given.
    A function of the supports and the pairs only (not of the order in which they were
    given), and the pairs given are left as they are."""
    held_uz = [d // dpn for d in fixed if d % dpn == 1]
    free = set(free_to_slide(mesh.n_nodes, mesh.cells, np.array(held_uz, np.int64), np.zeros(0, np.int64)))
    body = bodies(mesh.n_nodes, mesh.cells) if free else None
    out = []
    for pair in pairs:
        if pair.stabilization is None:
            from ..contact.pair import STABILIZATION

            on_free = body is not None and bool(set(body[pair.nodes].tolist()) & free)
            pair = copy.copy(pair)
            pair.stabilization = STABILIZATION if on_free else 0.0
        out.append(pair)
    return out


def prescribed_curves(
    dofmap: DofMap, fixed: Mapping[int, float], curve_of_dof: Mapping[int, Curve]
) -> tuple[tuple[Curve, ...], np.ndarray]:
    """The distinct curves of the prescribed equations (in their first order) and the index of
    each prescribed equation's curve among them, (np,): the value of equation k at t is
    prescribed_ref[k] f_index[k](t)."""
    curve_of_eq = {int(dofmap.eq[d]) - dofmap.nf: curve_of_dof.get(d, PROPORTIONAL) for d in fixed}
    curves = tuple(dict.fromkeys(curve_of_eq.values())) or (PROPORTIONAL,)
    index = {c: i for i, c in enumerate(curves)}
    return curves, np.array([index[curve_of_eq[k]] for k in range(dofmap.np)], dtype=np.int64)


def rigid_translations(mesh: Mesh, dpn: int, dofmap: DofMap, n_free: int) -> sp.csc_matrix:
    """Unit translations along z of the bodies that no prescribed uz holds, as columns over
    the unknowns, (n_free, k) (zero on the unknowns past the free equations): zero-energy
    modes of the tangent unless contact (or a tie) resists them."""
    body = bodies(mesh.n_nodes, mesh.cells)
    uz = np.arange(mesh.n_nodes) * dpn + 1
    eq = dofmap.eq[uz]
    held = np.zeros(body.max() + 1, dtype=bool)
    held[body[eq >= dofmap.nf]] = True
    free = (eq < dofmap.nf) & ~held[body]
    _, col = np.unique(body[free], return_inverse=True)
    return sp.csc_matrix((np.ones(free.sum()), (eq[free], col)), shape=(n_free, col.max(initial=-1) + 1))
