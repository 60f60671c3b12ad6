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
4. A step within the limit must still find E rising beyond the limit: H
   holds a passive strip's bend as stiff as an actuated one, so where the
   strips give, its step is far too short (a thin vertex's ``newton`` crawls
   toward an equilibrium 10³ limits away while H predicts 0.3 limit). Along
   the paper's map step −K⁻¹ ½∇E, which lets the strips follow, and along
   the run's last step, E at 1 and 2 limits decides: falling from 1 to 2 by
   more than its rounding, the equilibrium on that line is farther than the
   limit — refused, the residual the vertex of the parabola through the
   three energies (at least 2 limits).

Scale-free: the move is compared with tolerance × size, energy changes with
E's rounding at the state, λ is relative to K's diagonal; the same state in mm
and in µm gets the same answer. Its resolution is the rounding of ½∇E through
H (about 1e-11 × the size on a thick waterbomb, 3e-10 on a thick Miura driven
flat): a tolerance below it cannot be certified. Cost: one assembly of H, one
factorisation and one energy per trial (one trial at most states, a few where
H is soft in directions E is not), plus one K solve and two to four energies
for step 4, at the end of a run only; H's factor is freed after, K's (built at
the first check where no strategy has built it) is kept.
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
    probe : (float, float) or None
        The last check's E at 1 and 2 limits along the last direction step 4
        probed, minus E, / the rounding noise (None where none was probed).
    checks, seconds : int, float
        Checks so far and their time, s.
    line_seconds : float
        The share of :attr:`seconds` spent on step 4's lines, s.
    """

    def __init__(self, model):
        self.model = model
        self.residual, self.trials, self.probe = np.nan, [], None
        self.checks, self.seconds, self.line_seconds = 0, 0.0, 0.0

    def check(self, limit: float, last_step=None) -> bool:
        """Whether the model's state is its equilibrium within ``limit`` mm (tolerance ×
        size); ``last_step`` ((N, 3) mm or None) is the run's last step, a direction
        step 4 probes. Sets :attr:`residual`."""
        model = self.model
        start = time.perf_counter()
        targets = model.slot_targets.copy()
        linear = Linearisation(model)
        try:
            with model.scratch_projections():
                move, passed = self._trials(linear, limit, last_step)
        finally:
            model.slot_targets[:] = targets
            linear.release()
            self.checks += 1
            self.seconds += time.perf_counter() - start
        self.residual = move / model.length_scale
        return passed

    def _trials(self, linear, limit: float, last_step) -> tuple[float, bool]:
        """(predicted move mm of the deciding trial, certified) — steps 1–4."""
        model, x = self.model, self.model.x
        energy, rhs = model.local_step(x)
        gradient = linear.gradient(x, rhs)
        values = linear.hessian(model.slot_targets)
        floor = self.energy_floor()  # E's rounding at this state: residuals rounded
        noise = ROUNDING * energy + 2.0 * np.sqrt(energy * floor) + floor  # by ROUNDING × size
        damping, move, self.trials, self.probe = DAMPING[0], np.inf, [], None
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
                farther = self.falls_beyond(x, gradient, energy, noise, limit, last_step)
                return (move, True) if farther is None else (farther, False)
            change = (model.local_step(x + delta)[0] - energy) / noise
            self.trials.append((damping, share, change))
            if change < -1.0 or (abs(change) <= 1.0 and len(self.trials) == 1):
                return move, False  # a lower state, or the Newton step E cannot judge
            damping *= DAMPING_UP  # the linear model overshot: a shorter step
        return move, False

    def falls_beyond(self, x: np.ndarray, gradient: np.ndarray, energy: float,
                     noise: float, limit: float, last_step=None) -> float | None:
        """Step 4: where E still falls beyond ``limit`` mm along the paper's map step
        −K⁻¹ ½∇E (``gradient``: ½∇E = K x − b(x), (3N,) mm⁴) or along ``last_step``
        ((N, 3) mm, the run's last step, if given), the distance (mm) to the lowest E
        on that line; else None."""
        start = time.perf_counter()
        try:
            map_step = -self.model.global_step(gradient.reshape(-1, 3))
            farther = self._falls_along(x, map_step, energy, noise, limit)
            if farther is None and last_step is not None:
                farther = self._falls_along(x, last_step, energy, noise, limit)
            return farther
        finally:
            self.line_seconds += time.perf_counter() - start

    def _falls_along(self, x: np.ndarray, step: np.ndarray, energy: float, noise: float,
                     limit: float) -> float | None:
        """E at 1 and 2 limits along ``step`` (N, 3) mm: falling from 1 to 2 by more
        than ``noise``, the vertex of the parabola through E at 0, 1 and 2 limits (at
        least 2 limits; 2 where its curvature is within rounding), mm; else None."""
        model = self.model
        if not model.position_targets:
            step = without_rigid_motion(step, x)
        reach = float(np.abs(step).max())
        if not reach > ROUNDING * model.length_scale:  # a fixed point of the map
            return None
        near, far = (model.local_step(x + share * limit / reach * step)[0] for share in (1.0, 2.0))
        self.probe = ((near - energy) / noise, (far - energy) / noise)
        if not (near < energy and far < near - noise):
            return None
        curvature = far - 2.0 * near + energy  # E'' × limit²
        slope = (4.0 * near - 3.0 * energy - far) / 2.0  # E'(0) × limit
        lowest = -slope / curvature if curvature > noise else 2.0
        return limit * max(2.0, lowest)

    def energy_floor(self) -> float:
        """mm⁵: the energy of residuals at rounding level (every vertex off by
        ``ROUNDING`` × its coordinates' magnitude: the size, or the thickness of a
        block thicker than its pattern is wide), below which changes are noise even
        where E is 0."""
        model = self.model
        reach = max(model.length_scale, float(np.abs(model.x).max(initial=0.0)))
        return model.system.reference_weight * model.mesh.n_vertices * (ROUNDING * reach) ** 2

