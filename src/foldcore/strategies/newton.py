"""``newton``: Gauss–Newton / Levenberg–Marquardt on every vertex (elastic panels).

Why: a mesh with elastic cells (``thicken(elastic=...)``) has no rigid
bodies for the ``rigid`` strategy, and the local/global strategies crawl on
it: the cells of a thin sheet are stiff in their plane and soft in bending,
so L-BFGS from K⁻¹ needs tens of thousands of iterations where this strategy
takes tens of steps (`docs/architecture.md#newton`).

The energy is the paper's, E(x) = Σ_e w_e ‖C x_e − P_e(x)‖² (+ pins), P_e the
element's projection: its target shape, best rotated (:mod:`elements`). Since
P_e minimises the misfit, ½∇E = K x − b(x) (the envelope theorem, as the
accelerated strategies use). Gauss–Newton keeps the first-order change of
the projections and drops their curvature: P_e moves along its rotations,
δP = ω × p, so with Q_e (3m × 3) an orthonormal basis of those motions at
P_e, ½∇²E ≈ H = K ⊗ I₃ − Σ_e w_e Q_e Q_eᵀ (each element's term w_e (C − Q_e Q_eᵀ)
a projector: H is positive semi-definite, singular along rigid motions of the
whole sheet). A passive strip can also bend toward x (its Eq. 9 angle); that
freedom is left out of H, which then overestimates the strip's stiffness: the
step is shorter, never wrong, since each step must lower E. A slack strip's
length follows x too (:mod:`foldcore.hinges`); that freedom is in H (one
more column of Q_e, the target's change per mm of length): left out, the
strips resist the lengthening a binding vertex needs as stiffly as bending,
and the steps crawl.

A step solves (H + λ D) δ = −(K x − b), D the diagonal of K ⊗ I₃
(Levenberg–Marquardt, damping λ relative), then takes ``corrections`` steps
of the paper's map from x + δ: a linear step turns a panel by stretching it
(O(L ω²)), and the map restores the cells' shapes. Large rotations still
cost many steps: ``hybrid`` therefore starts such a mesh on its rigid-panel
twin (:mod:`.hybrid`) and uses this strategy to finish. The step is kept if E
decreases (λ ÷ ``lambda_down``), else λ × ``lambda_up`` and it is solved again
(the fields of :class:`NewtonOptions`).

Verdict (:meth:`Newton.settled`): an accepted, nearly undamped step within
the run's limit, after an accepted step at most ``contraction_max`` times
longer, so the distance left (the geometric tail of the steps) is within the
limit too — or, on a compatible fold, E down to tolerance² of the run's
largest, where the steps are rounding.

With contact (``model.contact``) the barrier joins E, its gradient and
PSD-projected blocks join the step, and every trial is moved back until its
straight-line motion is collision-free (:mod:`.vertex_contact`).

Cost per step: one assembly of H into a fixed pattern (:class:`HessianPattern`)
and one sparse Cholesky per trial (CHOLMOD refactors in place, else SciPy),
plus 1 + ``corrections`` local steps and K solves per trial (the accepted
trial's projections serve the next step). Units: mm.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp

from elements import bending_hinge
from elements.bending_hinge import MODEL, SLACK

from ..errors import SimulationError
from ..linsolve import Factor
from .base import Strategy
from .vertex_contact import VertexContact

ROUNDING = 64 * np.finfo(float).eps  # energy change (share of the run's largest) that is noise
SUPPORTED = {"rigid_panel", "bending_hinge"}  # groups whose projections turn a fixed shape


@dataclass(frozen=True)
class NewtonOptions:
    """Options of ``newton``.

    Attributes
    ----------
    lambda_start : float
        Initial damping, relative to the diagonal of K ⊗ I₃.
    lambda_min, lambda_max : float
        Bounds of the damping.
    lambda_down, lambda_up : float
        Damping divided after an accepted step, multiplied after a rejected one.
    corrections : int
        Paper-map steps after each linear step (module docstring).
    contraction_max : float
        Largest ratio of two accepted steps' lengths that may end a run.
    stall_steps : int
        Accepted steps within rounding of E, not shrinking, that end a run stalled.
    lambda_settled : float
        Largest damping of a step that may end a run.
    """

    lambda_start: float = 1e-3
    lambda_min: float = 1e-12
    lambda_max: float = 1e12
    lambda_down: float = 3.0
    lambda_up: float = 5.0
    corrections: int = 3
    contraction_max: float = 0.5
    stall_steps: int = 30
    lambda_settled: float = 1.0


class Newton(Strategy):
    """Levenberg–Marquardt on every vertex with the Gauss–Newton Hessian of E.

    ``step()`` returns (energy at the start point, largest move in mm).
    """

    name = "newton"
    Options = NewtonOptions
    supports_contact = True

    def __init__(self, model, progress, options=None):
        super().__init__(model, progress, options)
        other = set(model.mesh.groups) - SUPPORTED
        if other:
            raise SimulationError(f"solver 'newton' takes rigid panels, elastic cells and "
                                  f"bending hinges (mesh has {sorted(other)}); use 'lbfgs'")
        self.lam = self.options.lambda_start
        self.accepted = False
        self.undamped = False  # whether the last accepted step's damping was ≤ lambda_settled
        self.moves = []  # the run's accepted step lengths, mm
        self.level = 0  # accepted steps in a row whose E changed within rounding (stalled)
        self.energy, self.energy_max = np.inf, 0.0  # after the last step; the run's largest, mm⁵
        #: mm⁵: the energy of residuals at rounding level (every vertex off by ROUNDING ×
        #: the size), below which changes are noise even where E is zero (targets met
        #: at rest: without it a fold at 0 % took 17 rejected factorisations per step)
        self.energy_floor = (model.system.reference_weight * model.mesh.n_vertices
                             * (ROUNDING * model.length_scale) ** 2)

        self._at = None  # the accepted trial's projections, reused by the next step
        self.contact = VertexContact(model) if model.contact is not None else None
        self.hessian_pattern = None  # HessianPattern of the current K (and contact blocks)
        self._factor = None  # Factor of H + λ D, refactored in place while the pattern holds

    def restart(self) -> None:
        self.lam, self.moves, self.energy_max, self.level = self.options.lambda_start, [], 0.0, 0
        self._at = None

    def begin_run(self) -> None:
        self.moves, self.energy_max, self.level = [], 0.0, 0

    def step(self) -> tuple[float, float]:
        model, o = self.model, self.options
        x = model.x
        energy, rhs, targets, touch = self._projections(x)
        self.energy_max = max(self.energy_max, energy)
        noise = ROUNDING * self.energy_max + self.energy_floor  # changes that count as none
        gradient = (model.system.apply(x) - rhs).ravel()
        if touch is not None:
            gradient = gradient + self.contact.gradient(touch)
        hessian = self.hessian(targets, touch)
        while True:
            delta = self._solve(hessian, -gradient).reshape(-1, 3)
            if not (model.position_targets or (self.contact and
                                               self.contact.holds_rigid_motion)):
                delta = _without_rigid_motion(delta, x)
            trial = self._corrected(x + delta)
            if self.contact is not None:
                trial = self.contact.collision_free(x, trial)
            if trial is x:  # no share of the step is free of contact: a shorter one may be
                trial_energy, trial_rhs, trial_touch = np.inf, None, None
            else:
                trial_energy, trial_rhs = model.local_step(trial)
                trial_touch = None if self.contact is None else self.contact.state(trial)
                if trial_touch is not None:
                    trial_energy += trial_touch.energy
            if trial_energy <= energy + noise:
                self.accepted, self.undamped = True, self.lam <= o.lambda_settled
                self.lam = max(self.lam / o.lambda_down, o.lambda_min)
                break
            self.lam *= o.lambda_up
            if self.lam > o.lambda_max:  # no decrease at any damping: not a verdict
                self.accepted, self.lam = False, o.lambda_start
                model.local_step(x)
                return energy, 0.0
        moved = float(np.abs(trial - x).max())
        self.moves.append(moved)
        self.level = self.level + 1 if abs(energy - trial_energy) <= noise else 0
        self.energy = trial_energy
        self._at = (trial, trial_energy, trial_rhs.copy(), model.slot_targets.copy(),
                    model.system.version, trial_touch)
        model.x = trial
        return energy, moved

    def _projections(self, x: np.ndarray):
        """(E, b, slot targets, contacts or None) at ``x``: kept from the step that
        accepted ``x`` while K is the same (a stop that closed there refactors it) and
        the barrier's stiffness holds, else projected anew. E includes the barrier's."""
        at, self._at = self._at, None
        kept = at is not None and at[0] is x and at[4] == self.model.system.version
        touch = None
        if self.contact is not None:  # κ may stiffen: then E is taken anew
            touch = self.contact.adapted(x, at[5] if kept else None)
            kept = kept and touch is at[5]
        if kept:
            return at[1], at[2], at[3], touch
        energy, rhs = self.model.local_step(x)
        if touch is not None:
            energy += touch.energy
        return energy, rhs, self.model.slot_targets, touch

    def settled(self, moved: float, limit: float) -> bool:
        """An accepted step, damped at most ``lambda_settled``, within ``limit`` mm,
        after a step at most ``contraction_max`` times longer (the steps' tail,
        moved·r/(1 − r) with r their ratio, is then within the limit too) or with
        E down to tolerance² of the run's largest (a compatible fold: the residuals
        are at the tolerance, the steps at rounding). A step that no damping makes
        lower E is not a verdict (the run goes on to its budget)."""
        if not (self.accepted and self.undamped) or moved > limit or len(self.moves) < 2:
            return False
        ratio = moved / max(self.moves[-2], np.finfo(float).tiny)
        tolerance = limit / self.model.length_scale
        return ratio <= self.options.contraction_max or self.energy <= tolerance ** 2 * self.energy_max

    @property
    def stalled(self) -> bool:
        """``stall_steps`` accepted steps in a row changed E by no more than rounding
        (``ROUNDING`` × the run's largest E + the floor) and the last third of them
        were no shorter than half the first third's: the steps wander at the
        resolution E can judge, where without this a binding fold at a tight
        tolerance ran its whole budget; steps that still shrink are converging
        and go on (`docs/architecture.md#newton`)."""
        steps = self.options.stall_steps
        if self.level < steps:
            return False
        third = steps // 3
        window = self.moves[-steps:]
        return max(window[-third:]) >= 0.5 * max(window[:third])

    def _corrected(self, x: np.ndarray) -> np.ndarray:
        """``x`` after ``corrections`` steps of the paper's map (projections, K solve)."""
        for _ in range(self.options.corrections):
            _, rhs = self.model.local_step(x)
            x = self.model.global_step(rhs)
        return x

    def hessian(self, targets: np.ndarray, touch=None) -> np.ndarray:
        """Values of H = K ⊗ I₃ − Σ w Q Qᵀ (+ ½∇²C of the contacts ``touch``) at the
        projections ``targets`` (nnz, 3) mm, in the fixed pattern of
        :class:`HessianPattern` (built anew when K changes or a contact block joins)."""
        system = self.model.system
        bases = list(self.rotation_bases(targets))
        ids = [ids for ids, _, _ in bases]
        blocks = [-weights[:, None, None] * np.matmul(basis, basis.transpose(0, 2, 1))
                  for _, weights, basis in bases]
        version = (system.version, 0)
        if touch is not None:
            runs, values = self.contact.blocks(touch)
            ids, blocks = ids + runs, blocks + values
            version = (system.version, self.contact.version)
        if self.hessian_pattern is None or self.hessian_pattern.version != version:
            self.hessian_pattern = HessianPattern(system, ids, version)
            self._factor = None
        return self.hessian_pattern.values(blocks)

    def _solve(self, values: np.ndarray, rhs: np.ndarray) -> np.ndarray:
        """(H + λ D)⁻¹ rhs, D the diagonal of K ⊗ I₃; the factor keeps its symbolic
        analysis while the pattern stays (CHOLMOD ``cholesky_inplace``)."""
        matrix = self.hessian_pattern.matrix(values, self.lam)
        if self._factor is None:
            self._factor = Factor(matrix, self.model.system.backend, stored="lower")
        else:
            self._factor.refactor(matrix)
        return self._factor.solve(rhs)

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
                    basis = _with_direction(basis, slack[slots].reshape(len(sel), -1))
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


def _with_direction(basis: np.ndarray, direction: np.ndarray) -> np.ndarray:
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
        What the pattern was built for (K's version, the contact blocks' count).
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
            raise SimulationError("solver 'newton': a vertex without elements (K has a zero "
                                  "diagonal)")

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


def _without_rigid_motion(delta: np.ndarray, x: np.ndarray) -> np.ndarray:
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
