"""Whether a local/global run reached its equilibrium: a small step is not a verdict.

The paper's map, L-BFGS and Anderson all move a long panel only through its
thin hinge faces. Far from the fold (a hinge 90° short), their steps can be
far below tolerance × size while the panels turn by 10⁻⁸ of the remaining
angle per step: the length-only rule called that "converged" (issue 18: a
single hinge at H / size = 10⁻⁴ stopped after 2 iterations 90° short under
``paper``, ``anderson`` and ``lbfgs``).

The check here (:class:`EquilibriumCheck`), run when a step is within the
tolerance, is a *probe*: ``PROBE_STEPS`` plain steps of the paper's map from
the current positions, on scratch copies (the simulation's state, stops and
strategy history are untouched). Near a fixed point the map is linear, so
after its fast modes (the hinge faces settling against the panels, ratio ≈
0.55 per step, measured) have died out, successive steps shrink by the
slowest mode's ratio ρ; the distance still to go is estimated as the path
the probe moved (its net displacement, in which rounding noise cancels) plus
the geometric tail ‖s_last‖ ρ / (1 − ρ), with ρ from the smallest steps of
its last two windows of ``RATE_WINDOW`` steps (a rounding spike only ever
enlarges a step). The run is
settled only when that estimate is within the tolerance × size. A probe whose
steps stop shrinking (ρ ≥ 1) sees no equilibrium unless its last step is at
the rounding floor (``ROUNDING`` × size), where no rate can be resolved.

Measured on a single hinge to 90° (``bench`` scene sizes, tolerance 1e-8):
at H / size = 10⁻³ after L-BFGS's small 5th step, ρ = 1 − 3·10⁻⁹ and an
estimated distance of 5·10⁻² × size (the length-only rule stopped there); at
10⁻² after 294 L-BFGS iterations (89.999999°), 3·10⁻¹⁰. The estimate is
scale-free (ratios of lengths), so the same scene in mm, m and µm gets the
same verdict. Its limits: a stall whose plain steps are already below the
rounding floor is not seen, and a tolerance below ``RESOLUTION`` (10⁻¹²) is
checked to that resolution (the probe's net move at rounding noise measured
1.1·10⁻¹³ on a hinge converged by ``anderson`` to 10⁻¹³).

Cost: ``PROBE_STEPS`` local steps and solves per check; after a failed check
the next waits as many iterations as the run has taken (at least
``PROBE_STEPS``), so probes cost at most a few tens of percent of a run that
never settles. :attr:`EquilibriumCheck.residual` is the last estimate (the
run's ``Result.residual``).
"""
from __future__ import annotations

import numpy as np

PROBE_STEPS = 60  # plain map steps per check (fast modes fall by ≈ 0.55 per step, measured)
ROUNDING = 3e-14  # relative step at which the probe's rate is rounding noise (measured 1e-14)
RESOLUTION = 1e-12  # relative distance the probe resolves (its net move at rounding: 1e-13)
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
        self.new_run()

    def new_run(self) -> None:
        """A run starts: no check yet, the first one is due at once."""
        self.residual, self.rate, self.failed = np.nan, np.nan, False
        self._start = self.sim.iterations
        self._next = self.sim.iterations

    def settled(self, moved: float, limit: float) -> bool:
        """Whether a run may stop after a step of ``moved`` mm (limit: tolerance × size,
        mm): the step is within the limit and a due probe finds the equilibrium within
        it too."""
        sim = self.sim
        if not moved <= limit or sim.iterations < self._next:
            return False
        self.residual, self.rate = self.probe()
        self.failed = not self.residual <= max(limit / sim.length_scale, RESOLUTION)
        if self.failed:
            self._next = sim.iterations + max(PROBE_STEPS, sim.iterations - self._start)
        return not self.failed

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

    def probe(self) -> tuple[float, float]:
        """(estimated distance to the equilibrium / size, slowest ratio) from
        ``PROBE_STEPS`` plain steps at the current positions; the simulation's
        state is left as it was."""
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
    def _estimate(travelled: float, steps: np.ndarray) -> tuple[float, float]:
        """Distance the probe moved + geometric tail, relative; and the slowest ratio
        per step (``travelled``: the probe's net move / size; ``steps``: each step's
        largest move / size).

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
        return float(travelled + tail), float(rate)
