"""Dof numbering: fixed and prescribed dofs, ties (shared dofs), and the sparse pattern.

Full dofs are numbered node by node, dofs_per_node each.  Every full dof maps to an
equation of the extended system: free equations 0..nf-1 first, then prescribed ones
nf..nf+np-1.  Tied dofs share one equation.  Prescribed values are multiplied by the
load factor lambda.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
import scipy.sparse as sp

from .graphs import connected_components


class DofMap:
    """Map full dofs to equations.  fixed: {full dof: reference value}; ties: groups of full
    dofs that share one value."""

    def __init__(self, n_full: int, fixed: dict[int, float], ties: Sequence[np.ndarray] = ()):
        root = np.arange(n_full)
        if len(ties):
            pairs = np.vstack([np.column_stack([g[:-1], g[1:]]) for g in map(np.asarray, ties) if len(g) > 1])
            graph = sp.coo_matrix((np.ones(len(pairs)), (pairs[:, 0], pairs[:, 1])), shape=(n_full, n_full))
            _, label = connected_components(graph, directed=False)
            first = np.full(label.max() + 1, n_full)
            np.minimum.at(first, label, np.arange(n_full))
            root = first[label]
        value: dict[int, float] = {}  # root dof -> reference value
        for dof, v in fixed.items():
            r = root[dof]
            if r in value and abs(value[r] - v) > 1e-14 * max(1.0, abs(v)):
                raise ValueError(f"dof {dof} is tied to a dof prescribed to another value")
            value[r] = v
        roots = np.unique(root)
        is_presc = np.isin(roots, np.fromiter(value.keys(), dtype=np.int64, count=len(value)))
        free_roots, presc_roots = roots[~is_presc], roots[is_presc]
        eq_of_root = np.empty(n_full, dtype=np.int64)
        eq_of_root[free_roots] = np.arange(len(free_roots))
        eq_of_root[presc_roots] = len(free_roots) + np.arange(len(presc_roots))
        self.n_full = n_full
        self.nf = len(free_roots)
        self.np = len(presc_roots)
        self.eq = eq_of_root[root]  # full dof -> equation
        self.prescribed_ref = np.array([value[r] for r in presc_roots], dtype=float)
        self.free_dof = free_roots  # one representative full dof per free equation

    @property
    def n_eq(self) -> int:
        return self.nf + self.np

    def expand(self, u_f: np.ndarray, prescribed: np.ndarray) -> np.ndarray:
        """Full displacement vector from the free unknowns (nf,) and the prescribed values (np,)."""
        return np.concatenate([u_f[: self.nf], prescribed])[self.eq]

    def gather(self, v_full: np.ndarray) -> np.ndarray:
        """Sum a full vector (forces) into the equations of the extended system."""
        return np.bincount(self.eq, weights=v_full, minlength=self.n_eq)


class SparsePattern:
    """The CSR pattern of the extended system, built once from the dof connectivity of
    every term (element dofs, edge dofs ...); values are refilled each iteration.

    The data array holds the K_ff block first (free rows and columns, in CSR order), then
    K_fp (free rows, prescribed columns), then the prescribed rows: K_ff's values are a
    view of its head, with no copy."""

    def __init__(self, dofmap: DofMap, blocks: list[np.ndarray]):
        self.dofmap = dofmap
        n = dofmap.n_eq
        keys = np.sort(np.concatenate([self._keys(b).ravel() for b in blocks]))
        distinct = np.empty(keys.size, dtype=bool)  # np.unique, by one sort: several times faster
        distinct[:1] = True
        np.not_equal(keys[1:], keys[:-1], out=distinct[1:])
        self.keys = keys[distinct]
        rows, cols = self.keys // n, self.keys % n
        nf = dofmap.nf
        ff = (rows < nf) & (cols < nf)
        fp = (rows < nf) & (cols >= nf)
        order = np.concatenate([np.flatnonzero(ff), np.flatnonzero(fp), np.flatnonzero(~(ff | fp))])
        self._slot = np.empty(order.size, dtype=np.int64)  # sorted key -> place in the data array
        self._slot[order] = np.arange(order.size)
        self.n_ff, self.n_fp = int(ff.sum()), int(fp.sum())
        self._ff_csr = self._sub(rows[ff], cols[ff], nf, nf)
        self._fp_csr = self._sub(rows[fp], cols[fp] - nf, nf, dofmap.np)
        self._fp_rows, self._fp_cols = rows[fp], cols[fp] - nf
        # the terms of few entries: id of their positions -> (positions, distinct ones, inverse)
        self._few: dict[int, tuple[np.ndarray, np.ndarray, np.ndarray]] = {}

    def _keys(self, dofs: np.ndarray) -> np.ndarray:
        eq = self.dofmap.eq[dofs]  # (m, k)
        return eq[:, :, None] * self.dofmap.n_eq + eq[:, None, :]

    @staticmethod
    def _sub(rows, cols, nr, nc):
        indptr = np.concatenate([[0], np.cumsum(np.bincount(rows, minlength=nr))])
        return cols.astype(np.int32), indptr.astype(np.int32), (nr, nc)

    def positions(self, dofs: np.ndarray) -> np.ndarray:
        """Positions in the data array of each entry (m, k, k) of blocks on these dofs.  For a
        term with fewer entries than a quarter of the pattern's (a pressure, a contact pair)
        its distinct positions and where each entry goes among them are kept with the array
        (`accumulate` sums over them)."""
        pos = self._slot[np.searchsorted(self.keys, self._keys(dofs)).ravel()]
        if 4 * pos.size < len(self.keys):
            distinct, inverse = np.unique(pos, return_inverse=True)
            self._few[id(pos)] = (pos, distinct, inverse.ravel())  # the array held: its id is not reused
        return pos

    def accumulate(self, positions: np.ndarray, values: np.ndarray, data: np.ndarray | None = None):
        """Add values (matching positions) into a data array of the pattern.  Into a data array
        given, a term of few entries (`positions`) is summed over its own distinct positions
        and added there, not over a whole array of the pattern (the same sums)."""
        if data is None:
            return np.bincount(positions, weights=values.ravel(), minlength=len(self.keys))
        few = self._few.get(id(positions))
        if few is not None and few[0] is positions:
            distinct, inverse = few[1], few[2]
            data[distinct] += np.bincount(inverse, weights=values.ravel(), minlength=distinct.size)
            return data
        data += np.bincount(positions, weights=values.ravel(), minlength=len(self.keys))
        return data

    def free_block(self, data: np.ndarray) -> sp.csr_matrix:
        """K_ff (free rows and columns) as a CSR matrix on a view of data."""
        i, p, s = self._ff_csr
        K = sp.csr_matrix((data[: self.n_ff], i, p), shape=s)
        K.has_sorted_indices = True  # the keys are sorted: spares a scan of every row
        return K

    def fp_product(self, data: np.ndarray, v: np.ndarray) -> np.ndarray:
        """K_fp v (nf,) for v (np,) on the prescribed equations."""
        w = data[self.n_ff : self.n_ff + self.n_fp] * v[self._fp_cols]
        return np.bincount(self._fp_rows, weights=w, minlength=self.dofmap.nf)

    def blocks(self, data: np.ndarray) -> tuple[sp.csr_matrix, sp.csr_matrix]:
        """K_ff and K_fp (free rows; free and prescribed columns) as CSR matrices."""
        i, p, s = self._fp_csr
        K_fp = sp.csr_matrix((data[self.n_ff : self.n_ff + self.n_fp], i, p), shape=s)
        return self.free_block(data), K_fp


class BorderedPattern:
    """The CSR pattern of K_ff (nf, nf) bordered by m constraint rows and columns,
    [[K, -G], [Cu, Cp]]: G (nf, m) and Cu (m, nf) = c_u G^T nonzero only on the rows
    `supports[j]` (the equations of cavity j's wall), Cp (m, m) diagonal, its entry j
    present where diagonal[j] (a gas cavity: dC/dp = V; a volume constraint has none).
    Built once from K_ff's pattern; `matrix` places the values of an iteration with one
    gather (scipy's block assembly rebuilt the whole matrix at every iteration)."""

    def __init__(self, pattern: SparsePattern, supports: list[np.ndarray], diagonal: list[bool]):
        indices, indptr, (nf, _) = pattern._ff_csr
        self.supports = [np.asarray(s, np.int64) for s in supports]
        self.diagonal = np.flatnonzero(diagonal)
        m = len(supports)
        k_rows = np.repeat(np.arange(nf), np.diff(indptr))
        col = np.concatenate([np.full(len(s), nf + j) for j, s in enumerate(self.supports)] + [np.zeros(0, int)])
        row = np.concatenate(self.supports + [np.zeros(0, int)])
        rows = np.concatenate([k_rows, row, col, nf + self.diagonal])
        cols = np.concatenate([indices, col, row, nf + self.diagonal])
        source = np.arange(1, len(rows) + 1, dtype=float)  # where each entry comes from, + 1
        B = sp.csr_matrix((source, (rows, cols)), shape=(nf + m, nf + m))
        B.sort_indices()
        self._source = B.data.astype(np.int64) - 1  # the CSR slot -> the entry of the values
        self._indices, self._indptr, self.shape = B.indices, B.indptr, B.shape

    def matrix(self, K: sp.csr_matrix, G: np.ndarray, c_u: np.ndarray, c_p: np.ndarray) -> sp.csr_matrix:
        """The bordered matrix of K_ff (on this pattern), G (nf, m), c_u (m,) and c_p (m,),
        with no stored zero in the border (a wall node on the axis, dV/du_r = 0; a volume
        constraint's dC/dp), as block assembly leaves them out: the same matrix."""
        g = [G[s, j] for j, s in enumerate(self.supports)]
        border = np.concatenate(g + [c * v for c, v in zip(c_u, g, strict=False)] + [c_p[self.diagonal]])
        if not border.all() or not np.array_equal(np.flatnonzero(c_p), self.diagonal):  # zeros: another pattern
            Cu = c_u[:, None] * G.T
            return sp.bmat([[K, sp.csr_matrix(-G)], [sp.csr_matrix(Cu), sp.csr_matrix(np.diag(c_p))]], format="csr")
        n_g = sum(len(v) for v in g)
        values = np.concatenate([K.data, -border[:n_g], border[n_g:]])
        out = sp.csr_matrix((values[self._source], self._indices, self._indptr), shape=self.shape)
        out.has_sorted_indices = True
        return out
