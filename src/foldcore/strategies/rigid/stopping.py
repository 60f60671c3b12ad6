"""The rigid-body engine's stopping rule: when a step ends a run, when steps stall.

A step's length alone is met by a stall (a sheet creeping out of flat in tiny
steps), so a run ends only after an accepted, nearly undamped step that
leaves a small distance (the step's length, or a bound from the steps'
contraction, Deuflhard, "Newton Methods for Nonlinear Problems", 2004, §2.1)
*and* lowers the energy by ≤ tolerance × E. Where the energy vanishes
(compatible targets) its decrease is rounding noise, hence a floor. Why each
part: `docs/architecture.md#the-rigid-body-stopping-rule`. Units: mm, mm⁵.
"""
from __future__ import annotations

import numpy as np

from .residual import ROUNDING


class StoppingRule:
    """The verdict on an engine's last step (:class:`.step.LevenbergMarquardt`).

    Parameters
    ----------
    engine : RigidBodySolver
    options : RigidOptions

    Attributes
    ----------
    distance : float
        Estimated distance left after the last step, mm.
    energy_scale : float
        The run's largest energy so far, mm⁵ (the scale of its energy floor).
    """

    def __init__(self, engine, options):
        self.engine, self.options = engine, options
        self.distance = np.inf
        self.energy_scale = 0.0

    def new_run(self) -> None:
        self.energy_scale = 0.0

    def observe(self, energy: float) -> None:
        """A step started at ``energy`` mm⁵."""
        self.energy_scale = max(self.energy_scale, energy)

    def _quiet(self) -> bool:
        """Whether the last step's damping was neither large nor the main part of the
        decrease its model predicted (a step held back by λ says nothing)."""
        lm, o = self.engine.lm, self.options
        return lm.step_lam <= o.lambda_settled and lm.damped_share <= o.damped_share_max

    def settled(self, moved: float, tolerance: float) -> bool:
        """Whether the last step (of largest move ``moved`` mm) ends a run at relative
        ``tolerance``: accepted, the distance it leaves ≤ tolerance × size, the energy
        lowered by ≤ tolerance × E (or left no more than that), the damping quiet.
        A rejected step ends a run only at the energy's rounding floor, where no
        damping finds a descent, or where an undamped step within the limit changed
        E by ≤ tolerance × E."""
        lm = self.engine.lm
        limit = tolerance * self.engine.model.length_scale
        floor = tolerance ** 2 * self.energy_scale + self.engine.residual.rounding_energy()
        if lm.accepted:  # a step damped to a crawl says nothing: λ must be small
            quiet = self._quiet()
            energy_limit = tolerance * lm.energy + floor
            if self.distance_left(moved, limit, energy_limit if quiet else None) > limit:
                return False
            left = lm.energy_after  # ≥ any later decrease
            return bool(min(lm.decrease, left) <= energy_limit and quiet)
        if self.distance_left(moved, limit) > limit:
            return False
        quiet = self._quiet()
        return bool(lm.energy <= floor or -lm.decrease <= ROUNDING * lm.energy
                    or lm.step_lam >= self.options.lambda_max
                    or (quiet and -lm.decrease <= tolerance * lm.energy + floor))

    def stalls(self, moved: float, relative: float) -> bool:
        """Whether the last step, of largest move ``moved`` mm ≤ ``relative`` × the
        size, was rejected with its energy within rounding of the start's (or at the
        rounding floor), or was accepted and did not contract (where the steps
        still shrink steadily the run is converging, however small they are)."""
        lm = self.engine.lm
        size = self.engine.model.length_scale
        if moved > relative * size:
            return False
        if not lm.accepted:  # neither lower nor closer (closer_within_rounding)
            return bool(-lm.decrease <= ROUNDING * lm.energy
                        or lm.energy <= self.engine.residual.rounding_energy())
        contracting = moved > ROUNDING * size and (lm.contraction < 1.0 or lm.jumped
                                                   or lm.follows_jump)
        return not contracting

    def distance_left(self, moved: float, limit: float, energy_limit=None) -> float:
        """Estimated distance (mm) from the state after the last step to the
        equilibrium, for a run whose limit is ``limit`` mm; stored as
        :attr:`distance`. ``energy_limit`` (mm⁵; None: no correction is tried): the
        largest energy decrease, or energy, that ends the run.

        After two accepted steps contracting by Θ ≤ ``contraction_max`` the steps to
        come sum to ≤ Θ/(1 − Θ) × the last one's. After a first accepted step within
        ``chord_from`` × the limit the simplified correction is tried, and applied
        only when it ends the run. Otherwise the step's own length. Once an
        extrapolation saw a slow mode (ratio r) the bound uses max(r, Θ)."""
        lm, o = self.engine.lm, self.options
        self.distance = moved
        theta = lm.contraction
        if lm.accepted and lm.slow_ratio > 0.0:  # a slow mode was seen: its rate bounds
            theta = max(lm.slow_ratio, theta if theta < 1.0 else 0.0)
            self.distance = moved * theta / (1.0 - theta)
        elif lm.accepted and theta <= o.contraction_max:
            self.distance = moved * theta / (1.0 - theta)
        elif lm.accepted and energy_limit is not None and limit < moved <= o.chord_from * limit:
            self._try_correction(moved, limit, energy_limit)
        return self.distance

    def _try_correction(self, moved: float, limit: float, energy_limit: float) -> None:
        """Apply the simplified correction where it contracts, lowers the energy and
        ends the run (its bound becomes :attr:`distance`); else restore the shapes."""
        engine, lm = self.engine, self.engine.lm
        trial, energy, length = self.simplified_correction()
        theta = length / moved
        left = length * theta / (1.0 - theta) if theta < 1.0 else np.inf
        if (energy <= lm.energy_after and theta <= self.options.contraction_max
                and left <= limit and min(lm.energy - energy, energy) <= energy_limit):
            engine.set_state(trial)
            lm.decrease, lm.energy_after = lm.energy - energy, energy
            self.distance = left
        else:
            engine.residual.update_shapes(engine.phi)  # the kept state's shapes

    def simplified_correction(self):
        """(state, energy mm⁵, largest vertex move mm) of the simplified correction
        v̄ = −(JᵀJ + λD)⁻¹ ∇E/2 at the current state (the last step's factorisation,
        the gradient here: one more solve); not applied. The shapes are left at
        the correction's angles."""
        engine = self.engine
        state = engine.state()
        gradient = engine.residual.gradient(state, engine.residual.residuals(state))
        v = engine.lm.solve(-gradient)
        trial = engine.kinematics.apply(state, v, engine.lo, engine.hi)
        energy = engine.residual.trial_energy(trial)
        return trial, energy, float(np.abs(trial.x - state.x).max())
