"""``hybrid``: rigid-body steps first, L-BFGS where they cannot finish (a composite).

Each :meth:`Simulation.run` starts with a rigid phase (:mod:`.rigid`) from
the current positions (one rigid-body engine serves every run: its column
layout and factor analysis are built once). A rigid step that settles
(:meth:`.rigid.Rigid.settled`: accepted, ≤ the run's tolerance × size and
lowering the energy by ≤ tolerance × E) ends the run there: the rigid-body
model's equilibrium (panels exactly rigid, each passive crease one bounded
bend). Otherwise the phase ends when an accepted step moves ≤
``HYBRID_RIGID_TOL`` × size (a run with a tighter tolerance, e.g. 0) or
after ``HYBRID_RIGID_MAX`` steps, and :mod:`.lbfgs` continues
from where it stopped on the paper's own energy (Eq. 9 passive sub-strips,
panels as stiff elements). Why the run ends with the rigid phase when it
settles (measured, issue 16): where the rigid phase converges the L-BFGS
phase only changes the state within the tolerance on compatible scenes, and
under angle-controlled actuation its 10³ stiffness contrast kept it from
converging at all (Pehrson's vertex folded flat: rigid 21 iterations, then
L-BFGS 10 000 without converging). A mesh the rigid phase cannot take
(elastic cells, other element types) runs L-BFGS alone, and so does a run
with a fading position target (``decay`` < 1, counted in iterations: the
rigid phase would settle on the pull before it fades). Bare :meth:`Simulation.step` calls outside a run are L-BFGS steps;
whatever ends a rigid phase (its criterion, the budget, an exception or an
interrupt), the strategy is left in its L-BFGS phase. Changed targets start
the next run with a rigid phase again; positions set from outside are
continued from with L-BFGS (a rigid phase would refit the panels).
"""
from __future__ import annotations

import numpy as np

from ..errors import SimulationError
from . import Strategy
from .lbfgs import Lbfgs
from .rigid import Rigid

HYBRID_RIGID_MAX = 1_000  # rigid-body steps at most per run (Miura 20 × 20, one crease driven: 206)
HYBRID_RIGID_TOL = 1e-10  # relative step below which the rigid phase ends (even at tolerance 0)


class Hybrid(Strategy):
    """``rigid`` for the first steps of each run, then ``lbfgs``."""

    name = "hybrid"

    def __init__(self, sim):
        super().__init__(sim)
        self.lbfgs = Lbfgs(sim)
        self.rigid = None  # the rigid phase's strategy while it runs
        self._rigid_steps = 0
        self._pending = True  # the next run starts with a rigid phase
        self._engine = None  # the rigid phase's strategy, built on the first run (False: none)

    @property
    def phase(self) -> str:
        return "rigid" if self.rigid is not None else "lbfgs"

    def begin_run(self) -> None:
        if not self._pending:
            return
        self._pending = False
        if any(t.decay < 1.0 for t in self.sim._position_targets.values()):
            return  # a pull-and-release schedule: the rigid phase would settle before it fades
        if self._engine is None:
            try:
                self._engine = Rigid(self.sim)
            except SimulationError:
                self._engine = False  # not a rigid-panel mesh: L-BFGS alone
        if self._engine is False:
            return
        self.rigid = self._engine  # one engine for every run: its layout and analysis stay
        self.rigid.engine.resync(self.sim.x)
        self.sim.x = self.rigid.engine.x
        self._rigid_steps = 0
        self.rigid.begin_run()  # a run's stages share its energy scale (rigid_body.settled)

    def step(self) -> tuple[float, float]:
        if self.rigid is None:
            return self.lbfgs.step()
        self._rigid_steps += 1
        return self.rigid.step()

    def settled(self, moved: float, limit: float) -> bool:
        if self.rigid is None:
            return super().settled(moved, limit)
        coarse = self.rigid.twin is not None
        done = self.rigid.settled(moved, limit)
        if coarse and not done and self._rigid_steps < HYBRID_RIGID_MAX:
            return False  # the twin's steps: it hands over itself when it stalls
        tiny = self.rigid.engine.accepted and moved <= HYBRID_RIGID_TOL * self.sim.length_scale
        if done or tiny or self._rigid_steps >= HYBRID_RIGID_MAX:
            if not done:  # L-BFGS takes over: the run will not end at a rigid state
                self.rigid.hand_over()
                self.rigid.engine.forget_ends()
            self._leave_rigid_phase()
        return done

    def predict(self, ratio: float) -> bool:
        if not self._engine or not self._engine.predict(ratio):
            return False
        self.lbfgs.restart()
        return True

    def end_run(self) -> None:
        if self._engine:
            self._engine.end_run()  # the coarse twin hands over unless the run goes on
        self._leave_rigid_phase()

    def _leave_rigid_phase(self) -> None:
        if self.rigid is None:
            return
        self.rigid = None
        self.sim.x = np.ascontiguousarray(self.sim.x.copy())
        self.lbfgs.restart()

    def targets_changed(self) -> None:
        self.lbfgs.restart()
        self._pending = True

    def positions_set(self) -> None:
        self._leave_rigid_phase()
        if self._engine:
            self._engine.engine.forget_ends()
        self._pending = False
        self.lbfgs.restart()

    def restart(self) -> None:
        self.lbfgs.restart()
