"""Whether a state is the model's equilibrium: the certificate a run passes to converge.

A strategy's own test (the rigid-body stopping rule, ``newton``'s contraction,
the equilibrium probe of the local/global maps) judges the state by the
strategy's steps or by a model of its own (rigid panels, a coarse twin); none
of them is what a re-run would find. So before a run ends ``converged`` the
convergence test asks this certificate, which measures the state with the
model's own Gauss–Newton linearisation (:mod:`foldcore.model.linearisation`)
— every element of the mesh, whatever moved it
(`docs/architecture.md#the-equilibrium-certificate`):

1. ½∇E = K x − b(x) and H = K ⊗ I₃ − Σ w Q Qᵀ at the state (scratch
   projections: the model is left as it was).
2. The Levenberg–Marquardt step δ = −(H + λD)⁻¹ ½∇E, D the diagonal of K ⊗ I₃,
   without the sheet's rigid motion, from λ = ``DAMPING[0]`` (nearly undamped).
3. Its predicted move |δ|∞ within the run's limit (tolerance × size):
   certified. Else E at x + δ decides: lower than E by more than its rounding,
   the equilibrium is farther than the limit — refused; higher (the linear
   model overshot), λ grows by ``DAMPING_UP`` and the step is solved again, up
   to ``DAMPING[1]``. Within E's rounding: the first, nearly undamped step
   lands on a state E cannot tell from this one (the tolerance is below what
   the state resolves: refused); a damped one after an overshoot is no
   evidence of a lower state (damped further).

Scale-free: the move is compared with tolerance × size, energy changes with
E's rounding at the state, λ is relative to K's diagonal; the same state in mm
and in µm gets the same answer. Its resolution is the rounding of ½∇E through
H (about 1e-11 × the size on a thick waterbomb, 3e-10 on a thick Miura driven
flat): a tolerance below it cannot be certified. Cost: one assembly of H, one
factorisation and one energy per trial (one trial at most states, a few where
H is soft in directions E is not), at the end of a run only; K's factor is not
needed and H's is freed after.
"""
from __future__ import annotations

import time

import numpy as np

from .linsolve import not_positive_definite
from .model.linearisation import Linearisation, without_rigid_motion

DAMPING = (1e-12, 1e4)  # first and last λ of the trials, relative to K's diagonal
DAMPING_UP = 100.0  # λ's growth after a trial that raised the energy
ROUNDING = 64 * np.finfo(float).eps  # energy change (share of the state's) that is rounding


class Certificate:
    """The certificate of one model (module docstring).

    Parameters
    ----------
    model : foldcore.model.Model

    Attributes
    ----------
    residual : float
        The last check's predicted move / the pattern's size (NaN before any).
    trials : list of (float, float, float)
        The last check's trials: λ, predicted move / limit, energy change / the
        rounding noise (NaN where the move was within the limit).
    checks, seconds : int, float
        Checks so far and their time, s.
    """

    def __init__(self, model):
        self.model = model
        self.residual, self.trials = np.nan, []
        self.checks, self.seconds = 0, 0.0

    def check(self, limit: float) -> bool:
        """Whether the model's state is its equilibrium within ``limit`` mm (tolerance ×
        size). Sets :attr:`residual`."""
        model = self.model
        start = time.perf_counter()
        targets = model.slot_targets.copy()
        linear = Linearisation(model)
        try:
            with model.scratch_projections():
                move, passed = self._trials(linear, limit)
        finally:
            model.slot_targets[:] = targets
            linear.release()
            self.checks += 1
            self.seconds += time.perf_counter() - start
        self.residual = move / model.length_scale
        return passed

    def _trials(self, linear, limit: float) -> tuple[float, bool]:
        """(predicted move mm of the deciding trial, certified) — steps 1–3."""
        model, x = self.model, self.model.x
        energy, rhs = model.local_step(x)
        gradient = linear.gradient(x, rhs)
        values = linear.hessian(model.slot_targets)
        floor = self.energy_floor()  # E's rounding at this state: residuals rounded
        noise = ROUNDING * energy + 2.0 * np.sqrt(energy * floor) + floor  # by ROUNDING × size
        damping, move, self.trials = DAMPING[0], np.inf, []
        while damping <= DAMPING[1]:
            try:
                delta = linear.solve(values, -gradient, damping).reshape(-1, 3)
            except not_positive_definite():  # rounding at a tiny λ: damp more
                damping *= DAMPING_UP
                continue
            if not model.position_targets:  # the sheet's rigid motion changes nothing
                delta = without_rigid_motion(delta, x)
            move = float(np.abs(delta).max())
            share = move / limit if limit > 0 else np.inf
            if move <= limit:
                self.trials.append((damping, share, np.nan))
                return move, True
            change = (model.local_step(x + delta)[0] - energy) / noise
            self.trials.append((damping, share, change))
            if change < -1.0 or (abs(change) <= 1.0 and len(self.trials) == 1):
                return move, False  # a lower state, or the Newton step E cannot judge
            damping *= DAMPING_UP  # the linear model overshot: a shorter step
        return move, False

    def energy_floor(self) -> float:
        """mm⁵: the energy of residuals at rounding level (every vertex off by
        ``ROUNDING`` × its coordinates' magnitude: the size, or the thickness of a
        block thicker than its pattern is wide), below which changes are noise even
        where E is 0."""
        model = self.model
        reach = max(model.length_scale, float(np.abs(model.x).max(initial=0.0)))
        return model.system.reference_weight * model.mesh.n_vertices * (ROUNDING * reach) ** 2

