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

Cost per step: one assembly of H into a fixed pattern (:class:`~foldcore.model.linearisation.HessianPattern`)
and one sparse Cholesky per trial (CHOLMOD refactors in place, else SciPy),
plus 1 + ``corrections`` local steps and K solves per trial (the accepted
trial's projections serve the next step). Units: mm.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import SimulationError
from ..model.linearisation import Linearisation, without_rigid_motion
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
        self.stuck = False  # whether the last step found no damping that lowers E
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
        self.linear = Linearisation(model)  # H in its fixed pattern, and its factor

    def restart(self) -> None:
        self.lam, self.moves, self.energy_max, self.level = self.options.lambda_start, [], 0.0, 0
        self._at, self.stuck = None, False

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
                delta = without_rigid_motion(delta, x)
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
                self.stuck = False
                self.lam = max(self.lam / o.lambda_down, o.lambda_min)
                break
            self.lam *= o.lambda_up
            if self.lam > o.lambda_max:  # no decrease at any damping: not a verdict
                self.accepted, self.lam, self.stuck = False, o.lambda_start, True
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
        and go on (`docs/architecture.md#newton`). Also a step that no damping made
        lower E (with K unchanged the next one would be the same, each up to ~25
        factorisations): the convergence test then certifies the state or calls
        it stalled."""
        if self.stuck and not self.model.pins.fading():
            return True
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
        :class:`~foldcore.model.linearisation.HessianPattern` (built anew when K
        changes or a contact block joins)."""
        if touch is None:
            return self.linear.hessian(targets)
        runs, values = self.contact.blocks(touch)
        return self.linear.hessian(targets, runs, values, self.contact.version)

    @property
    def hessian_pattern(self):
        """The :class:`~foldcore.model.linearisation.HessianPattern` of the last
        :meth:`hessian` (None before)."""
        return self.linear.pattern

    def _solve(self, values: np.ndarray, rhs: np.ndarray) -> np.ndarray:
        """(H + λ D)⁻¹ rhs, D the diagonal of K ⊗ I₃ (:meth:`Linearisation.solve`)."""
        return self.linear.solve(values, rhs, self.lam)

    def rotation_bases(self, all_targets: np.ndarray):
        """:meth:`Linearisation.rotation_bases` of the model."""
        return self.linear.rotation_bases(all_targets)
