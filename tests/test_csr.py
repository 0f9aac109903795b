"""csr.CSRMatrix, the tangent of Model.evaluate, against SciPy's csr_matrix; `axiform run`
solves without importing scipy.sparse (0.06 to 0.15 s of every run)."""

import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import scipy.sparse as sp

from axiform.csr import CSRMatrix

SRC = Path(__file__).resolve().parents[1] / "src"
PLATE = Path(__file__).resolve().parents[1] / "examples" / "hughes_carnoy_plate.toml"


def test_the_operations_agree_with_scipy():
    rng = np.random.default_rng(0)
    S = sp.random(40, 30, density=0.15, random_state=1, format="csr")
    S.data = rng.standard_normal(S.nnz)
    S.sort_indices()
    K = CSRMatrix(S.data, S.indices, S.indptr, S.shape)
    assert K.nnz == S.nnz and K.format == "csr"
    assert np.array_equal(K.toarray(), S.toarray())
    x, X = rng.standard_normal(30), rng.standard_normal((30, 3))
    assert np.allclose(K @ x, S @ x, rtol=1e-14, atol=1e-14)
    assert np.allclose(K @ X, S @ X, rtol=1e-14, atol=1e-14)
    assert (K.tocsr() != S).nnz == 0 and (K.tocsc() != S).nnz == 0


def test_a_run_does_not_import_scipy_sparse(tmp_path):
    code = ("import sys; from axiform.cli import main; "
            f"code = main(['run', {str(PLATE)!r}, '--out', {str(tmp_path / 'out')!r}, '-q', "
            "'--set', 'solver.steps=2', '--set', 'solver.target=0.5', '--set', 'output.plots=false']); "
            "print(code, sorted(m for m in sys.modules if m.startswith('scipy')))")
    proc = subprocess.run([sys.executable, "-c", code], env={**os.environ, "PYTHONPATH": str(SRC)},
                          capture_output=True, text=True, timeout=120)
    assert proc.stdout.split() == ["0", "[]"], proc.stdout + proc.stderr
