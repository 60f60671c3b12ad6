"""The Levenberg–Marquardt step of the rigid-body engine, with geodesic acceleration.

Each step linearises the residuals in all unknowns (Gauss–Newton), solves the
damped normal equations (JᵀJ + λD) v = −Jᵀr (Marquardt scaling, angles
pressing on a bound frozen), bends the step along the curved set of
unstrained configurations with the geodesic acceleration (Transtrum &
Sethna, "Improvements to the Levenberg–Marquardt algorithm", 2012), keeps it
only if the energy decreases (or, at rounding level, if it came closer:
:meth:`LevenbergMarquardt.closer_within_rounding`), tries the end of a
geometric tail of aligned steps (:meth:`LevenbergMarquardt.extrapolated`),
and updates λ by the gain ratio (Nielsen's rule). With contact every trial
is shortened until no panel crosses another on the way to it
(:meth:`LevenbergMarquardt.collision_free`). Why each part:
`docs/architecture.md#the-rigid-body-strategy`. Units: mm, rad.
"""
from __future__ import annotations

import logging
import time

import numpy as np
import scipy.sparse as sp

from ...linsolve import Factor, not_positive_definite
from .residual import ROUNDING

log = logging.getLogger(__name__)

BOUND_TOL = 1e-12  # rad: a bounded angle this close to its bound is on it
MAX_CUTS = 30  # shortenings of one step toward a contact before it is not taken


class LevenbergMarquardt:
    """One damped Gauss–Newton step per :meth:`step` on an engine's state.

    Parameters
    ----------
    engine : RigidBodySolver
        Its state (:meth:`~.engine.RigidBodySolver.state`), angle bounds, layout,
        kinematics and residual model.
    options : RigidOptions

    Attributes
    ----------
    lam : float
        The damping of the next step (relative to diag(JᵀJ)).
    step_lam : float
        The damping of the last step.
    accepted : bool
        Whether the last step was kept.
    energy, energy_after, decrease : float
        E before the last step, after it (the kept state's), and their
        difference (< 0 when rejected), mm⁵.
    gain_ratio, damped_share : float
        The last step's actual over predicted decrease, and the damping's share
        of the predicted decrease.
    contraction : float
        The last accepted step's length over the one before (NaN: unknown).
    slow_ratio : float
        The largest ratio an extrapolation used this run (0: none).
    jumped, follows_jump : bool
        The last step / the one before was extrapolated.
    solve_time : float
        Seconds spent factorising and solving (the rest is assembly).
    """

    def __init__(self, engine, options):
        self.engine, self.options = engine, options
        self.lam = options.lambda_start
        self.step_lam = self.lam
        self.jumped = self.follows_jump = False
        self.accepted, self.energy, self.decrease = False, np.inf, np.inf
        self.energy_after = np.inf
        self.gain_ratio, self.damped_share = np.nan, 0.0
        self.contraction = np.nan
        self.previous_velocity = None  # the last accepted plain step's velocity
        self.slow_ratio = 0.0
        self.accepted_move = None  # mm, the run's last accepted step, if the last step
        self.solve_time = 0.0
        self.cut = False  # the last step was shortened toward a contact
        self.factor = None  # of JᵀJ + λD, from the first step on a layout
        self._pattern = None  # the layout's pattern version the factor was analysed for

    def new_run(self) -> None:
        """A run starts: no step history; the damping at most ``lambda_start`` (one
        saturated at the end of the last run made the new run crawl; a small one is
        kept, a path's frames reuse it)."""
        self.contraction, self.accepted_move = np.nan, None
        self.previous_velocity, self.slow_ratio = None, 0.0
        self.lam = min(self.lam, self.options.lambda_start)

    def forget(self) -> None:
        """The state was moved from outside: no step history to extrapolate from."""
        self.previous_velocity, self.slow_ratio = None, 0.0

    def solve(self, rhs: np.ndarray) -> np.ndarray:
        """(JᵀJ + λD)⁻¹ rhs with the last step's factorisation, timed."""
        t0 = time.perf_counter()
        out = self.factor.solve(rhs)
        self.solve_time += time.perf_counter() - t0
        return out

    def step(self) -> tuple[float, float]:
        """One Levenberg–Marquardt iteration with geodesic acceleration from the
        engine's state; returns (E before, mm⁵; largest vertex move of the step
        tried, mm, accepted or not)."""
        engine, o = self.engine, self.options
        residual_model, kin = engine.residual, engine.kinematics
        start = engine.state()
        self.adapt_contact(start)
        lin = residual_model.linearise(start)
        res, grad = lin.residual, lin.grad
        energy = float(res @ res) + lin.contact_energy
        t0 = time.perf_counter()
        factor = self._factor(lin.normal, grad)
        velocity = factor.solve(-grad)
        self.solve_time += time.perf_counter() - t0
        trial, velocity = self.collision_free(start, velocity)
        j_velocity = lin.apply(velocity)
        if o.geodesic_max > 0:  # geodesic acceleration (Transtrum & Sethna 2012)
            h = o.geodesic_h
            probe = kin.apply(start, h * velocity, engine.lo, engine.hi)
            res_h = residual_model.residuals(probe)
            r_vv = 2.0 / h * ((res_h - res) / h - j_velocity)
            accel = self.solve(-lin.apply_transpose(r_vv))
            if np.linalg.norm(accel) <= o.geodesic_max * np.linalg.norm(velocity):
                accelerated = kin.apply(start, velocity + 0.5 * accel, engine.lo, engine.hi)
                if self.crosses(start, accelerated) is None:
                    trial = accelerated
        moved = float(np.abs(trial.x - engine.x).max())
        new_energy = residual_model.trial_energy(trial)
        self.accepted, self.step_lam = new_energy <= energy, self.lam
        unresolved = not self.accepted and self.closer_within_rounding(
            trial, energy, new_energy, -float(grad @ velocity))
        self.accepted |= unresolved
        self._rate(unresolved, energy, new_energy, grad, velocity, j_velocity)
        jumped = False
        if self.accepted and not unresolved:
            trial, new_energy, jumped = self.extrapolated(start, velocity, trial, new_energy)
            if jumped:
                moved = float(np.abs(trial.x - engine.x).max())
        self.previous_velocity = velocity if self.accepted and not jumped else None
        self.follows_jump, self.jumped = self.jumped, jumped
        self._keep(trial, moved, jumped)
        self.update_damping()
        self.decrease = energy - new_energy  # < 0 when rejected
        self.energy = energy
        self.energy_after = new_energy if self.accepted else energy  # not E − decrease: that
        #   rounds to 0 where the step took E from 1.9e-7 to 8e-24
        return energy, moved

    def adapt_contact(self, start) -> None:
        """Stiffen the barrier where a contact holds only at a vanishing gap
        (:meth:`foldcore.contact.ContactModel.stiffen`); energies are then taken anew."""
        contact = self.engine.model.contact
        if contact is None:
            return
        if contact.stiffen(self.engine.residual.contact_state(start.x)):
            self.engine.residual.forget_contact()

    def crosses(self, start, trial) -> float | None:
        """None when the straight-line motion from ``start`` to ``trial`` brings no two
        panels into contact (always, without contact); else the collision-free
        fraction of it (< 1)."""
        contact = self.engine.model.contact
        if contact is None:
            return None
        fraction = contact.free_fraction(start.x, trial.x)
        return None if fraction >= 1.0 else fraction

    def collision_free(self, start, velocity):
        """(trial, velocity): the step ``velocity`` from ``start``, shortened until
        the straight-line motion of every vertex to the trial crosses no panel
        (IPC's CCD-bounded step; without contact the step as it is). The trial's
        rotations make the motion not quite straight, so each shortened trial is
        checked again."""
        engine = self.engine
        trial = engine.kinematics.apply(start, velocity, engine.lo, engine.hi)
        self.cut = False  # whether contact shortened this step
        for _ in range(MAX_CUTS):
            fraction = self.crosses(start, trial)
            if fraction is None:
                return trial, velocity
            self.cut = True
            velocity = velocity * fraction
            trial = engine.kinematics.apply(start, velocity, engine.lo, engine.hi)
        return engine.kinematics.apply(start, 0.0 * velocity, engine.lo, engine.hi), 0.0 * velocity

    def _rate(self, unresolved, energy, new_energy, grad, velocity, j_velocity) -> None:
        """The step's gain ratio and damped share from the model's predicted decrease
        ‖Jv‖² + 2λvᵀDv = −2 gᵀv − ‖Jv‖²."""
        model = float(j_velocity @ j_velocity)  # ‖Jv‖²
        predicted = -2.0 * float(grad @ velocity) - model
        if unresolved:  # E cannot judge the model there: λ stays
            self.gain_ratio, self.damped_share = np.nan, 1.0 - model / max(predicted, 1e-300)
        elif predicted > 0:
            self.gain_ratio = (energy - new_energy) / predicted
            self.damped_share = 1.0 - model / predicted
        else:  # ≤ 0 only by rounding: no verdict on the model
            self.gain_ratio, self.damped_share = np.nan, 0.0

    def _keep(self, trial, moved: float, jumped: bool) -> None:
        """Make an accepted trial the engine's state (and its length the contraction's
        measure); after a rejected one restore the kept angles' shapes."""
        engine = self.engine
        if self.accepted:
            engine.set_state(trial)
            last = self.accepted_move
            self.contraction = moved / last if last else np.nan
            self.accepted_move = moved
            if jumped:  # its length says nothing of the contraction: the next steps will
                self.contraction, self.accepted_move = np.nan, None
        else:
            engine.residual.update_shapes(engine.phi)  # the shapes of the kept angles
            self.contraction, self.accepted_move = np.nan, None

    def closer_within_rounding(self, trial, energy: float, new_energy: float,
                               decrement: float) -> bool:
        """Whether a trial whose energy rose by no more than rounding (``ROUNDING`` ×
        E, mm⁵) still came closer to the equilibrium: its Newton decrement
        g̃ᵀ(JᵀJ + λD)⁻¹g̃ (g̃ = Jᵀr at the trial; one solve with the step's
        factorisation) is below the start's ``decrement`` (mm⁵). The shapes must be
        the trial's. Why: at a binding equilibrium E's rounding noise hides the last
        steps' decrease, which the gradient still resolves."""
        if not new_energy - energy <= ROUNDING * energy:
            return False
        residual_model = self.engine.residual
        g = residual_model.gradient(trial, residual_model.residuals_at_shapes(trial))
        trial_decrement = float(g @ self.solve(g))
        return trial_decrement < decrement

    def extrapolated(self, start, velocity, trial, energy: float):
        """(state, energy, whether extrapolated): the accepted ``trial`` (at ``energy``),
        or the step scaled to the end of its geometric tail where that is lower.

        Where a residual is left (a binding equilibrium) Gauss–Newton converges only
        linearly: the velocities keep their direction and shrink by a steady ratio
        r, so the distance left is |v| r / (1 − r) along v. When two accepted
        velocities are aligned within ``extrapolate_cos`` and r is in
        ``extrapolate_ratio``, the state moved by v / (1 − r) (at most
        ``extrapolate_max`` v) is tried and kept only if its energy is lower. Not in
        a branch stage nor after a damped step (a sheet creeping out of flat takes
        such steps too)."""
        o, engine = self.options, self.engine
        previous = self.previous_velocity
        if (previous is None or previous.shape != velocity.shape
                or engine.progress.stage == "branch" or self.step_lam > o.lambda_settled):
            return trial, energy, False
        lengths = np.linalg.norm(velocity), np.linalg.norm(previous)
        if not lengths[0] > 0 or not lengths[1] > 0:
            return trial, energy, False
        ratio = lengths[0] / lengths[1]
        aligned = float(velocity @ previous) / (lengths[0] * lengths[1])
        low, high = o.extrapolate_ratio
        if aligned <= o.extrapolate_cos or not low <= ratio <= high:
            return trial, energy, False
        far = engine.kinematics.apply(start, min(1.0 / (1.0 - ratio), o.extrapolate_max)
                                      * velocity, engine.lo, engine.hi)
        far_energy = engine.residual.trial_energy(far) if self.crosses(start, far) is None \
            else np.inf
        if far_energy < energy:
            self.slow_ratio = max(self.slow_ratio, ratio)
            return far, far_energy, True
        engine.residual.update_shapes(trial.phi)  # the kept trial's shapes
        return trial, energy, False

    def update_damping(self) -> None:
        """Next step's λ from how well the linear model predicted the last one.

        Accepted: λ × max(1/``lambda_down``, 1 − (2ρ − 1)³), ρ the gain ratio
        (Nielsen's rule, Madsen, Nielsen & Tingleff, "Methods for non-linear least
        squares problems", 2004, §3.2); an accepted step whose predicted decrease
        rounds to ≤ 0 leaves λ. Rejected: λ × ``lambda_up``."""
        o = self.options
        if not self.accepted:
            self.lam = min(self.lam * o.lambda_up, o.lambda_max)
        elif np.isfinite(self.gain_ratio):  # accepted: ρ ≥ 0, the factor is ≤ 2
            shrink = max(1.0 / o.lambda_down, 1.0 - (2.0 * self.gain_ratio - 1.0) ** 3)
            self.lam = min(max(self.lam * shrink, o.lambda_min), o.lambda_max)

    def _factor(self, normal: np.ndarray, grad) -> Factor:
        """Factorisation of JᵀJ + λ·diag(JᵀJ) (values ``normal`` on the fixed pattern,
        damped in place), angles on a bound they press against frozen; the symbolic
        analysis is reused."""
        engine, lay = self.engine, self.engine.layout
        diag = normal[lay.diag_slot]
        diag = np.maximum(diag, 1e-12 * max(diag.max(), 1e-300))
        folds = lay.folds(engine.phi)
        g_fold = grad[lay.phi_col:]
        blocked = ((folds <= engine.lo + BOUND_TOL) & (g_fold > 0)) | \
                  ((folds >= engine.hi - BOUND_TOL) & (g_fold < 0))
        undamped = normal[lay.diag_slot].copy()
        while True:
            damping = self.lam * diag
            damping[lay.phi_col:][blocked] = 1e12 * diag[lay.phi_col:][blocked]
            normal[lay.diag_slot] = undamped + damping  # in place: the step needs no more
            try:
                return self._factorised(normal)
            except not_positive_definite():
                # rounding in a matrix whose contact terms span many decades: more damping
                if self.lam >= self.options.lambda_max:
                    raise
                log.debug("rigid: normal matrix not positive definite at λ %.3g: raised", self.lam)
                self.lam = min(self.lam * self.options.lambda_up, self.options.lambda_max)

    def _factorised(self, normal: np.ndarray) -> Factor:
        """The factor of the damped normal matrix (values on the layout's pattern)."""
        engine, lay = self.engine, self.engine.layout
        n = lay.n_unknowns
        matrix = sp.csc_matrix((normal, lay.csc_indices, lay.csc_indptr), shape=(n, n))
        if self.factor is None or self._pattern != lay.version:
            log.debug("rigid: normal matrix analysed and factorised (%d unknowns, %d entries)",
                      n, len(normal))
            self.factor = Factor(matrix, engine.backend, stored="lower")
            self._pattern = lay.version
        else:
            self.factor.refactor(matrix)
        return self.factor
