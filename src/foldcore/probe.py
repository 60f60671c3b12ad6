"""Whether a local/global state is the paper model's equilibrium: the probe.

The paper's map, L-BFGS and Anderson move a long panel only through its thin
hinge faces, so far from the fold their steps can be far below tolerance ×
size while the panels still turn: a small step is not a verdict. The probe
runs when a step is within the limit, in three parts
(`docs/architecture.md#the-equilibrium-probe`):

1. *Probe*: ``PROBE_STEPS`` plain steps of the map on scratch copies (the
   model's state is untouched); near a fixed point the map is linear, so once
   its fast modes have died out its steps shrink by the slowest mode's ratio
   ρ, and the distance still to go is the probe's net move plus the geometric
   tail ‖s_last‖ ρ / (1 − ρ). It must be within the limit; ρ ≥ 1 sees none.
2. *Rounding floor*: where the probe's last steps are below ``ROUNDING`` ×
   size no rate is resolved; the run must then have lowered its energy to
   ``ENERGY_LEFT`` of its largest.
3. *Hold*: the strategy's own next ``HOLD`` iterations (a tenth of the stage,
   if more) must not creep: their drift, extrapolated over as many iterations
   as the stage had taken, must stay within the limit.

Scale-free (ratios of lengths and energies): the same scene in mm, m and µm
gets the same verdict. Cost: ``PROBE_STEPS`` local steps and solves per probe;
after a failed check the next waits as many iterations as the stage has taken.
"""
from __future__ import annotations

import numpy as np

PROBE_STEPS = 60  # plain map steps per check (fast modes fall by ≈ 0.55 per step, measured)
ROUNDING = 3e-14  # relative step at which the probe's rate is rounding noise (measured 1e-14)
RESOLUTION = 1e-12  # relative distance the probe resolves (its net move at rounding: 1e-13)
ENERGY_LEFT = 0.5  # at the rounding floor: the run must have lowered E to this share of its largest
HOLD = 10  # strategy iterations at least over which a passed probe's state must not creep
RATE_WINDOW = 15  # probe steps per window of the rate estimate (the last two windows)


class EquilibriumProbe:
    """The probe of one model (module docstring).

    Parameters
    ----------
    model : foldcore.model.Model
        Its positions, local and global step are probed.
    progress : foldcore.convergence.Progress
        The run's iteration count and energies.

    Attributes
    ----------
    residual : float
        Last estimated distance to the equilibrium / the pattern size
        (dimensionless; NaN before the first check of the stage).
    rate : float
        The slowest mode's ratio per plain step seen by the last probe.
    failed : bool
        Whether the stage's last check found the equilibrium not reached.
    """

    def __init__(self, model, progress):
        self.model, self.progress = model, progress
        self._run_start = self._targets_set = progress.iterations
        self.new_run()

    def begin_run(self) -> None:
        """A run starts (its stages each call :meth:`new_run`)."""
        self._run_start = self.progress.iterations

    def targets_changed(self) -> None:
        """The fold targets (or K) changed: energies before now belong to another
        problem."""
        self._targets_set = self.progress.iterations

    def new_run(self) -> None:
        """A stage starts: no check yet, the first one is due at once."""
        self.residual, self.rate, self.failed = np.nan, np.nan, False
        self._start = self.progress.iterations
        self._next = self.progress.iterations
        self._anchor = None  # (hold's end, positions, iteration) where the last probe passed

    def settled(self, moved: float, limit: float) -> bool:
        """Whether a run may stop after a step of ``moved`` mm (limit: tolerance × size,
        mm): the step is within the limit, a probe found the equilibrium within it,
        and the strategy's own iterations stayed within it since, for ``HOLD`` of
        them (or a tenth of the stage, if more)."""
        model, iterations = self.model, self.progress.iterations
        if not moved <= limit:
            return False
        if self._anchor is not None:
            return self._held(limit)
        if iterations < self._next:
            return False
        self.residual, self.rate, resolved = self.probe()
        relative = max(limit / model.length_scale, RESOLUTION)
        self.failed = not (self.residual <= relative
                           and (resolved or self._energy_fell(relative)))
        if self.failed:
            self._probe_later()
        else:
            hold = max(HOLD, (iterations - self._start) // 10)
            self._anchor = (iterations + hold, model.x.copy(), iterations)
        return False

    def _held(self, limit: float) -> bool:
        """At the end of the hold: whether the positions' drift since the probe passed,
        extrapolated at its rate over as many iterations as the stage had taken by
        then, is within ``limit`` mm."""
        model, iterations = self.model, self.progress.iterations
        due, anchor, started = self._anchor
        if iterations < due:
            return False
        drift = float(np.abs(model.x - anchor).max())
        if drift > RESOLUTION * model.length_scale:  # rounding noise is not extrapolated
            drift *= max(1.0, (started - self._start) / (iterations - started))
        self._anchor = None
        self.residual = max(self.residual, drift / model.length_scale)
        self.failed = not drift <= max(limit, RESOLUTION * model.length_scale)
        if self.failed:
            self._probe_later()
        return not self.failed

    def refuse(self, residual: float) -> None:
        """The equilibrium certificate refused a state this probe passed: the check
        failed, with the certificate's estimate (``residual``, / size) if larger,
        and the next probe waits (:meth:`_probe_later`)."""
        if not self.residual >= residual:  # (NaN before any probe of the stage)
            self.residual = residual
        self.failed, self._anchor = True, None
        self._probe_later()

    def _probe_later(self) -> None:
        """After a failed check: the next probe waits as many iterations as the stage
        has taken, at least ``PROBE_STEPS``."""
        iterations = self.progress.iterations
        self._next = iterations + max(PROBE_STEPS, iterations - self._start)

    def _energy_fell(self, relative: float) -> bool:
        """Whether the energy fell to ``ENERGY_LEFT`` of its largest, or to
        ``relative`` × it, since the run began or the targets were last set,
        whichever is earlier (a second stage may start at the equilibrium)."""
        energies = self.progress.energies[min(self._run_start, self._targets_set):]
        if not energies:
            return False
        return energies[-1] <= max(ENERGY_LEFT, relative) * max(energies)

    def hopeless(self, limit: float, budget: int) -> bool:
        """After a failed check: whether the plain map, at the probe's rate, needs more
        than ``budget`` further steps to come within ``limit`` mm."""
        if not self.failed:
            return False
        if not self.rate < 1.0:
            return True
        distance = self.residual * self.model.length_scale
        needed = np.log(limit / distance) / np.log(self.rate)
        return bool(needed > budget)

    def probe(self) -> tuple[float, float, bool]:
        """(estimated distance to the equilibrium / size, slowest ratio, whether it was
        resolved) from ``PROBE_STEPS`` plain steps at the current positions; the
        model's state is left as it was."""
        model = self.model
        x, steps = model.x, []
        with model.scratch_projections():
            for _ in range(PROBE_STEPS):
                _, rhs = model.local_step(x)
                new_x = model.global_step(rhs)
                steps.append(float(np.abs(new_x - x).max()))
                x = new_x
        size = model.length_scale
        return self._estimate(float(np.abs(x - model.x).max()) / size, np.array(steps) / size)

    @staticmethod
    def _estimate(travelled: float, steps: np.ndarray) -> tuple[float, float, bool]:
        """Distance the probe moved + geometric tail, relative; the slowest ratio per
        step; whether that ratio was resolved (the last steps above the rounding
        floor). ``travelled``: the probe's net move / size; ``steps``: each step's
        largest move / size. The ratio compares the smallest step of the last
        ``RATE_WINDOW`` steps with that of the window before (a rounding spike only
        ever enlarges a step)."""
        w = RATE_WINDOW
        early, late = steps[-2 * w:-w].min(), steps[-w:].min()
        rate = (late / early) ** (1.0 / w) if early > 0 else 0.0
        if late <= ROUNDING:
            tail = 0.0  # at the rounding floor no rate can be resolved
        elif rate < 1.0:
            tail = late * rate / (1.0 - rate)
        else:
            tail = np.inf
        return float(travelled + tail), float(rate), bool(late > ROUNDING)
