"""``rigid``: rigid panels as rigid bodies, Levenberg–Marquardt on the hinge energy.

The engine is :class:`foldcore.rigid_body.RigidBodySolver` (unknowns, Jacobian,
damping, geodesic acceleration); this module is the strategy around it: it
steps the engine, hands its positions and strip angles to the Simulation and
books the engine's assembly as projection time, its factorisations and
solves as solve time. Needs a mesh of rigid panels and bending hinges.

**Coarse start** (``COARSE_START``): a run from the rest state takes its first
steps on the mesh's coarse twin, its creases one sub-strip wide
(:mod:`foldcore.coarse`; ``twin`` is set meanwhile), through every stage of the run
(the branch stage included), and hands the twin's equilibrium to the mesh's
own engine when it settles in the run's last stage (or an accepted step of
it moves ≤ ``TWIN_STALL`` × the size: it stalls); the run ends there when
the twin settled and the mesh's strips meet their bent shapes within the
run's limit, else when the mesh's own steps settle. Meanwhile
``sim.x`` keeps the start positions (an interrupted run hands over first, so
it ends at the twin's last state). Not for meshes whose creases are one
strip wide already, or with position targets (their vertex ids are the mesh's).

**A run that continues a certified hand-over** (the last run ended there and
the mesh has not moved since: a fold-percent sweep's next frame) steps the
kept twin again, the predictor included (:meth:`Rigid.predict` extrapolates
the twin's run ends), and hands over under the same certificate. Any other
start (positions the mesh reached by its own steps, or set) runs on the
mesh, and the kept twin is freed. Why: a sweep's frames are a step or two
each, and the twin's steps are cheaper than the mesh's (1 sub-strip per
crease instead of 4): a thin Miura 8 × 8's 200-frame path took 2.29 s,
13.8 × one fold, and takes 1.18 s, 7.5 × (254 steps both; bench/paths.py,
README). The cost: the twin stays in memory between runs (its mesh, engine
and factor: ~65 MB RSS at Miura 50 × 50).
Measured (2-core Xeon guest, hybrid, tolerance 1e-8, 15 folds of the
accuracy and convergence benchmarks): see :data:`COARSE_START`.
"""
from __future__ import annotations

import time

import numpy as np

from ..errors import SimulationError
from . import Strategy

#: Whether a run from the rest state starts on the mesh's coarse twin (module docstring).
COARSE_START = True
REST_TOL = 1e-9  # relative distance from the rest positions that counts as the rest state
TWIN_STALL = 1e-10  # relative accepted step of the twin that hands over unsettled


def at_rest(sim, x: np.ndarray) -> bool:
    """Whether ``sim`` has no position targets and ``x`` (N, 3) mm is its mesh's rest
    state, within ``REST_TOL`` × the size (a panels' fit rounds it): where a run
    may start on a twin mesh."""
    gap = np.abs(x - sim.mesh.rest_positions).max(initial=0.0)
    return not sim._position_targets and gap <= REST_TOL * sim.length_scale


class Rigid(Strategy):
    """One Levenberg–Marquardt iteration per :meth:`step` (rejected steps count)."""

    name = "rigid"

    def __init__(self, sim):
        from ..rigid_body import RigidBodySolver

        super().__init__(sim)
        self.engine = RigidBodySolver(sim)  # SimulationError on meshes it cannot take
        self._run = -1  # the Simulation.run the engine's energy scale belongs to
        self.twin = None  # the coarse twin while it steps (module docstring)
        self._twin = None  # built on first use (False: this mesh has none)
        self._branch_done = False  # the twin settled the branch stage in progress
        self._handed_x = None  # the mesh's state at a kept twin's hand-over (_continues)
        sim.x = self.engine.x

    @property
    def stepping(self):
        """The engine the next step moves: the twin's while the coarse phase lasts."""
        return self.twin.engine if self.twin is not None else self.engine

    def step(self) -> tuple[float, float]:
        return self._engine_call(self.stepping.step)

    def _engine_call(self, call, *args):
        """``call(*args)`` on the stepping engine, its time added to the simulation's
        timings (solve / the rest as projection); the mesh's own engine's state is
        handed to the simulation."""
        sim, engine = self.sim, self.stepping
        t0, solve0 = time.perf_counter(), engine.solve_time
        out = call(*args)
        if engine is self.engine:
            self._sync_sim()
        solve = engine.solve_time - solve0
        sim.timings["solve"] += solve
        sim.timings["projection"] += time.perf_counter() - t0 - solve
        return out

    def _sync_sim(self) -> None:
        """Hand the mesh's engine's positions and strip angles to the simulation."""
        self.sim.x = self.engine.x
        if self.sim._hinges is not None:
            self.sim._hinges.state[:, 0] = self.engine.phi

    def begin_run(self) -> None:
        if self._run != self.sim.runs:  # a new Simulation.run, not its second stage
            self._run = self.sim.runs
            self.engine.new_run()
            continues = self._continues()
            if not continues:
                self._drop_twin()  # a kept twin whose state the mesh left
            if (continues or self._at_rest()) and self._coarse_twin() is not None:
                self.twin = self._twin
                self.twin.engine.new_run()
        if self.twin is not None:
            self.twin.mirror(self.sim)  # this stage's targets and floors

    def _at_rest(self) -> bool:
        """Whether the run starts the coarse phase: enabled, no position targets, and
        the engine's positions at the rest state (:func:`at_rest`)."""
        return COARSE_START and at_rest(self.sim, self.engine.x)

    def _continues(self) -> bool:
        """Whether a kept twin can take this run's steps: the last run ended at its
        certified hand-over (:meth:`settled`), the mesh's engine has not moved
        since, and there are no position targets (their vertex ids are the mesh's).
        A fold-percent sweep's frames go on on the twin this way."""
        return (COARSE_START and self._handed_x is not None and not self.sim._position_targets
                and np.array_equal(self.engine.x, self._handed_x))

    def _drop_twin(self) -> None:
        """Free the twin (built again from rest when a run needs it)."""
        self.twin, self._handed_x = None, None
        if self._twin:
            self._twin = None  # (False, no twin for this mesh, stays)

    def _coarse_twin(self):
        """The mesh's coarse twin (:class:`foldcore.coarse.Twin`), built once; None
        where there is none."""
        if self._twin is None:
            from ..coarse import Twin, twin_mesh

            mesh = twin_mesh(self.sim.mesh, self.sim.pattern)
            self._twin = False if mesh is None else Twin(self.sim, mesh)
        return self._twin or None

    def hand_over(self, keep: bool = False) -> None:
        """End the coarse phase: the mesh's engine continues from the twin's state. The
        twin is freed before the mesh's own step allocates (peak memory), unless
        ``keep`` (the caller frees it if the mesh must step)."""
        if self.twin is None:
            return
        t0 = time.perf_counter()
        self.twin.hand_over(self.engine)
        self.twin = None
        if not keep:
            self._drop_twin()
        self._sync_sim()
        self.sim.timings["projection"] += time.perf_counter() - t0

    def end_run(self) -> None:
        """A stage ended: the coarse phase goes on only into the stage after a branch
        stage its twin settled; otherwise (the run ends: converged, out of budget,
        stopped or interrupted) the twin hands over."""
        if not (self.sim.stage == "branch" and self._branch_done):
            self.hand_over()
        self._branch_done = False

    def settled(self, moved: float, limit: float) -> bool:
        """An accepted step, small in the distance it leaves and in energy decrease
        (:meth:`RigidBodySolver.settled`): a stall does not end a run. A settled
        state is kept for :meth:`predict`. Timed and synced as a step: the test
        may apply a simplified correction. In the coarse phase a settled twin ends
        a branch stage, and in the run's last stage hands over; the run ends there
        when every strip vertex of the mesh lies within ``limit`` of its strip's
        bent shape (:meth:`RigidBodySolver.strips_placed_within`: the twin's
        equilibrium is the mesh's, its verdict holds), else the mesh's own steps
        go on. Why not always a confirming step: on a thin Miura 50 × 50 it was
        a factorisation of the mesh's 255 093-unknown normal matrix, 1.7 s of
        the fold's 16.6 s and its peak memory (RSS 387 → 625 MB), to find a
        step of 7e-7 mm (the limit: 1e-5 mm)."""
        engine = self.stepping
        done = self._engine_call(engine.settled, moved, limit / self.sim.length_scale)
        self.sim.equilibrium.residual = engine.distance / self.sim.length_scale
        if self.twin is not None:
            if (done or engine.stalls(moved, TWIN_STALL)) and self.sim.stage != "branch":
                self.hand_over(keep=True)
                if self._handed_x is None:  # a fold from rest (a continued run keeps the
                    engine.release_factor()  # last hand-over's): the next run analyses anew
                if done and self.engine.strips_placed_within(limit):
                    engine.record_end()  # the twin's verdict holds for the mesh
                    self.engine.record_end()
                    self._handed_x = self.engine.x.copy()  # the next run may go on on it
                    return True
                self._drop_twin()  # the mesh's own steps finish
                return False
            self._branch_done = done
            return done
        if done:
            self.engine.record_end()
        return done

    def predict(self, ratio: float) -> bool:
        """Extrapolate the last two run ends (:meth:`RigidBodySolver.predict`): on the
        kept twin when the next run goes on on it (the mesh keeps its state until
        the twin hands over), else on the mesh's engine."""
        if self._continues():
            return self._twin.engine.predict(ratio)
        if not self.engine.predict(ratio):
            return False
        self.sim.x = self.engine.x
        return True

    def positions_set(self) -> None:
        raise SimulationError("solver 'rigid' keeps its panels rigid by construction: "
                              "its positions cannot be set")
