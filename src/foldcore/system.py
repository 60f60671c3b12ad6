"""System: the constant matrix K = Σ w SᵀCS (+ pins) and the gather of its rhs.

With C the centring matrix of an element of m vertices,
SᵀCS = diag(1 on its vertices) − (1/m)·11ᵀ, so K = diag(Σ w) − Bᵀ diag(w/m) B
with B the element–vertex incidence matrix: assembled with two sparse products,
no per-element Python loop. The right-hand side Σ w·Sᵀ(R T) is a *gather*
through a vertex→slot CSR (each vertex sums its own slots: no races; why a
gather: `docs/architecture.md#the-element-contract-gathers-it-does-not-scatter`).
"""
from __future__ import annotations

import logging
import math
from pathlib import Path

import numpy as np
import scipy.sparse as sp
from numba import njit, prange

from elements.cache import choose_cache_dir

from .linsolve import Factor, resolved_backend

choose_cache_dir(Path(__file__))  # before this module's cache=True kernels (read-only installs)

log = logging.getLogger(__name__)

TAKE_CHUNKS = 64  # blocks of vertices :func:`take_solution` splits among threads


def element_matrix(groups, weights, n_vertices: int):
    """K = Σ_e w_e S_eᵀ C_e S_e over every group, (N, N) CSC.

    Parameters
    ----------
    groups : sequence of ElementGroup
    weights : sequence of (n_g,) float, mm³
        One weight per element of each group.
    n_vertices : int
    """
    diag = np.zeros(n_vertices)
    low_rank = sp.csr_matrix((n_vertices, n_vertices))
    for g, w in zip(groups, weights):
        sizes = np.diff(g.indptr)
        np.add.at(diag, g.indices, np.repeat(w, sizes))
        incidence = sp.csr_matrix((np.ones(len(g.indices)), g.indices, g.indptr),
                                  shape=(len(g), n_vertices))
        low_rank = low_rank + incidence.T @ sp.diags(w / sizes) @ incidence
    return (sp.diags(diag) - low_rank).tocsc()


def vertex_slots(indices: np.ndarray, n_vertices: int):
    """Transpose of the slot→vertex map: (indptr (N+1,), slots (nnz,)) CSR."""
    order = np.argsort(indices, kind="stable")
    counts = np.bincount(indices, minlength=n_vertices)
    indptr = np.zeros(n_vertices + 1, dtype=np.int64)
    np.cumsum(counts, out=indptr[1:])
    return indptr, order.astype(np.int64)


@njit(parallel=True, cache=True)
def gather(v_indptr, v_slots, slot_weight, targets, rhs):
    """rhs[v] = Σ over v's slots of weight·target (3 columns), in parallel over v."""
    for v in prange(len(v_indptr) - 1):
        a0 = a1 = a2 = 0.0
        for k in range(v_indptr[v], v_indptr[v + 1]):
            s = v_slots[k]
            w = slot_weight[s]
            a0 += w * targets[s, 0]
            a1 += w * targets[s, 1]
            a2 += w * targets[s, 2]
        rhs[v, 0] = a0
        rhs[v, 1] = a1
        rhs[v, 2] = a2


@njit(parallel=True, cache=True)
def take_solution(solution, previous, out):
    """out[:] = solution and the largest |solution − previous| (mm), in one pass.

    Parameters
    ----------
    solution : (N, 3) float, mm, any layout (CHOLMOD returns column-major)
    previous : (N, 3) float, mm
    out : (N, 3) float, C-contiguous, written

    Returns
    -------
    float
        max over vertices and axes of |solution − previous|, mm; NaN when
        ``solution`` holds a non-finite value.
    """
    n = solution.shape[0]
    chunks = min(n, TAKE_CHUNKS)
    largest = np.zeros(max(chunks, 1))
    for c in prange(chunks):
        m, finite = 0.0, True
        for v in range(c * n // chunks, (c + 1) * n // chunks):
            for d in range(3):
                value = solution[v, d]
                out[v, d] = value
                finite = finite and math.isfinite(value)
                m = max(m, abs(value - previous[v, d]))
        largest[c] = m if finite else math.nan
    result = 0.0
    for c in range(len(largest)):  # serial: a parallel max() reduction drops NaN
        if math.isnan(largest[c]):
            return math.nan
        result = max(result, largest[c])
    return result


class System:
    """The global least-squares system of one thick mesh.

    K alone is singular (free translation) and CHOLMOD may refuse it, so the
    first factorisation already pins vertex 0 with ``reference_weight`` — the
    anchor a model without position targets uses (no second factorisation
    at setup) — until :meth:`set_pin_weights` says otherwise.

    Parameters
    ----------
    groups : sequence of ElementGroup
    n_vertices : int
    backend : str
        Linear-solver backend (see :class:`foldcore.linsolve.Factor`).
    weights : sequence of (n_g,) float, optional
        Element weights to factor K with first, mm³ (default: the groups' own;
        the model passes its actuation's and stops' weights, so the first
        factorisation is already the one it needs).

    Attributes
    ----------
    reference_weight : float
        Mean diagonal of K at the groups' own weights, Σ_e w_e (m_e − 1) / N
        (mm³; m_e vertices per element): the scale that makes pin weights
        dimensionless.
    weights : list of (n_g,) float
        Current element weights of each group, mm³.
    backend : str
        ``"cholmod"`` or ``"scipy"``: the backend the factor uses (resolved from
        ``auto`` at construction, before any factorisation).
    version : int
        Number of refactorisations since construction: a change tells an
        accelerated strategy that K changed and its history is stale.
    """

    def __init__(self, groups, n_vertices: int, backend: str = "auto", weights=None):
        self.n_vertices = n_vertices
        self.groups = list(groups)
        self.reference_weight = sum(float(g.weights @ (np.diff(g.indptr) - 1))
                                    for g in self.groups) / max(n_vertices, 1)
        own = [g.weights for g in self.groups]
        self.weights = [np.array(w, dtype=float) for w in (own if weights is None else weights)]
        self._assemble()
        indices = np.concatenate([g.indices for g in self.groups])
        self.v_indptr, self.v_slots = vertex_slots(indices, n_vertices)
        self._pins = np.zeros(n_vertices)
        if n_vertices:  # anchor vertex 0 (K alone is singular: free translation)
            self._pins[0] = self.reference_weight
        self.version = 0
        self.backend = resolved_backend(backend)
        self._factor = None  # built at first use (the factor property)

    @property
    def factor(self) -> Factor:
        """The factorisation of K with the pins, built at its first use: the
        rigid-body strategies never solve with K, so a rigid-body fold never pays
        its memory (`docs/architecture.md#linear-solves`)."""
        if self._factor is None:
            log.debug("K factorised: %d rows (%s)", self.n_vertices, self.backend)
            self._factor = Factor(self.with_pins(), self.backend)
        return self._factor

    @property
    def factored(self) -> bool:
        """Whether K has been factorised (some step or measurement solved with it)."""
        return self._factor is not None

    @property
    def matrix(self):
        """K without the pins, (N, N) sparse, mm³: assembled at its first use (as the
        factor, and for the same reason: a rigid-body fold never needs it)."""
        if self._matrix is None:
            self._matrix = element_matrix(self.groups, self.weights, self.n_vertices)
        return self._matrix

    def _assemble(self) -> None:
        self._matrix = None  # (the matrix property) from the current weights
        self.slot_weight = np.concatenate([np.repeat(w, np.diff(g.indptr))
                                           for g, w in zip(self.groups, self.weights)])

    def set_weights(self, group: int, weights: np.ndarray) -> bool:
        """New element weights (mm³) for group ``group``; numeric refactor if changed."""
        if np.array_equal(weights, self.weights[group]):
            return False
        self.weights[group] = np.array(weights, dtype=float)
        self._assemble()
        self._refactor()
        return True

    def with_pins(self):
        """K with the pins, (N, N) CSC, mm³ (what the factor factorises)."""
        return (self.matrix + sp.diags(self._pins)).tocsc()

    def set_pin_weights(self, pins: np.ndarray) -> bool:
        """Per-vertex pin weights (mm³); numeric refactor only if they changed."""
        if np.array_equal(pins, self._pins):
            return False
        self._pins = np.array(pins, dtype=float)
        self._refactor()
        return True

    def _refactor(self) -> None:
        if self._factor is not None:  # else the first use factorises the new K
            log.debug("K refactorised: its weights or pins changed")
            self._factor.refactor(self.with_pins())
        self.version += 1

    def apply(self, x: np.ndarray) -> np.ndarray:
        """K x with the pins, (N, 3) for (N, 3) positions in mm (result in mm⁴)."""
        return self.matrix @ x + self._pins[:, None] * x

    def rhs(self, targets: np.ndarray, out: np.ndarray) -> np.ndarray:
        """Gather Σ w·(R T) per vertex from the stacked slot targets (nnz, 3) into
        ``out`` (N, 3); column-major ``out`` is what CHOLMOD reads without a copy."""
        gather(self.v_indptr, self.v_slots, self.slot_weight, targets, out)
        return out
