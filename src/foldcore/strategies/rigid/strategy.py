"""``rigid``: rigid panels as rigid bodies, Levenberg–Marquardt on the hinge energy.

The engine (:class:`.engine.RigidBodySolver`) owns the unknowns, the residual
model, the step and its stopping rule; this module is the strategy around it:
it steps the engine, hands its positions and strip angles to the model,
books the engine's assembly as projection time and its factorisations and
solves as solve time, and reports its verdict. Needs a mesh of rigid panels
and bending hinges.

**Coarse start** (``RigidOptions.coarse_start``): a run from the rest state
takes its first steps on the mesh's coarse twin, its creases one sub-strip
wide (:mod:`.twin`), through every stage of the run, and hands the twin's
equilibrium to the mesh's own engine when it settles in the run's last stage
(or an accepted step of it moves ≤ ``twin_stall`` × the size). The run ends
there when the twin settled and the mesh's strips meet their bent shapes
within the run's limit, else when the mesh's own steps settle. A run that
continues a certified hand-over (a fold-percent sweep's next frame) steps the
kept twin again. Why: `docs/architecture.md#the-coarse-twin`.
"""
from __future__ import annotations

import logging
import time

import numpy as np

from ...convergence import Report
from ...errors import SimulationError
from ..base import Strategy
from .engine import RigidBodySolver
from .options import RigidOptions


log = logging.getLogger(__name__)


def at_rest(model, x: np.ndarray, tolerance: float) -> bool:
    """Whether ``model`` has no position targets and ``x`` (N, 3) mm is its mesh's rest
    state within ``tolerance`` × the size (a panels' fit rounds it): where a run
    may start on a twin mesh."""
    gap = np.abs(x - model.mesh.rest_positions).max(initial=0.0)
    return not model.position_targets and gap <= tolerance * model.length_scale


def slack_creases(mesh) -> np.ndarray:
    """(K,) crease edges of ``mesh`` with slack hinges (:mod:`foldcore.hinges`)."""
    return np.flatnonzero(np.asarray(mesh.hinge_model) == "slack")


def refuse_slack(mesh) -> None:
    """SimulationError where ``mesh`` has slack hinges: this strategy bends every strip
    along a neutral axis of a length set by its angle, a slack strip's length is
    free between bounds (:mod:`foldcore.hinges`); ``hybrid`` uses these steps as
    its predictor and finishes such meshes with ``newton``."""
    slack = slack_creases(mesh)
    if len(slack):
        listed = ", ".join(str(int(e)) for e in slack[:8]) + (" …" if len(slack) > 8 else "")
        raise SimulationError(f"solver 'rigid' holds every hinge strip at the length its "
                              f"angle sets; crease edges {listed} have slack hinges "
                              f"(their length is free): use solver 'hybrid' or 'newton'")


class Rigid(Strategy):
    """One Levenberg–Marquardt iteration per :meth:`step` (rejected steps count)."""

    name = "rigid"
    Options = RigidOptions
    supports_contact = True
    own_model = True  # its verdict is the rigid-body model's, which the user chose

    def __init__(self, model, progress, options=None, predictor: bool = False):
        super().__init__(model, progress, options)
        if not predictor:
            refuse_slack(model.mesh)
        # SimulationError on meshes it cannot take
        self.engine = RigidBodySolver(model, progress, self.options)
        self._run = -1  # the run the engine's energy scale belongs to
        self.twin = None  # the coarse twin while it steps (module docstring)
        self._twin = None  # built on first use (False: this mesh has none)
        self._branch_done = False  # the twin settled the branch stage in progress
        self._handed_x = None  # the mesh's state at a kept twin's hand-over (_continues)
        self.residual = np.nan  # the stepping engine's distance left / size, last report
        model.x = self.engine.x

    @property
    def kept_twin(self):
        """The coarse twin kept between runs (None: none built; False: this mesh has none)."""
        return self._twin

    @property
    def stepping(self):
        """The engine the next step moves: the twin's while the coarse phase lasts."""
        return self.twin.engine if self.twin is not None else self.engine

    def step(self) -> tuple[float, float]:
        return self._engine_call(self.stepping.step)

    def _engine_call(self, call, *args):
        """``call(*args)`` on the stepping engine, its time added to the model's
        timings (solve / the rest as projection); the mesh's own engine's state is
        handed to the model."""
        model, engine = self.model, self.stepping
        t0, solve0 = time.perf_counter(), engine.solve_time
        out = call(*args)
        if engine is self.engine:
            self._sync_model()
        solve = engine.solve_time - solve0
        model.timings["solve"] += solve
        model.timings["projection"] += time.perf_counter() - t0 - solve
        return out

    def _sync_model(self) -> None:
        """Hand the mesh's engine's positions and strip angles to the model."""
        self.model.x = self.engine.x
        if self.model.hinges is not None:
            self.model.hinges.state[:, 0] = self.engine.phi

    def begin_run(self) -> None:
        if self._run != self.progress.runs:  # a new run, not its second stage
            self._run = self.progress.runs
            self.engine.new_run()
            continues = self._continues()
            if not continues:
                self._drop_twin()  # a kept twin whose state the mesh left
            if (continues or self._at_rest()) and self._coarse_twin() is not None:
                self.twin = self._twin
                self.twin.engine.new_run()
                log.info("rigid: the run steps the coarse twin first (%d strips for %d)",
                         len(self.twin.engine.layout.ids), len(self.engine.layout.ids))
        if self.twin is not None:
            self.twin.mirror(self.model, self.progress)  # this stage's targets and floors

    def _at_rest(self) -> bool:
        """Whether the run starts the coarse phase: enabled, no position targets, and
        the engine's positions at the rest state (:func:`at_rest`)."""
        o = self.options
        return o.coarse_start and at_rest(self.model, self.engine.x, o.rest_tol)

    def _continues(self) -> bool:
        """Whether a kept twin can take this run's steps: the last run ended at its
        certified hand-over, the mesh's engine has not moved since, and there are no
        position targets (their vertex ids are the mesh's)."""
        return (self.options.coarse_start and self._handed_x is not None
                and not self.model.position_targets
                and np.array_equal(self.engine.x, self._handed_x))

    def _drop_twin(self) -> None:
        """Free the twin (built again from rest when a run needs it)."""
        self.twin, self._handed_x = None, None
        if self._twin:
            self._twin = None  # (False, no twin for this mesh, stays)

    def _coarse_twin(self):
        """The mesh's coarse twin (:class:`.twin.Twin`), built once; None where there
        is none."""
        if self._twin is None:
            from .twin import Twin, twin_mesh

            mesh = twin_mesh(self.model.mesh, self.model.pattern)
            self._twin = False if mesh is None else Twin(self.model, mesh, self.options)
        return self._twin or None

    def hand_over(self, keep: bool = False) -> None:
        """End the coarse phase: the mesh's engine continues from the twin's state. The
        twin is freed before the mesh's own step allocates (peak memory), unless
        ``keep`` (the caller frees it if the mesh must step)."""
        if self.twin is None:
            return
        t0 = time.perf_counter()
        log.info("rigid: the coarse twin hands over to the mesh's own engine")
        self.twin.hand_over(self.engine)
        self.twin = None
        if not keep:
            self._drop_twin()
        self._sync_model()
        self.model.timings["projection"] += time.perf_counter() - t0

    def end_run(self) -> None:
        """A stage ended: the coarse phase goes on only into the stage after a branch
        stage its twin settled; otherwise (the run ends: converged, out of budget,
        stopped or interrupted) the twin hands over."""
        if not (self.progress.stage == "branch" and self._branch_done):
            self.hand_over()
        self._branch_done = False

    def report(self, moved: float, limit: float) -> Report:
        settled = self.settled(moved, limit)
        return Report(moved, settled=settled, stalled=self.stalled, residual=self.residual)

    def settled(self, moved: float, limit: float) -> bool:
        """The engine's stopping rule (:mod:`.stopping`): an accepted step, small in the
        distance it leaves and in energy decrease. Timed and synced as a step (the
        rule may apply a simplified correction). In the coarse phase a settled twin
        ends a branch stage, and in the run's last stage hands over; the run ends
        there when every strip vertex of the mesh lies within ``limit`` of its
        strip's bent shape (the twin's equilibrium is the mesh's), else the mesh's
        own steps go on. A settled state is kept for :meth:`predict`."""
        engine, size = self.stepping, self.model.length_scale
        done = self._engine_call(engine.settled, moved, limit / size)
        self.residual = engine.distance / size
        if self.twin is None:
            if done:
                self.engine.record_end()
            return done
        if not (done or engine.stalls(moved, self.options.twin_stall)) \
                or self.progress.stage == "branch":
            self._branch_done = done
            return done
        self.hand_over(keep=True)
        if self._handed_x is None:  # a fold from rest (a continued run keeps the last
            engine.release_factor()  # hand-over's): the next run analyses anew
        if done and self.engine.strips_placed_within(limit):
            engine.record_end()  # the twin's verdict holds for the mesh
            self.engine.record_end()
            self._handed_x = self.engine.x.copy()  # the next run may go on on it
            return True
        self._drop_twin()  # the mesh's own steps finish
        return False

    def refused(self) -> bool:
        """The rigid-body model's equilibrium is not the mesh's (every element free: a
        binding fold its panels resolve by bending, a passive crease its bounds
        hold), where a composite that steps this strategy first is certified on the
        mesh (``hybrid``): these steps cannot leave it (False), and the state is no
        run end to extrapolate from."""
        self.engine.forget_ends()
        self._drop_twin()
        return False

    def predict(self, ratio: float) -> bool:
        """Extrapolate the last two run ends: on the kept twin when the next run goes on
        on it (the mesh keeps its state until the twin hands over), else on the
        mesh's engine."""
        if self._continues():
            return self._twin.engine.predict(ratio)
        if not self.engine.predict(ratio):
            return False
        self.model.x = self.engine.x
        return True

    def positions_set(self) -> None:
        raise SimulationError("solver 'rigid' keeps its panels rigid by construction: "
                              "its positions cannot be set")
