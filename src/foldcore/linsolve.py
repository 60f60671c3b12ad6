"""Sparse SPD factorisation behind one small interface: factor once, solve many.

Backends: ``cholmod`` (scikit-sparse, simplicial — measured ~4× faster solves
than supernodal on sheet-like matrices, DESIGN.md) and ``scipy`` (SuperLU), the
fallback when scikit-sparse is not installed. ``refactor`` reuses the symbolic
analysis (CHOLMOD) when only the values of K change.

Fill-reducing ordering (CHOLMOD): its default (AMD, METIS only when AMD's
fill looks poor) below ``NESTED_DISSECTION_FROM`` rows, CHOLMOD's nested
dissection (``nesdis``) from there. Measured by ``bench/ordering.py`` on the
scaling benchmark's Miura-ori K (2-core Xeon, 2026-11-25,
``bench/results/ordering.json``), default → nesdis: at 88 796 rows
(50 × 50) nnz(L) −15 %, solve 5.5 → 4.2 ms, analysis + numeric
factorisation 0.16 → 0.22 s; at 357 596 rows (100 × 100) nnz(L) −21 %,
solve 43 → 37 ms, numeric 1.30 → 0.63 s, analysis 0.13 → 0.73 s; at
1 435 196 rows (200 × 200) nnz(L) −27 %, solve 225 → 179 ms, analysis +
numeric 13.4 → 8.9 s. Below ~50 000 rows the two fill alike (20 × 20: −5 %)
and nesdis's analysis costs more (3 → 15 ms at 20 × 20). A CHOLMOD built
without METIS has no nesdis: the default ordering is used there.
"""
from __future__ import annotations

import numpy as np
import scipy.sparse as sp

NESTED_DISSECTION_FROM = 50_000  # rows from which CHOLMOD orders by nested dissection


def cholmod_ordering(n_rows: int) -> str:
    """CHOLMOD ``ordering_method`` for a matrix of ``n_rows`` rows (module docstring)."""
    return "nesdis" if n_rows >= NESTED_DISSECTION_FROM else "default"


def cholmod_available() -> bool:
    try:
        import sksparse.cholmod  # noqa: F401
    except ImportError:
        return False
    return True


def resolved_backend(backend: str) -> str:
    """``"cholmod"`` or ``"scipy"`` for a backend name (``auto``: CHOLMOD when
    scikit-sparse imports); ValueError for an unknown one."""
    if backend == "auto":
        backend = "cholmod" if cholmod_available() else "scipy"
    if backend not in ("cholmod", "scipy"):
        raise ValueError(f"unknown linear-solver backend {backend!r} "
                         "(expected 'auto', 'cholmod' or 'scipy')")
    return backend


class Factor:
    """Factorisation of a sparse symmetric positive-definite matrix.

    Parameters
    ----------
    matrix : (n, n) scipy.sparse matrix
    backend : {"auto", "cholmod", "scipy"}
        ``auto`` picks CHOLMOD when scikit-sparse imports, else SciPy.
    stored : {"full", "lower"}
        What ``matrix`` holds: both triangles, or only the lower one (row ≥
        column) of the symmetric matrix. CHOLMOD reads only the lower triangle
        either way (scikit-sparse passes it as stype −1), so a lower-only
        matrix gives the same factor from half the memory, as fast (the
        rigid-body normal matrix of a thin Miura 20 × 20, 39 633 rows, six
        interleaved refactorisations, 2-core Xeon guest, 2026-12-02: medians
        33 vs 32 ms; 50 × 50, 255 093 rows: 294 vs 332 ms). SciPy's LU needs
        both: it is mirrored there.
    """

    def __init__(self, matrix, backend: str = "auto", stored: str = "full"):
        backend = resolved_backend(backend)
        if stored not in ("full", "lower"):
            raise ValueError(f"unknown matrix storage {stored!r} (expected 'full' or 'lower')")
        self.backend, self.stored = backend, stored
        self._factor = None
        self.refactor(matrix)

    def refactor(self, matrix) -> None:
        """New numeric factorisation of a matrix with the same sparsity pattern."""
        matrix = sp.csc_matrix(matrix)
        if self.backend == "scipy":
            from scipy.sparse.linalg import splu
            if self.stored == "lower":  # L + Lᵀ − diag
                matrix = (matrix + sp.tril(matrix, -1).T).tocsc()
            self._factor = splu(matrix, permc_spec="MMD_AT_PLUS_A",
                                options={"SymmetricMode": True})
        elif self._factor is None:
            from sksparse.cholmod import CholmodNotInstalledError, cholesky
            try:
                self._factor = cholesky(matrix, mode="simplicial",
                                        ordering_method=cholmod_ordering(matrix.shape[0]))
            except CholmodNotInstalledError:  # a CHOLMOD built without METIS: no nesdis
                self._factor = cholesky(matrix, mode="simplicial")
        else:
            self._factor.cholesky_inplace(matrix)

    def solve(self, rhs: np.ndarray) -> np.ndarray:
        """Solution of ``K x = rhs`` for an (n,) or (n, k) right-hand side."""
        if self.backend == "scipy":
            return self._factor.solve(np.asarray(rhs, dtype=np.float64))
        return self._factor(rhs)
