"""Sparse SPD factorisation behind one small interface: factor once, solve many.

Backends: ``cholmod`` (scikit-sparse, simplicial: its solves are several
times faster than supernodal ones on these sheet-like matrices) and
``scipy`` (SuperLU), the fallback when scikit-sparse is not installed.
``refactor`` reuses the symbolic analysis (CHOLMOD) when only the values
change. CHOLMOD orders by its default (AMD) below ``NESTED_DISSECTION_FROM``
rows and by nested dissection (``nesdis``, less fill on large sheets) from
there; a CHOLMOD built without METIS has no nesdis and keeps its default.
Why each choice, with the measurements: `docs/architecture.md#linear-solves`.
"""
from __future__ import annotations

import numpy as np
import scipy.sparse as sp

NESTED_DISSECTION_FROM = 50_000  # rows from which CHOLMOD orders by nested dissection


def cholmod_ordering(n_rows: int) -> str:
    """CHOLMOD ``ordering_method`` for a matrix of ``n_rows`` rows (module docstring)."""
    return "nesdis" if n_rows >= NESTED_DISSECTION_FROM else "default"


def not_positive_definite() -> tuple:
    """Exception classes a factorisation raises for a matrix that is not positive
    definite (CHOLMOD's; SciPy's LU raises RuntimeError for a singular one)."""
    try:
        from sksparse.cholmod import CholmodNotPositiveDefiniteError
    except ImportError:
        return (RuntimeError,)
    return (CholmodNotPositiveDefiniteError, RuntimeError)


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
        matrix gives the same factor from half the memory, as fast
        (`docs/architecture.md#linear-solves`). SciPy's LU needs both: it is
        mirrored there.
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
