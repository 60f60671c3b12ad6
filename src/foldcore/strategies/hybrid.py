"""``hybrid``: rigid-body steps first, Gauss–Newton where they cannot finish.

Each :meth:`Simulation.run` starts with a rigid phase (:mod:`.rigid`) from
the current positions (one rigid-body engine serves every run: its column
layout and factor analysis are built once). A rigid step that settles
(:meth:`.rigid.Rigid.settled`: accepted, ≤ the run's tolerance × size and
lowering the energy by ≤ tolerance × E) ends the run there: the rigid-body
model's equilibrium (panels exactly rigid, each passive crease one bounded
bend). Otherwise the phase ends when an accepted step moves ≤
``HYBRID_RIGID_TOL`` × size (a run with a tighter tolerance, e.g. 0) or
after ``HYBRID_RIGID_MAX`` steps, and :mod:`.newton` continues from where
it stopped on the paper's own energy (Eq. 9 passive sub-strips, panels as
stiff elements; :mod:`.lbfgs` on meshes ``newton`` refuses, e.g. stretch
hinges). Why ``newton`` and not L-BFGS there (measured 2026-12-03, 2-core
Xeon guest, tolerance 1e-8/1e-9): a run hands over where the rigid model's
state is not the paper model's equilibrium, mostly at a binding fold, where
the residual left makes L-BFGS crawl — Origami Simulator's map fold,
Miura and simple vertex at 90 % ran L-BFGS's 3 000-iteration budget
(``bench/real_patterns.py``), the map fold 69.8° off; with ``newton`` they
converge in 193, 213 and 154 iterations (map fold 19.2° off), a thick
Miura 4 × 4 driven flat in 128 (L-BFGS: budget). Why the run ends with the
rigid phase when it settles (measured, issue 16): where the rigid phase converges the L-BFGS
phase only changes the state within the tolerance on compatible scenes, and
under angle-controlled actuation its 10³ stiffness contrast kept it from
converging at all (Pehrson's vertex folded flat: rigid 21 iterations, then
L-BFGS 10 000 without converging). A mesh the rigid phase cannot take
(elastic cells, other element types) runs one strategy alone — L-BFGS, or
:mod:`.newton` where every elastic face is cut into rings (L-BFGS crawls
there: that module's docstring), which from the rest state starts on the
mesh's rigid-panel twin (:class:`_RigidStart`) — and so does a run
with a fading position target (``decay`` < 1, counted in iterations: the
rigid phase would settle on the pull before it fades). Bare
:meth:`Simulation.step` calls outside a run are steps of the finish (L-BFGS,
or ``newton`` after a hand-over); a rigid phase ended otherwise than by its
hand-over (its criterion, an exception or an interrupt) leaves the strategy
in its L-BFGS phase. Changed targets start the next run with a rigid phase
again (and L-BFGS as the finish until it hands over); positions set from
outside are continued from with L-BFGS (a rigid phase would refit the panels).
"""
from __future__ import annotations

import numpy as np

from ..errors import SimulationError
from . import Strategy
from .lbfgs import Lbfgs
from .newton import Newton
from .rigid import Rigid, at_rest

HYBRID_RIGID_MAX = 1_000  # rigid-body steps at most per run (Miura 20 × 20, one crease driven: 206)
HYBRID_RIGID_TOL = 1e-10  # relative step below which the rigid phase ends (even at tolerance 0)


def _finishing(sim) -> Strategy:
    """The strategy after (or instead of) the rigid phase: ``newton`` on a mesh whose
    elastic faces are all in rings (it starts on their rigid twin: :class:`_RigidStart`),
    else ``lbfgs``. Why not ``newton`` on bars and plates (no rigid twin there): from
    rest it turns panels by small linear steps (a plate pair driven to 90°: not
    converged in 5 000 steps, where L-BFGS takes hundreds)."""
    from ..coarse import in_rings

    return Newton(sim) if in_rings(sim.mesh) else Lbfgs(sim)


class _RigidStart:
    """The rigid phase of a mesh whose faces are cut into rings: its rigid-panel twin
    (:func:`foldcore.coarse.rigid_twin_mesh`, a rigid Simulation mirroring the
    targets and floors, :class:`foldcore.coarse.Twin`) steps from the rest state
    through the run's stages; its state is then placed on the cells
    (:func:`foldcore.coarse.place_cells`), where the finishing strategy goes on.
    Why: a linear step on free vertices turns a panel only by stretching it, so
    a fold through large angles costs ``newton`` many steps (the FOLD project's
    diagonal fold to 162°, 10 mm cells: 3 000 steps, budget; with this start:
    12 iterations in all), and the rigid model is the elastic one's limit of
    stiff panels."""

    def __init__(self, sim, mesh):
        from ..coarse import Twin

        self.sim, self.mesh = sim, mesh
        self.twin = Twin(sim, mesh)
        self.steps = 0

    def begin(self) -> None:
        twin = self.twin.sim
        self.twin.mirror(self.sim)
        twin.stage = self.sim.stage
        twin.strategy.begin_run()

    def step(self) -> tuple[float, float]:
        self.steps += 1
        moved = self.twin.sim._step()
        return self.twin.sim.energy_history[-1], moved

    def settled(self, moved: float, limit: float) -> bool:
        self.twin.sim.stage = self.sim.stage
        return self.twin.sim.strategy.settled(moved, limit)

    def positions(self) -> np.ndarray:
        """The mesh's positions at the twin's state, and the twin's run ended."""
        from ..coarse import place_cells

        twin = self.twin.sim
        twin.strategy.end_run()
        twin.stage = None
        return place_cells(self.sim.mesh, self.mesh, twin.x)


class Hybrid(Strategy):
    """``rigid`` for the first steps of each run, then ``newton`` (``lbfgs`` where
    ``newton`` refuses the mesh, and for positions set from outside)."""

    name = "hybrid"

    def __init__(self, sim):
        super().__init__(sim)
        self.finish = _finishing(sim)  # L-BFGS, or Newton on elastic cells
        self._default_finish = self.finish
        self._newton = None  # the finish after a rigid phase hands over (False: refused)
        self.rigid = None  # the rigid phase's strategy while it runs
        self._rigid_steps = 0
        self._pending = True  # the next run starts with a rigid phase
        self._engine = None  # the rigid phase's strategy, built on the first run (False: none)
        self._start = None  # the rigid phase of a mesh in rings while it runs (_RigidStart)

    @property
    def stalled(self) -> bool:
        """The finishing strategy's verdict once the rigid phase has ended."""
        return self.rigid is None and self._start is None and self.finish.stalled

    @property
    def phase(self) -> str:
        return "rigid" if self.rigid is not None or self._start else self.finish.name

    def begin_run(self) -> None:
        self.finish.begin_run()
        if self._start is not None:  # the stage after a branch stage
            self._start.begin()
            return
        if not self._pending:
            return
        self._pending = False
        if any(t.decay < 1.0 for t in self.sim._position_targets.values()):
            return  # a pull-and-release schedule: the rigid phase would settle before it fades
        if self._engine is None:
            try:
                self._engine = Rigid(self.sim)
            except SimulationError:
                self._engine = False  # not a rigid-panel mesh: the finishing strategy
        if self._engine is False:
            self._begin_rigid_start()
            return
        self.rigid = self._engine  # one engine for every run: its layout and analysis stay
        self.rigid.engine.resync(self.sim.x)
        self.sim.x = self.rigid.engine.x
        self._rigid_steps = 0
        self.rigid.begin_run()  # a run's stages share its energy scale (rigid_body.settled)

    def _begin_rigid_start(self) -> None:
        """From the rest state, without position targets, a mesh in rings starts on its
        rigid-panel twin (:class:`_RigidStart`)."""
        sim = self.sim
        if not isinstance(self.finish, Newton) or not at_rest(sim, sim.x):
            return
        from ..coarse import rigid_twin_mesh

        mesh = rigid_twin_mesh(sim.mesh, sim.pattern)
        if mesh is not None:
            self._start = _RigidStart(sim, mesh)
            self._start.begin()

    def _end_rigid_start(self) -> None:
        """The cells take the rigid twin's state; the finishing strategy goes on."""
        start, self._start = self._start, None
        self.sim.x = np.ascontiguousarray(start.positions())
        self.finish.restart()

    def step(self) -> tuple[float, float]:
        if self._start is not None:
            return self._start.step()
        if self.rigid is None:
            return self.finish.step()
        self._rigid_steps += 1
        return self.rigid.step()

    def settled(self, moved: float, limit: float) -> bool:
        if self._start is not None:
            done = self._start.settled(moved, limit)
            if self.sim.stage == "branch":
                return done
            if done or self._start.steps >= HYBRID_RIGID_MAX:
                self._end_rigid_start()
            return False  # the cells' own steps confirm the twin's state
        if self.rigid is None:
            return self.finish.settled(moved, limit)
        coarse = self.rigid.twin is not None
        done = self.rigid.settled(moved, limit)
        if coarse and not done and self._rigid_steps < HYBRID_RIGID_MAX:
            return False  # the twin's steps: it hands over itself when it stalls
        tiny = self.rigid.engine.stalls(moved, HYBRID_RIGID_TOL)
        if done or tiny or self._rigid_steps >= HYBRID_RIGID_MAX:
            if not done:  # the run will not end at a rigid state: Newton takes over
                self.rigid.hand_over()
                self.rigid.engine.forget_ends()
                self._finish_with_newton()
            self._leave_rigid_phase()
        return done

    def _finish_with_newton(self) -> None:
        """After a rigid phase that handed over unsettled, ``newton`` finishes (where
        it takes the mesh; else the default finish): from the rigid state the paper
        model's equilibrium is near, and its residual left (a binding fold) makes
        L-BFGS crawl (module docstring)."""
        if self._newton is None:
            try:
                self._newton = Newton(self.sim)
            except SimulationError:
                self._newton = False  # e.g. stretch hinges: the default finish
        if self._newton:
            self.finish = self._newton

    def _default_finishing(self) -> None:
        """New targets or positions from outside: the default finish again (L-BFGS
        on a rigid-panel mesh; positions set are continued from with it)."""
        if self.finish is not self._default_finish:
            self.finish = self._default_finish
            self.finish.restart()

    def predict(self, ratio: float) -> bool:
        if not self._engine or not self._engine.predict(ratio):
            return False
        self.finish.restart()
        return True

    def end_run(self) -> None:
        if self._start is not None and self.sim.stage != "branch":
            self._end_rigid_start()  # out of budget, stopped or interrupted: the cells' state
        if self._engine:
            self._engine.end_run()  # the coarse twin hands over unless the run goes on
        self._leave_rigid_phase()

    def _leave_rigid_phase(self) -> None:
        if self.rigid is None:
            return
        self.rigid = None
        self.sim.x = np.ascontiguousarray(self.sim.x.copy())
        self.finish.restart()

    def targets_changed(self) -> None:
        self._default_finishing()
        self.finish.restart()
        self._pending = True

    def positions_set(self) -> None:
        self._start = None
        self._leave_rigid_phase()
        self._default_finishing()
        if self._engine:
            self._engine.engine.forget_ends()
        self._pending = False
        self.finish.restart()

    def restart(self) -> None:
        self.finish.restart()
