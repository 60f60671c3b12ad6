"""Whether a local/global run reached its equilibrium: a small step is not a verdict.

The paper's map, L-BFGS and Anderson all move a long panel only through its
thin hinge faces. Far from the fold (a hinge 90° short), their steps can be
far below tolerance × size while the panels turn by 10⁻⁸ of the remaining
angle per step: the length-only rule called that "converged" (issue 18: a
single hinge at H / size = 10⁻⁴ stopped after 2 iterations 90° short under
``paper``, ``anderson`` and ``lbfgs``; a thin Miura 10 × 10 from flat under
``lbfgs`` 60° short).

:class:`EquilibriumCheck` runs when a step is within the tolerance, in three parts:

1. *Probe*: ``PROBE_STEPS`` plain steps of the paper's map from the current
   positions, on scratch copies (the simulation's state, stops and strategy
   history are untouched). Near a fixed point the map is linear, so once its
   fast modes (the hinge faces settling against the panels, ratio ≈ 0.55 per
   step, measured) have died out, its steps shrink by the slowest mode's
   ratio ρ; the distance still to go is estimated as the probe's net move
   plus the geometric tail ‖s_last‖ ρ / (1 − ρ), with ρ from the smallest
   steps of its last two windows of ``RATE_WINDOW`` steps (a rounding spike
   only ever enlarges a step). It must be within the tolerance × size; ρ ≥ 1
   sees no equilibrium.
2. *Rounding floor*: where the probe's last steps are below ``ROUNDING`` ×
   size no rate can be resolved; the run must then have lowered its energy to
   ``ENERGY_LEFT`` of its largest (a hinge at H / size = 10⁻⁵ sits at its start,
   steps below 10⁻¹⁴, energy unchanged: before this rule ``paper``, ``lbfgs``
   and ``anderson`` called it converged at 0°).
3. *Hold*: the strategy's own next ``HOLD`` iterations (a tenth of the stage,
   if more) must not creep: their drift, extrapolated at its rate over as
   many iterations as the stage had taken, must stay within the tolerance
   (drift at the resolution below is not extrapolated). Why: the probe sees
   a mode only after every faster one has died out, and a thin sheet's
   clustered slow modes do not within 60 steps. The thin Miura 10 × 10 passed
   the probe (4.3e-9) 60° short while L-BFGS crept on at 1.2e-7 mm per
   iteration, 1.6e-6 mm over its hold (limit 2.1e-6 mm; extrapolated over the
   stage, 1.8e-5 mm). An energy test over the hold (the rigid-body
   strategy's) was tried and dropped: a compatible waterbomb under L-BFGS,
   its positions settled to 1e-10, kept lowering an energy of 1e-17 mm⁵ by
   10 % per hold and never passed in mm and m.

Measured on a single hinge to 90° (size 20 mm, tolerance 1e-8, 3 000
iterations): H / size = 10⁻¹…10⁻² converge under ``lbfgs`` (and 10⁻¹ under
``anderson``) to 90° within 1e-6°; 10⁻³…10⁻⁵ are ``stalled`` under all three
(``paper`` at once: its rate cannot reach the fold in the budget). Scale-free
(ratios of lengths and energies), so the same scene in mm, m and µm gets the
same verdict (``tests/test_verdict.py``). Tolerances below ``RESOLUTION``
(10⁻¹²) are checked to that resolution (rounding moved a hinge converged by
``anderson`` by 1.6·10⁻¹³ of its size over the hold). The verdict is exactly
scale-free: under a power-of-two unit change every strategy takes the same
steps bit for bit (tested); mm, m and µm differ by the inputs' rounding, which
the waterbomb's near-mechanism modes (panels shifting 4e-4 × size at energies
of 1e-17 mm⁵) amplify under L-BFGS's line search: at tolerance 1e-8 it
converges in 3 630 / 10 997 / 2 734 iterations with fold angles 8.3e-7 rad
apart, within the 2 × tolerance × size / H = 2e-6 rad two runs each within
tolerance × size of an equilibrium may differ by. Limit: a run whose targets
were just set, started at the rounding floor next to a binding equilibrium
(energy legitimately above half its start), is called ``stalled``; the
energy is measured from the run's start or the targets' last change,
whichever is earlier, so a second stage or a re-run from a converged state is
not.

Cost: ``PROBE_STEPS`` local steps and solves per probe; after a failed check
the next waits as many iterations as the run has taken (at least
``PROBE_STEPS``), so probes cost at most a few tens of percent of a run that
never settles; the hold adds at least ``HOLD`` iterations to a run that does.
:attr:`EquilibriumCheck.residual` is the last estimate (``Result.residual``).
"""
from __future__ import annotations

import numpy as np

PROBE_STEPS = 60  # plain map steps per check (fast modes fall by ≈ 0.55 per step, measured)
ROUNDING = 3e-14  # relative step at which the probe's rate is rounding noise (measured 1e-14)
RESOLUTION = 1e-12  # relative distance the probe resolves (its net move at rounding: 1e-13)
ENERGY_LEFT = 0.5  # at the rounding floor: the run must have lowered E to this share of its largest
HOLD = 10  # strategy iterations at least over which a passed probe's state must not creep
RATE_WINDOW = 15  # probe steps per window of the rate estimate (the last two windows)


class EquilibriumCheck:
    """The probe of one :class:`foldcore.Simulation` (module docstring).

    Attributes
    ----------
    residual : float
        Last estimated distance to the equilibrium / the pattern size
        (dimensionless; NaN before the first check of the run).
    rate : float
        The slowest mode's ratio per plain step seen by the last probe.
    failed : bool
        Whether the run's last check found the equilibrium not reached.
    """

    def __init__(self, sim):
        self.sim = sim
        self._run_start = self._targets_set = sim.iterations
        self.new_run()

    def begin_run(self) -> None:
        """:meth:`Simulation.run` starts (its stages each call :meth:`new_run`)."""
        self._run_start = self.sim.iterations

    def targets_changed(self) -> None:
        """The fold targets (or K) changed: energies before now belong to another
        problem."""
        self._targets_set = self.sim.iterations

    def new_run(self) -> None:
        """A run starts: no check yet, the first one is due at once."""
        self.residual, self.rate, self.failed = np.nan, np.nan, False
        self._start = self.sim.iterations
        self._next = self.sim.iterations
        self._anchor = None  # (hold's end, positions, iteration) where the last probe passed

    def settled(self, moved: float, limit: float) -> bool:
        """Whether a run may stop after a step of ``moved`` mm (limit: tolerance × size,
        mm): the step is within the limit, a probe found the equilibrium within it, and
        the strategy's own iterations stayed within it since, for ``HOLD`` of them
        (or a tenth of the run, if more)."""
        sim = self.sim
        if not moved <= limit:
            return False
        if self._anchor is not None:
            return self._held(limit)
        if sim.iterations < self._next:
            return False
        self.residual, self.rate, resolved = self.probe()
        relative = max(limit / sim.length_scale, RESOLUTION)
        self.failed = not (self.residual <= relative
                           and (resolved or self._energy_fell(relative)))
        if self.failed:
            self._probe_later()
        else:
            hold = max(HOLD, (sim.iterations - self._start) // 10)
            self._anchor = (sim.iterations + hold, sim.x.copy(), sim.iterations)
        return False

    def _held(self, limit: float) -> bool:
        """At the end of the hold: whether the positions' drift since the probe passed,
        extrapolated at its rate over as many iterations as the stage had taken by
        then, is within ``limit`` mm (a creep of the strategy's own steps, each within
        the limit, fails here and sends the run back to probing)."""
        sim = self.sim
        due, anchor, started = self._anchor
        if sim.iterations < due:
            return False
        drift = float(np.abs(sim.x - anchor).max())
        if drift > RESOLUTION * sim.length_scale:  # rounding noise is not extrapolated
            drift *= max(1.0, (started - self._start) / (sim.iterations - started))
        self._anchor = None
        self.residual = max(self.residual, drift / sim.length_scale)
        self.failed = not drift <= max(limit, RESOLUTION * sim.length_scale)
        if self.failed:
            self._probe_later()
        return not self.failed

    def _probe_later(self) -> None:
        """After a failed check: the next probe waits as many iterations as the stage
        has taken, at least ``PROBE_STEPS``."""
        iterations = self.sim.iterations
        self._next = iterations + max(PROBE_STEPS, iterations - self._start)

    def _energy_fell(self, relative: float) -> bool:
        """Whether the energy fell to ``ENERGY_LEFT`` of its largest, or to
        ``relative`` × it (a run at the rounding floor that never lowered its energy
        did not fold: it sits where it started). Largest since the run began or the
        targets were last set, whichever is earlier: a run's second stage (the
        branch floor released) or a second run with the same targets may start at
        the equilibrium the first reached, its energy already at the floor."""
        energies = self.sim.energy_history[min(self._run_start, self._targets_set):]
        if not energies:
            return False
        return energies[-1] <= max(ENERGY_LEFT, relative) * max(energies)

    def hopeless(self, limit: float, budget: int) -> bool:
        """After a failed check: whether the plain map, at the probe's rate, needs more
        than ``budget`` further steps to come within ``limit`` mm (the ``paper``
        strategy's steps are that map, so it can stop there, ``stalled``)."""
        if not self.failed:
            return False
        if not self.rate < 1.0:
            return True
        distance = self.residual * self.sim.length_scale
        needed = np.log(limit / distance) / np.log(self.rate)
        return bool(needed > budget)

    def probe(self) -> tuple[float, float, bool]:
        """(estimated distance to the equilibrium / size, slowest ratio, whether it was
        resolved) from ``PROBE_STEPS`` plain steps at the current positions; the
        simulation's state is left as it was."""
        sim = self.sim
        x, steps = sim.x, []
        with sim.scratch_projections():
            for _ in range(PROBE_STEPS):
                _, rhs = sim.local_step(x)
                new_x = sim.global_step(rhs)
                steps.append(float(np.abs(new_x - x).max()))
                x = new_x
        size = sim.length_scale
        return self._estimate(float(np.abs(x - sim.x).max()) / size, np.array(steps) / size)

    @staticmethod
    def _estimate(travelled: float, steps: np.ndarray) -> tuple[float, float, bool]:
        """Distance the probe moved + geometric tail, relative; the slowest ratio per
        step; whether that ratio was resolved (the last steps above the rounding floor)
        (``travelled``: the probe's net move / size; ``steps``: each step's largest
        move / size).

        The ratio compares the smallest step of the probe's last ``RATE_WINDOW`` steps
        with that of the window before (a rounding spike only ever enlarges a step,
        the slow mode's steady drift is in every one of them)."""
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
