"""The strategy protocol (foldcore.strategies): every built-in behind it, a user's own."""
from __future__ import annotations

import numpy as np
import pytest

from foldcore import patterns, strategies, thicken
from foldcore.errors import SimulationError
from foldcore.simulation import Simulation
from foldcore.strategies.paper import PaperMap


def hinge():
    pattern = patterns.single_hinge(panel_length=5.0, depth=4.0, angle=60.0, width=2.0)
    return pattern, thicken(pattern, 1.0, subdivisions=2)


@pytest.mark.parametrize("name", strategies.SOLVERS)
def test_every_builtin_strategy_moves_the_simulation_state(name):
    pattern, mesh = hinge()
    sim = Simulation(mesh, pattern, solver=name)
    assert isinstance(sim.strategy, strategies.get(name)) and sim.strategy.name == name
    before = sim.x.copy()
    sim.run(tolerance=0, max_iterations=3)
    energies = np.array(sim.energy_history)
    assert sim.iterations == 3 and np.isfinite(energies).all()
    assert np.abs(sim.x - before).max() > 0  # the strategy wrote sim.x
    assert sim.strategy.phase in strategies.SOLVERS


def test_a_user_strategy_registers_by_class_and_runs():
    class HalfStep(PaperMap):
        """The paper's map, moving half way each step."""

        name = "test_half_step"

        def step(self):
            old = self.sim.x
            energy, moved = super().step()
            self.sim.x = 0.5 * (old + self.sim.x)
            return energy, 0.5 * moved

    try:
        assert "test_half_step" in strategies.available()
        pattern, mesh = hinge()
        sim = Simulation(mesh, pattern, solver="test_half_step")
        paper = Simulation(mesh, pattern, solver="paper")
        sim.step()
        paper.step()
        np.testing.assert_allclose(sim.x, 0.5 * (mesh.rest_positions + paper.x), atol=1e-12)
    finally:
        strategies._REGISTRY.pop("test_half_step", None)


def test_unknown_and_nameless_strategies_are_refused():
    pattern, mesh = hinge()
    with pytest.raises(SimulationError, match="unknown solver 'newton'"):
        Simulation(mesh, pattern, solver="newton")
    with pytest.raises(TypeError, match="name"):
        type("Nameless", (strategies.Strategy,), {})


def test_rigid_refuses_set_positions_and_keeps_its_state():
    pattern, mesh = hinge()
    sim = Simulation(mesh, pattern, solver="rigid")
    sim.step()
    x = sim.x.copy()
    with pytest.raises(SimulationError, match="cannot be set"):
        sim.set_positions(mesh.rest_positions)
    np.testing.assert_array_equal(sim.x, x)
