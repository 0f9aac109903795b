"""The tangent K_ff as the program's own CSR matrix: its three arrays (the data a view of the
pattern's) and the few operations that `axiform run` asks of them, so that its path does not
import scipy.sparse (0.06 to 0.15 s of every run, benchmarks/README.md § 3.5).  `tocsr()`
gives SciPy's csr_matrix on the same arrays for everything else.
"""

from __future__ import annotations

import numpy as np


class CSRMatrix:
    """A square or rectangular matrix in compressed sparse rows: data (nnz,), column indices
    (nnz,) sorted within each row, row pointers indptr (n_rows + 1,), shape."""

    format = "csr"
    has_sorted_indices = True

    def __init__(self, data: np.ndarray, indices: np.ndarray, indptr: np.ndarray, shape: tuple[int, int]):
        self.data, self.indices, self.indptr, self.shape = data, indices, indptr, shape

    @property
    def nnz(self) -> int:
        return int(self.indptr[-1])

    def row_of_entries(self) -> np.ndarray:
        """The row of each stored entry (nnz,)."""
        return np.repeat(np.arange(self.shape[0]), np.diff(self.indptr))

    def toarray(self) -> np.ndarray:
        """The dense matrix (n_rows, n_cols)."""
        dense = np.zeros(self.shape)
        np.add.at(dense, (self.row_of_entries(), self.indices), self.data)
        return dense

    def __matmul__(self, x: np.ndarray) -> np.ndarray:
        """K x for x (n_cols,) or (n_cols, k)."""
        x = np.asarray(x)
        rows = self.row_of_entries()
        if x.ndim == 1:
            return np.bincount(rows, weights=self.data * x[self.indices], minlength=self.shape[0])
        return np.column_stack([self @ x[:, j] for j in range(x.shape[1])]).reshape(self.shape[0], *x.shape[1:])

    def tocsr(self):
        """SciPy's csr_matrix on the same arrays."""
        import scipy.sparse as sp

        K = sp.csr_matrix((self.data, self.indices, self.indptr), shape=self.shape)
        K.has_sorted_indices = True
        return K

    def tocsc(self):
        return self.tocsr().tocsc()
