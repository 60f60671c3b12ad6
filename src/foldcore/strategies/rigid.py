"""``rigid``: rigid panels as rigid bodies, Levenberg–Marquardt on the hinge energy.

The engine is :class:`foldcore.rigid_body.RigidBodySolver` (unknowns, Jacobian,
damping, geodesic acceleration); this module is the strategy around it: it
steps the engine, hands its positions and strip angles to the Simulation and
books the engine's assembly as projection time, its factorisations and
solves as solve time. Needs a mesh of rigid panels and bending hinges.
"""
from __future__ import annotations

import time

from ..errors import SimulationError
from . import Strategy


class Rigid(Strategy):
    """One Levenberg–Marquardt iteration per :meth:`step` (rejected steps count)."""

    name = "rigid"

    def __init__(self, sim):
        from ..rigid_body import RigidBodySolver

        super().__init__(sim)
        self.engine = RigidBodySolver(sim)  # SimulationError on meshes it cannot take
        self._run = -1  # the Simulation.run the engine's energy scale belongs to
        sim.x = self.engine.x

    def step(self) -> tuple[float, float]:
        return self._engine_call(self.engine.step)

    def _engine_call(self, call, *args):
        """``call(*args)`` on the engine, its time added to the simulation's timings
        (solve / the rest as projection) and its state handed to the simulation."""
        sim, engine = self.sim, self.engine
        t0, solve0 = time.perf_counter(), engine.solve_time
        out = call(*args)
        sim.x = engine.x
        if sim._hinges is not None:
            sim._hinges.state[:, 0] = engine.phi
        solve = engine.solve_time - solve0
        sim.timings["solve"] += solve
        sim.timings["projection"] += time.perf_counter() - t0 - solve
        return out

    def begin_run(self) -> None:
        if self._run != self.sim.runs:  # a new Simulation.run, not its second stage
            self._run = self.sim.runs
            self.engine.new_run()

    def settled(self, moved: float, limit: float) -> bool:
        """An accepted step, small in the distance it leaves and in energy decrease
        (:meth:`RigidBodySolver.settled`): a stall does not end a run. A settled
        state is kept for :meth:`predict`. Timed and synced as a step: the test
        may apply a simplified correction."""
        done = self._engine_call(self.engine.settled, moved, limit / self.sim.length_scale)
        self.sim.equilibrium.residual = self.engine.distance / self.sim.length_scale
        if done:
            self.engine.record_end()
        return done

    def predict(self, ratio: float) -> bool:
        if not self.engine.predict(ratio):
            return False
        self.sim.x = self.engine.x
        return True

    def positions_set(self) -> None:
        raise SimulationError("solver 'rigid' keeps its panels rigid by construction: "
                              "its positions cannot be set")
