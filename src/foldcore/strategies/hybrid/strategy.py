"""``hybrid``: rigid-body steps first, Gauss–Newton where they cannot finish.

Each run starts with a rigid phase (:mod:`..rigid`) from the current positions
(one rigid-body engine serves every run: its column layout and factor analysis
are built once). A rigid step that settles ends the run there: the rigid-body
model's equilibrium (panels exactly rigid, each passive crease one bounded
bend), where the run's equilibrium certificate finds it the mesh's too; where
it does not (:meth:`Hybrid.refused`) ``newton`` goes on from it. Otherwise the
phase ends when an accepted step moves ≤ ``rigid_tol`` × size or after
``rigid_max_steps`` steps, and :mod:`..newton` continues from where it stopped
on the paper's own energy (:mod:`..lbfgs` on meshes
``newton`` refuses, e.g. stretch hinges). A mesh the rigid phase cannot take
runs one strategy alone: L-BFGS, or ``newton`` where every elastic face is
cut into rings, which from the rest state starts on the mesh's rigid-panel
twin (:mod:`.rings`); so does a run with a fading position target. Bare steps
outside a run are steps of the finish. Changed targets start the next run
with a rigid phase again; positions set from outside are continued from with
L-BFGS. Why this composite: `docs/architecture.md#the-default-strategy`.
"""
from __future__ import annotations

import logging
from dataclasses import dataclass, field

import numpy as np

from ...convergence import Report
from ...errors import SimulationError
from ..base import Strategy
from ..lbfgs import Lbfgs, LbfgsOptions
from ..newton import Newton, NewtonOptions
from ..rigid import Rigid, RigidOptions, at_rest, slack_creases
from .rings import RigidStart, in_rings, rigid_twin_mesh


log = logging.getLogger(__name__)


@dataclass(frozen=True)
class HybridOptions:
    """Options of ``hybrid``: its own, and those of the strategies it holds.

    Attributes
    ----------
    rigid_max_steps : int
        Rigid-body steps at most per run.
    rigid_tol : float
        Relative step below which the rigid phase ends (even at tolerance 0).
    rigid, newton, lbfgs
        Options of the phases.
    """

    rigid_max_steps: int = 1_000
    rigid_tol: float = 1e-10
    rigid: RigidOptions = field(default_factory=RigidOptions)
    newton: NewtonOptions = field(default_factory=NewtonOptions)
    lbfgs: LbfgsOptions = field(default_factory=LbfgsOptions)


class Hybrid(Strategy):
    """``rigid`` for the first steps of each run, then ``newton`` (``lbfgs`` where
    ``newton`` refuses the mesh, and for positions set from outside)."""

    name = "hybrid"
    Options = HybridOptions
    supports_contact = True  # every phase keeps panels apart (rigid, newton, lbfgs)

    def __init__(self, model, progress, options=None):
        super().__init__(model, progress, options)
        self.finish = self._finishing()  # L-BFGS, or Newton on elastic cells / with contact
        self._default_finish = self.finish
        self._newton = None  # the finish after a rigid phase hands over (False: refused)
        self.rigid = None  # the rigid phase's strategy while it runs
        self._rigid_steps = 0
        self._pending = True  # the next run starts with a rigid phase
        self._engine = None  # the rigid phase's strategy, built on the first run (False: none)
        self._start = None  # the rigid phase of a mesh in rings while it runs (RigidStart)
        # slack hinges: the rigid phase holds their strips at their shortest, newton frees them
        self._slack = bool(len(slack_creases(model.mesh)))
        self._rigid_settled = False  # the last report was the rigid phase's settled state

    def _finishing(self) -> Strategy:
        """The strategy after (or instead of) the rigid phase: ``newton`` on a mesh whose
        elastic faces are all in rings, else ``lbfgs`` (from rest ``newton`` turns
        panels of bars and plates by small linear steps); both keep panels apart
        with contact."""
        o = self.options
        if in_rings(self.model.mesh):
            return Newton(self.model, self.progress, o.newton)
        return Lbfgs(self.model, self.progress, o.lbfgs)

    @property
    def rigid_phase(self):
        """The rigid phase's strategy (:class:`..rigid.Rigid`), once a run built it
        (None before; False on meshes it cannot take)."""
        return self._engine

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
        if self.model.pins.fading():
            return  # a pull-and-release schedule: the rigid phase would settle before it fades
        if self._engine is None:
            try:
                self._engine = Rigid(self.model, self.progress, self.options.rigid,
                                     predictor=True)
            except SimulationError:
                self._engine = False  # not a rigid-panel mesh: the finishing strategy
        if self._engine is False:
            self._begin_rigid_start()
            return
        self.rigid = self._engine  # one engine for every run: its layout and analysis stay
        self.rigid.engine.resync(self.model.x)
        self.model.x = self.rigid.engine.x
        self._rigid_steps = 0
        self.rigid.begin_run()  # a run's stages share its energy scale

    def _begin_rigid_start(self) -> None:
        """From the rest state, without position targets, a mesh in rings starts on its
        rigid-panel twin (:class:`.rings.RigidStart`)."""
        model = self.model
        if not isinstance(self.finish, Newton) or \
                not at_rest(model, model.x, self.options.rigid.rest_tol):
            return
        mesh = rigid_twin_mesh(model.mesh, model.pattern)
        if mesh is not None:
            log.info("hybrid: the rigid-panel twin steps first, then %s on the cells",
                     self.finish.name)
            self._start = RigidStart(model, self.progress, mesh, self.options.rigid)
            self._start.begin()

    def _end_rigid_start(self) -> None:
        """The cells take the rigid twin's state; the finishing strategy goes on."""
        start, self._start = self._start, None
        log.info("hybrid: the cells take the rigid twin's state after %d steps", start.steps)
        self.model.x = np.ascontiguousarray(start.positions())
        self.finish.restart()

    def step(self) -> tuple[float, float]:
        if self._start is not None:
            return self._start.step()
        if self.rigid is None:
            return self.finish.step()
        self._rigid_steps += 1
        return self.rigid.step()

    def report(self, moved: float, limit: float) -> Report:
        self._rigid_settled = False
        if self._start is not None:
            return Report(moved, settled=self._settled_start(moved, limit),
                          stalled=self.stalled)
        if self.rigid is None:
            return self.finish.report(moved, limit)
        coarse = self.rigid.twin is not None  # (before the report: it may hand over)
        rigid = self.rigid.report(moved, limit)
        done = self._settled_rigid(rigid.settled, moved, coarse)
        return Report(moved, settled=done, stalled=self.stalled, residual=rigid.residual)

    def _settled_start(self, moved: float, limit: float) -> bool:
        """A rings mesh's rigid start: a settled twin ends a branch stage; in the run's
        last stage it (or its step budget) hands over to the cells' own steps, which
        confirm its state."""
        done = self._start.settled(moved, limit)
        if self.progress.stage == "branch":
            return done
        if done or self._start.steps >= self.options.rigid_max_steps:
            self._end_rigid_start()
        return False

    def _settled_rigid(self, done: bool, moved: float, coarse: bool) -> bool:
        """The rigid phase's verdict ``done`` (``coarse``: the step was the coarse
        twin's); where it is not reached but the phase is over (a tiny step, the step
        budget), ``newton`` takes over."""
        o = self.options
        if coarse and not done and self._rigid_steps < o.rigid_max_steps:
            return False  # the twin's steps: it hands over itself when it stalls
        # a step contact cut short is tiny without the phase being over, unless the
        # rigid model is not the mesh's (slack hinges): newton must finish anyway
        tiny = self.rigid.engine.stalls(moved, o.rigid_tol) and (
            self._slack or not self.rigid.engine.lm.cut)
        if done and self._slack:  # the rigid model's equilibrium, not the mesh's
            done = False
        if done or tiny or self._rigid_steps >= o.rigid_max_steps:
            if not done:  # the run will not end at a rigid state: Newton takes over
                self.rigid.hand_over()
                self.rigid.engine.forget_ends()
                self._finish_with_newton()
                log.info("hybrid: rigid phase ends unsettled after %d steps; %s finishes",
                         self._rigid_steps, self.finish.name)
            self._rigid_settled = done
            self._leave_rigid_phase()
        return done

    def refused(self) -> bool:
        """The convergence test refused a settled state. Where the rigid phase settled
        it, the rigid-body model's equilibrium is not the mesh's (a binding fold its
        panels resolve by bending, a passive crease its bounds hold): ``newton`` (or
        the default finish where it refuses the mesh) goes on from it. Else the
        finishing strategy says."""
        if not self._rigid_settled:
            return self.finish.refused()
        self._rigid_settled = False
        self._engine.refused()  # no run end to extrapolate from, no twin to continue
        self._finish_with_newton()
        self.finish.restart()
        log.info("hybrid: the rigid phase's equilibrium is not the mesh's; %s finishes",
                 self.finish.name)
        return True

    def _finish_with_newton(self) -> None:
        """After a rigid phase that handed over unsettled, ``newton`` finishes (where it
        takes the mesh; else the default finish): its residual left (a binding fold)
        makes L-BFGS crawl."""
        if self._newton is None:
            try:
                self._newton = Newton(self.model, self.progress, self.options.newton)
            except SimulationError:
                self._newton = False  # e.g. stretch hinges: the default finish
        if self._newton:
            self.finish = self._newton

    def _default_finishing(self) -> None:
        """New targets or positions from outside: the default finish again."""
        if self.finish is not self._default_finish:
            self.finish = self._default_finish
            self.finish.restart()

    def predict(self, ratio: float) -> bool:
        if not self._engine or not self._engine.predict(ratio):
            return False
        self.finish.restart()
        return True

    def end_run(self) -> None:
        if self._start is not None and self.progress.stage != "branch":
            self._end_rigid_start()  # out of budget, stopped or interrupted: the cells' state
        if self._engine:
            self._engine.end_run()  # the coarse twin hands over unless the run goes on
        self._leave_rigid_phase()

    def _leave_rigid_phase(self) -> None:
        if self.rigid is None:
            return
        self.rigid = None
        self.model.x = np.ascontiguousarray(self.model.x.copy())
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
