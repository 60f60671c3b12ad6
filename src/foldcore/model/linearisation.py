"""The Gauss–Newton linearisation of the model's energy, for whatever solves with it.

The energy is the paper's, E(x) = Σ_e w_e ‖C x_e − P_e(x)‖² (+ pins), P_e the
element's projection: its target shape, best rotated (:mod:`elements`). Since
P_e minimises the misfit, ½∇E = K x − b(x) (the envelope theorem). Gauss–Newton
keeps the first-order change of the projections and drops their curvature:
P_e moves along its rotations, δP = ω × p, so with Q_e (3m × 3) an orthonormal
basis of those motions at P_e, ½∇²E ≈ H = K ⊗ I₃ − Σ_e w_e Q_e Q_eᵀ (each
element's term w_e (C − Q_e Q_eᵀ) a projector: H is positive semi-definite,
singular along rigid motions of the whole sheet). A slack strip's length
follows x too (:mod:`foldcore.hinges`): one more column of Q_e, the target's
change per mm of length. A passive strip's freedom to bend toward x (its Eq.
9 angle) is left out, which overestimates its stiffness.

Two users: the ``newton`` strategy steps with it, and the verdict's
equilibrium certificate (:mod:`foldcore.certificate`) measures with it how
far a state is from the model's equilibrium
(`docs/architecture.md#the-equilibrium-certificate`). Units: mm, mm⁴ (½∇E),
mm³ (H).
"""
from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from elements import bending_hinge
from elements.bending_hinge import MODEL, SLACK

from ..errors import SimulationError
from ..linsolve import Factor


class Linearisation:
    """H of one model at given projections, in a fixed pattern, and its factor.

    Parameters
    ----------
    model : foldcore.model.Model
    """

    def __init__(self, model):
        self.model = model
        self.pattern = None  # HessianPattern of the current K (and extra blocks)
        self._factor = None  # Factor of H + λ D, refactored in place while the pattern holds

    def gradient(self, x: np.ndarray, rhs: np.ndarray) -> np.ndarray:
        """(3N,) ½∇E = K x − b(x) at ``x`` (N, 3) mm from b(x) = ``rhs``, mm⁴."""
        return (self.model.system.apply(x) - rhs).ravel()

    def hessian(self, targets: np.ndarray, extra_ids=(), extra_blocks=(),
                version: int = 0) -> np.ndarray:
        """Values of H = K ⊗ I₃ − Σ w Q Qᵀ (+ ``extra_blocks``, (n, 3m, 3m) each over the
        vertex ids ``extra_ids``, (n, m) each) at the projections ``targets`` (nnz, 3)
        mm, in the fixed pattern of :class:`HessianPattern`, built anew when K
        changes or ``version`` (what the extra blocks' pattern is) does."""
        system = self.model.system
        bases = list(self.rotation_bases(targets))
        ids = [ids for ids, _, _ in bases] + list(extra_ids)
        blocks = [-weights[:, None, None] * np.matmul(basis, basis.transpose(0, 2, 1))
                  for _, weights, basis in bases] + list(extra_blocks)
        key = (system.version, version)
        if self.pattern is None or self.pattern.version != key:
            self.pattern = HessianPattern(system, ids, key)
            self._factor = None
        return self.pattern.values(blocks)

    def solve(self, values: np.ndarray, rhs: np.ndarray, damping: float) -> np.ndarray:
        """(H + ``damping`` D)⁻¹ rhs, D the diagonal of K ⊗ I₃; the factor keeps its
        symbolic analysis while the pattern stays (CHOLMOD ``cholesky_inplace``)."""
        matrix = self.pattern.matrix(values, damping)
        if self._factor is None:
            self._factor = Factor(matrix, self.model.system.backend, stored="lower")
        else:
            self._factor.refactor(matrix)
        return self._factor.solve(rhs)

    def release(self) -> None:
        """Free the pattern and the factor (built again at the next use)."""
        self.pattern, self._factor = None, None

    def rotation_bases(self, all_targets: np.ndarray):
        """Per group and element size m: vertex ids (n, m), weights (n,) and an
        orthonormal basis (n, 3m, 3) of the rotations of each element's projection
        (``all_targets``: every group's slot targets, mm)."""
        model = self.model
        for state, weights in zip(model.groups, model.system.weights):
            group = state.group
            sizes = np.diff(group.indptr)
            targets = all_targets[state.slots]
            slack = slack_directions(model.x, state) if state is model.hinges else None
            for m in np.unique(sizes):
                sel = np.flatnonzero(sizes == m)
                slots = group.indptr[sel][:, None] + np.arange(m)
                p = targets[slots]
                p = p - p.mean(axis=1, keepdims=True)
                zero = np.zeros_like(p[..., 0])
                turns = np.stack([np.stack([zero, -p[..., 2], p[..., 1]], axis=2),
                                  np.stack([p[..., 2], zero, -p[..., 0]], axis=2),
                                  np.stack([-p[..., 1], p[..., 0], zero], axis=2)], axis=3)
                basis, _ = np.linalg.qr(turns.reshape(len(sel), 3 * int(m), 3))
                if slack is not None:
                    basis = with_direction(basis, slack[slots].reshape(len(sel), -1))
                yield group.indices[slots], weights[sel], basis


def slack_directions(x: np.ndarray, hinges):
    """(nnz, 3) how the projections of the hinge group ``hinges`` move per mm of
    their slack strips' lengths (:func:`elements.bending_hinge.slack_directions`),
    or None where no strip is a slack one."""
    params = hinges.params
    if not np.any(params[:, MODEL] == SLACK):
        return None
    group = hinges.group
    out = np.zeros((len(group.indices), 3))
    bending_hinge.slack_directions(x, group.indptr, group.indices, group.rest, params,
                                   hinges.state, out)
    return out


def with_direction(basis: np.ndarray, direction: np.ndarray) -> np.ndarray:
    """``basis`` (n, d, c) orthonormal, with ``direction`` (n, d) orthonormalised
    against it as one more column (a zero column where it is zero or in the span)."""
    direction = direction - np.einsum("nij,nj->ni", basis, np.einsum("nij,ni->nj", basis,
                                                                          direction))
    norm = np.linalg.norm(direction, axis=1, keepdims=True)
    scale = np.where(norm > 1e-9, 1.0 / np.maximum(norm, 1e-300), 0.0)
    return np.concatenate([basis, (direction * scale)[:, :, None]], axis=2)


class HessianPattern:
    """The fixed sparsity pattern of H = K ⊗ I₃ − Σ w Q Qᵀ: its lower triangle in CSC,
    and where each entry of K ⊗ I₃ and of each element's (3m × 3m) block adds in.

    Built once per K (``system.version``), so a step assembles H by one
    ``bincount`` instead of SciPy's COO → CSR → sum → CSC conversions, and the
    pattern, explicit zeros kept, is the same at every step: CHOLMOD reuses its
    symbolic analysis (about half a whole run's time saved:
    `docs/architecture.md#newton`).

    Parameters
    ----------
    system : foldcore.system.System
        Its K with the pins (``with_pins``), N × N.
    blocks : list of (n, m) int arrays
        Vertex ids of each run of elements of size m, in the order their
        values will be given to :meth:`values`.
    version : tuple, optional
        What the pattern was built for (K's version, the extra blocks' version).
    """

    def __init__(self, system, blocks, version=None):
        self.version = (system.version, 0) if version is None else version
        base = sp.kron(system.with_pins(), sp.identity(3), format="coo")
        rows, cols = [base.row], [base.col]
        for ids in blocks:
            n, m = ids.shape
            dof = (3 * ids[:, :, None] + np.arange(3)).reshape(n, 3 * m)
            rows.append(np.repeat(dof, 3 * m, axis=1).ravel())
            cols.append(np.tile(dof, (1, 3 * m)).ravel())
        rows, cols = np.concatenate(rows), np.concatenate(cols)
        lower = rows >= cols  # the entries CHOLMOD reads
        size = base.shape[0]
        keys, slot = np.unique(cols[lower].astype(np.int64) * size + rows[lower],
                               return_inverse=True)
        #: slot in the CSC data of every entry, in :meth:`values`' order; the upper
        #: triangle's go to one extra slot that is dropped (no masked copy per step)
        self.slot = np.full(len(rows), len(keys), dtype=np.int64)
        self.slot[lower] = slot
        self.indices = (keys % size).astype(np.int32)
        self.indptr = np.searchsorted(keys // size, np.arange(size + 1)).astype(np.int32)
        self.shape = (size, size)
        self.base_values = base.data
        self.scale = base.tocsr().diagonal()
        self.diagonal = self.indptr[:-1]  # the first entry of each lower column: its diagonal
        if not np.array_equal(self.indices[self.diagonal], np.arange(size)):
            raise SimulationError("a vertex without elements (K has a zero diagonal): "
                                  "no Gauss–Newton matrix")

    def values(self, blocks) -> np.ndarray:
        """(nnz,) values of H from each run's (n, 3m, 3m) blocks (order of ``blocks``)."""
        entries = np.concatenate([self.base_values] + [b.ravel() for b in blocks])
        nnz = len(self.indices)
        return np.bincount(self.slot, weights=entries, minlength=nnz + 1)[:nnz]

    def matrix(self, values: np.ndarray, damping: float):
        """Lower triangle of H + ``damping`` × D (D the diagonal of K ⊗ I₃), CSC."""
        data = values.copy()
        data[self.diagonal] += damping * self.scale
        return sp.csc_matrix((data, self.indices, self.indptr), shape=self.shape)


def without_rigid_motion(delta: np.ndarray, x: np.ndarray) -> np.ndarray:
    """``delta`` (N, 3) mm without its component along the whole sheet's rigid motions
    (translations and infinitesimal rotations ω × (x − x̄)). Without position targets
    E does not change along them (the anchor pin follows vertex 0), so H is
    singular there and a nearly undamped step moves the sheet by rounding, step
    after step at a constant E (`docs/architecture.md#newton`)."""
    arm = x - x.mean(axis=0)
    zero, one = np.zeros(len(x)), np.ones(len(x))
    modes = [np.column_stack([one, zero, zero]), np.column_stack([zero, one, zero]),
             np.column_stack([zero, zero, one]),
             np.column_stack([zero, -arm[:, 2], arm[:, 1]]),
             np.column_stack([arm[:, 2], zero, -arm[:, 0]]),
             np.column_stack([-arm[:, 1], arm[:, 0], zero])]
    basis, _ = np.linalg.qr(np.stack([m.ravel() for m in modes], axis=1))
    flat = delta.ravel()
    return (flat - basis @ (basis.T @ flat)).reshape(delta.shape)
