"""A model: mesh, material, supports, loads; its residual and tangent for the solver.

R(u, lambda) = f_int(u) - lambda f_ext(u); the tangent K = dR/du includes the load stiffness
of the follower pressure, so it is not symmetric.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Iterable, Sequence

import numpy as np
import scipy.sparse as sp
from scipy.sparse.csgraph import connected_components

from .assembly import SolidAssembly
from .constraints import DofMap, SparsePattern
from .loads import FollowerPressure
from .mesh import Mesh

DOF_NAMES = {"ur": 0, "uz": 1, "rot": 2}
SFR_EDGE_RULES = ("tie", "fix", "free")


@dataclass
class Evaluation:
    """Residual and tangent at one state: r (free eqs), dR/dlambda (free eqs), K_ff, the full
    residual (reactions at supported dofs), the full external load per unit lambda, and the
    norm of the assembled magnitudes of the element forces (the scale against which the
    residual is small: it does not cancel where large stresses balance), and the round-off
    level of the residual, eps ||K||_inf ||u||: the residual of u rounded to double precision,
    below which no Newton iteration can go (thin walls with a large kappa reach it)."""

    r: np.ndarray
    dr_dlam: np.ndarray
    K: sp.csr_matrix | None
    r_full: np.ndarray
    f_ext_full: np.ndarray
    force_scale: float
    noise: float = 0.0


@dataclass
class Model:
    """Build a model step by step (fix, prescribe, pressure, point_load), then `finalize`.

    sfr_edges: what happens to the fibre rotations of an SFR edge whose normal displacement
    is held at both nodes (clamped edge, axis, symmetry plane): "tie" them to one shared value
    (default), "fix" them to zero, or leave them "free" (the edge then bows).
    """

    mesh: Mesh
    material: object
    sfr_edges: str = "tie"
    fixed: dict[int, float] = field(default_factory=dict)
    pressures: list[FollowerPressure] = field(default_factory=list)
    point_loads: list[tuple[int, float]] = field(default_factory=list)
    contacts: list = field(default_factory=list)

    def __post_init__(self):
        if self.sfr_edges not in SFR_EDGE_RULES:
            raise ValueError(f"sfr_edges must be one of {SFR_EDGE_RULES}, not {self.sfr_edges!r}")
        self.mesh.check()
        self.dpn = self.mesh.element.dofs_per_node
        self.n_full = self.mesh.n_nodes * self.dpn
        self.dofmap: DofMap | None = None

    # ---- building -------------------------------------------------------------------
    def dof(self, nodes: np.ndarray | int, name: str) -> np.ndarray:
        """Full dof numbers of a named dof ("ur", "uz", "rot") at nodes."""
        return np.asarray(nodes) * self.dpn + DOF_NAMES[name]

    def prescribe(self, nodes: Iterable[int], dofs: Sequence[str], value: float = 0.0) -> None:
        """Prescribe dofs at nodes to value * lambda (value 0: fixed).  "rot" is ignored by
        elements without rotations."""
        for name in dofs:
            if name == "rot" and self.dpn == 2:
                continue
            for d in self.dof(np.asarray(nodes), name):
                self.fixed[int(d)] = float(value)
        self.dofmap = None

    fix = prescribe

    def pressure(self, edges: np.ndarray, value: float) -> None:
        """Follower pressure value * lambda on boundary edges (indices of mesh.boundary_edges)."""
        self.pressures.append(FollowerPressure(self.mesh, np.asarray(edges), value))
        self.dofmap = None

    def point_load(self, nodes: Iterable[int], dof: str, value: float) -> None:
        """A force value * lambda on each node: the total force on the revolved ring."""
        for d in self.dof(np.asarray(nodes), dof):
            self.point_loads.append((int(d), float(value)))
        self.dofmap = None

    def contact(self, pair) -> None:
        """Add a contact pair (axiform.contact.ContactPair)."""
        self.contacts.append(pair)
        self.dofmap = None

    # ---- finalize ------------------------------------------------------------------------
    def _sfr_constraints(self, fixed: dict[int, float]) -> list[np.ndarray]:
        """Ties (or fixes) of theta on edges whose normal displacement is held at both nodes,
        and a fixed theta where nothing removes the uniform-theta zero-energy mode."""
        ties = []
        if self.sfr_edges != "free":
            held = np.zeros((self.mesh.n_nodes, 2), dtype=bool)
            for d in fixed:
                node, k = divmod(d, self.dpn)
                if k < 2:
                    held[node, k] = True
            e = self.mesh.boundary_edges[:, :2]
            t = self.mesh.points[e[:, 1]] - self.mesh.points[e[:, 0]]
            t /= np.linalg.norm(t, axis=1)[:, None]
            both = held[e[:, 0]] & held[e[:, 1]]  # (m, 2): ur, uz held at both ends
            along_z = np.abs(t[:, 0]) < 1e-8
            along_r = np.abs(t[:, 1]) < 1e-8
            normal_held = (both[:, 0] & both[:, 1]) | (along_z & both[:, 0]) | (along_r & both[:, 1])
            for i, j in e[normal_held]:
                a, b = self.dof(i, "rot"), self.dof(j, "rot")
                if self.sfr_edges == "fix":
                    fixed.setdefault(int(a), 0.0)
                    fixed.setdefault(int(b), 0.0)
                else:
                    ties.append(np.array([a, b]))
        # one theta per connected body, unless some theta of that body is already held
        cells = self.mesh.cells
        rows = np.repeat(cells[:, 0], cells.shape[1])
        graph = sp.coo_matrix((np.ones(rows.size), (rows, cells.ravel())),
                              shape=(self.mesh.n_nodes, self.mesh.n_nodes))
        _, body = connected_components(graph, directed=False)
        held = {body[d // self.dpn] for d in fixed if d % self.dpn == 2}
        for b in np.unique(body[cells[:, 0]]):
            if b not in held:
                node = int(cells[body[cells[:, 0]] == b][0, 0])
                fixed[int(self.dof(node, "rot"))] = 0.0
        return ties

    def finalize(self) -> "Model":
        """Number the equations and build the sparse pattern (once)."""
        fixed = dict(self.fixed)
        ties = self._sfr_constraints(fixed) if self.dpn == 3 else []
        self.dofmap = DofMap(self.n_full, fixed, ties)
        self.solid = SolidAssembly(self.mesh, self.material)
        self.pattern = SparsePattern(self.dofmap, [self.solid.dofs] + [p.dofs for p in self.pressures])
        self._solid_pos = self.pattern.positions(self.solid.dofs)
        self._pressure_pos = [self.pattern.positions(p.dofs) for p in self.pressures]
        self._contact_dofs = [c.dofs(self.dpn) for c in self.contacts]
        self._contact_pos = [self.pattern.positions(d) for d in self._contact_dofs]
        self._contact_edge_pos = [self.pattern.positions(c.edge_dofs(self.dpn)) for c in self.contacts]
        self.f_point = np.zeros(self.n_full)
        for d, v in self.point_loads:
            self.f_point[d] += v
        return self

    @property
    def n_free(self) -> int:
        return self.dofmap.nf

    def commit(self) -> None:
        """A step converged at the last evaluated state: update the history variables
        (contact stick points, sticky nodes, positions for the crossing test)."""
        for pair in self.contacts:
            pair.commit()

    # ---- evaluation ------------------------------------------------------------------------
    def expand(self, u_f: np.ndarray, lam: float) -> np.ndarray:
        return self.dofmap.expand(u_f, lam)

    def external_load(self, u_full: np.ndarray, tangent: bool = True):
        """f_ext per unit lambda (full vector) and, if asked, its derivative's pattern data."""
        f = self.f_point.copy()
        data = None
        for p, pos in zip(self.pressures, self._pressure_pos):
            fe, Ke = p.evaluate(u_full, tangent)
            f += np.bincount(p.dofs.ravel(), weights=fe.ravel(), minlength=self.n_full)
            if tangent:
                data = self.pattern.accumulate(pos, Ke, data)
        return f, data

    def evaluate(self, u_f: np.ndarray, lam: float, tangent: bool = True) -> Evaluation:
        """Residual R = f_int - lambda f_ext on the free equations, dR/dlambda and K_ff."""
        dm = self.dofmap
        u = dm.expand(u_f, lam)
        fe, Ke = self.solid.evaluate(u, tangent)
        f_int = np.bincount(self.solid.dofs.ravel(), weights=fe.ravel(), minlength=self.n_full)
        f_abs = np.bincount(self.solid.dofs.ravel(), weights=np.abs(fe).ravel(), minlength=self.n_full)
        f_ext, dfext = self.external_load(u, tangent)
        r_full = f_int - lam * f_ext
        # contact: R -= f_c, K -= df_c/dx; a moving surface adds dR/dlambda = (df_c/dx) motion
        dr_contact = np.zeros(self.n_full)
        contact_data = []
        u2 = u.reshape(-1, self.dpn)[:, :2]
        for pair, dofs in zip(self.contacts, self._contact_dofs):
            fc, Kc, _ = pair.evaluate(u2, lam)
            np.add.at(r_full, dofs.ravel(), -fc.ravel())
            motion = np.asarray(pair.surface.motion, float)
            if motion.any():
                np.add.at(dr_contact, dofs.ravel(), (Kc @ motion).ravel())
            contact_data.append(-Kc)
        r_eq = dm.gather(r_full)
        dr_dlam = (dm.gather(dr_contact) - dm.gather(f_ext))[: dm.nf]
        K = None
        if tangent:
            data = self.pattern.accumulate(self._solid_pos, Ke)
            if dfext is not None:
                data -= lam * dfext
            for pos, Kc in zip(self._contact_pos, contact_data):
                data = self.pattern.accumulate(pos, Kc, data)
            for pos, pair in zip(self._contact_edge_pos, self.contacts):
                data = self.pattern.accumulate(pos, -pair.coupling, data)  # through the current areas
            K, K_fp = self.pattern.blocks(data)
            if dm.np:
                dr_dlam = dr_dlam + K_fp @ dm.prescribed_ref
        scale = float(np.linalg.norm(f_abs) + abs(lam) * np.linalg.norm(f_ext))
        noise = 0.0
        if K is not None and K.nnz:
            row_sums = np.add.reduceat(np.abs(K.data), K.indptr[:-1][np.diff(K.indptr) > 0])
            noise = float(np.finfo(float).eps * row_sums.max() * np.linalg.norm(u))
        return Evaluation(r_eq[: dm.nf], dr_dlam, K, r_full, f_ext, scale, noise)
