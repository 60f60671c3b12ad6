"""Sparse factorisation: both orderings and both backends solve K x = b.

Matrix: the 5-point Laplacian of an m × m grid plus 1e-3·I (SPD, sheet-like
like K), at sizes on both sides of ``NESTED_DISSECTION_FROM``. A direct solve
of a matrix with condition number ~1e4 leaves a relative residual of a few
ε·cond at most: bound 1e-10.
"""
from __future__ import annotations

import numpy as np
import pytest
import scipy.sparse as sp

from foldcore.linsolve import (NESTED_DISSECTION_FROM, Factor, cholmod_available,
                               cholmod_ordering)

RESIDUAL = 1e-10


def grid_laplacian(m: int, shift: float = 1e-3) -> sp.csc_matrix:
    one = sp.diags([-np.ones(m - 1), 2 * np.ones(m), -np.ones(m - 1)], [-1, 0, 1])
    eye = sp.identity(m)
    return (sp.kron(one, eye) + sp.kron(eye, one) + shift * sp.identity(m * m)).tocsc()


def relative_residual(matrix, x, b) -> float:
    return float(np.abs(matrix @ x - b).max() / np.abs(b).max())


def test_ordering_switches_to_nested_dissection_at_the_threshold():
    assert cholmod_ordering(NESTED_DISSECTION_FROM - 1) == "default"
    assert cholmod_ordering(NESTED_DISSECTION_FROM) == "nesdis"


# 900 rows (CHOLMOD's default ordering), 57 600 rows (nested dissection), SuperLU
@pytest.mark.parametrize("backend, m", [("cholmod", 30), ("cholmod", 240), ("scipy", 30)])
def test_factor_solves_and_refactors(backend, m):
    if backend == "cholmod" and not cholmod_available():
        pytest.skip("scikit-sparse not installed")
    matrix = grid_laplacian(m)
    b = np.asfortranarray(np.random.default_rng(0).normal(size=(m * m, 3)))
    factor = Factor(matrix, backend)
    assert relative_residual(matrix, factor.solve(b), b) < RESIDUAL
    stiffer = (matrix + sp.diags(np.linspace(0.0, 1.0, m * m))).tocsc()  # same pattern
    factor.refactor(stiffer)
    assert relative_residual(stiffer, factor.solve(b), b) < RESIDUAL


@pytest.mark.parametrize("backend", ["cholmod", "scipy"])
def test_lower_triangle_alone_solves_as_the_full_matrix(backend):
    """The rigid-body step stores only JᵀJ's lower triangle (stored="lower")."""
    if backend == "cholmod" and not cholmod_available():
        pytest.skip("scikit-sparse not installed")
    m = 30
    matrix = (grid_laplacian(m) + sp.diags(np.linspace(0.0, 1.0, m * m))).tocsc()
    b = np.random.default_rng(2).normal(size=(m * m, 3))
    factor = Factor(sp.tril(matrix).tocsc(), backend, stored="lower")
    assert relative_residual(matrix, factor.solve(b), b) < RESIDUAL
    factor.refactor(sp.tril(2.0 * matrix).tocsc())
    assert relative_residual(2.0 * matrix, factor.solve(b), b) < RESIDUAL


def test_unknown_storage_is_refused():
    with pytest.raises(ValueError, match="unknown matrix storage"):
        Factor(grid_laplacian(3), "scipy", stored="upper")


def test_large_factor_is_ordered_by_nested_dissection():
    if not cholmod_available():
        pytest.skip("scikit-sparse not installed")
    from sksparse.cholmod import analyze

    matrix = grid_laplacian(240)
    assert matrix.shape[0] >= NESTED_DISSECTION_FROM
    used = Factor(matrix, "cholmod")._factor.P()
    assert np.array_equal(used, analyze(matrix, ordering_method="nesdis").P())
    assert not np.array_equal(used, analyze(matrix, ordering_method="default").P())


def test_cholmod_without_metis_falls_back_to_its_default_ordering(monkeypatch):
    """A CHOLMOD built without its partition module raises CholmodNotInstalledError
    for nesdis: the factorisation must still happen, with the default ordering."""
    if not cholmod_available():
        pytest.skip("scikit-sparse not installed")
    import sksparse.cholmod as cholmod

    real = cholmod.cholesky
    asked = []

    def without_metis(matrix, *args, ordering_method="default", **kwargs):
        asked.append(ordering_method)
        if ordering_method == "nesdis":
            raise cholmod.CholmodNotInstalledError("no partition module")
        return real(matrix, *args, ordering_method=ordering_method, **kwargs)

    monkeypatch.setattr(cholmod, "cholesky", without_metis)
    matrix = grid_laplacian(240)
    b = np.random.default_rng(1).normal(size=(matrix.shape[0], 3))
    factor = Factor(matrix, "cholmod")
    assert asked == ["nesdis", "default"]
    assert relative_residual(matrix, factor.solve(b), b) < RESIDUAL
