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
            old = self.model.x
            energy, moved = super().step()
            self.model.x = 0.5 * (old + self.model.x)
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
        strategies.unregister("test_half_step")


def test_unknown_and_nameless_strategies_are_refused():
    pattern, mesh = hinge()
    with pytest.raises(SimulationError, match="unknown solver 'steepest'"):
        Simulation(mesh, pattern, solver="steepest")
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


def rings_waterbomb(cell_mm: float):
    """The 6-crease waterbomb (R = 30 mm, H = 0.5 mm) with every crease driven to ±40°
    (no rigid folding motion has them equal) and every face elastic, in rings."""
    pattern = patterns.waterbomb(radius=30.0, width=1.0)
    angles = np.full(pattern.n_edges, np.nan)
    angles[:6] = np.where(np.arange(6) % 2 == 0, -40.0, 40.0)
    pattern = pattern.replace(fold_angles=angles)
    return pattern, thicken(pattern, 0.5, subdivisions=2, elastic="facets", cell_size=cell_mm)


def test_hybrid_on_elastic_rings_starts_rigid_and_finishes_with_newton():
    """On faces in rings ``hybrid`` steps the rigid-panel twin from rest, places the
    cells on it and finishes with Gauss–Newton: converged at a minimum of E in a
    3-fold symmetric state. No crease reaches its ±40° (no rigid folding motion has
    them equal), so E has two minima, images of each other under the pattern's
    symmetry (sheet turned over, one crease round: every angle negated, the targets
    carried onto themselves), and a 6-fold symmetric saddle between them (every
    crease at ±9.08°, E = 0.833 mm⁵, 2.7× the minima). Which minimum a run reaches is
    decided by rounding off that saddle, so the check is against Newton's minimum
    under the symmetry: the same E to rounding and the same angles within 1e-6°.
    L-BFGS does not get lower (it can stall on the saddle: 40 000 iterations
    there on one machine). The stretch hinge is refused by name."""
    pattern, mesh = rings_waterbomb(5.0)
    sim = Simulation(mesh, pattern, solver="hybrid")
    phases = []
    result = sim.run(tolerance=1e-9, max_iterations=5_000,
                     callback=lambda s, moved: phases.append(s.strategy.phase))
    assert result.converged and isinstance(sim.strategy.finish, strategies.get("newton"))
    assert phases[0] == "rigid" and phases[-1] == "newton"
    angles = result.fold_angles_deg[:6]
    np.testing.assert_allclose(angles[::2], angles[0], atol=1e-6)
    np.testing.assert_allclose(angles[1::2], angles[1], atol=1e-6)
    newton = Simulation(mesh, pattern, solver="newton").run(tolerance=1e-9,
                                                            max_iterations=500)
    assert newton.converged
    np.testing.assert_allclose(result.energy[-1], newton.energy[-1], rtol=1e-9)
    reached = newton.fold_angles_deg[:6]
    images = (reached, -np.roll(reached, 1))  # itself, and turned over one crease round
    assert min(np.abs(angles - image).max() for image in images) <= 1e-6
    lbfgs = Simulation(mesh, pattern, solver="lbfgs").run(tolerance=1e-9,
                                                          max_iterations=2_000)
    assert lbfgs.energy[-1] >= result.energy[-1] * (1 - 1e-9)
    plain = patterns.waterbomb(radius=30.0, width=1.0)
    stretchy = thicken(plain, 0.5, subdivisions=2, stretch={0: 0.3})
    with pytest.raises(SimulationError, match="solver 'newton' takes"):
        Simulation(stretchy, plain, solver="newton")


def test_newton_at_met_targets_settles_on_rounding():
    """Every target met where the run starts (fold percent 0, at rest): E is at
    rounding level, no step can lower it, and the run settles (without the energy
    floor each step rejected 17 factorisations and the run took its budget)."""
    pattern, mesh = rings_waterbomb(10.0)
    sim = Simulation(mesh, pattern, solver="newton")
    sim.set_fold_percent(0.0)
    result = sim.run(tolerance=1e-9, max_iterations=200)
    assert result.converged and result.iterations < 200
    assert np.abs(result.positions - mesh.rest_positions).max() <= 1e-9 * sim.length_scale


def test_newton_hessian_in_its_fixed_pattern_is_the_direct_sum():
    """The fixed-pattern assembly (one bincount into the lower triangle) gives the
    Gauss–Newton H = K ⊗ I₃ − Σ w Q Qᵀ summed densely element by element, to
    rounding, at a folded state (no entry of the pattern dropped as zero)."""
    pattern, mesh = rings_waterbomb(10.0)
    sim = Simulation(mesh, pattern, solver="newton")
    sim.run(tolerance=0, max_iterations=3)
    newton = sim.strategy
    _, _ = sim.model.local_step(sim.x)
    values = newton.hessian(sim.model.slot_targets)
    lower = newton.hessian_pattern.matrix(values, 0.0).toarray()
    dense = np.kron(sim.system.with_pins().toarray(), np.eye(3))
    for ids, weights, basis in newton.rotation_bases(sim.model.slot_targets):
        for v, w, q in zip(ids, weights, basis):
            dof = (3 * v[:, None] + np.arange(3)).ravel()
            dense[np.ix_(dof, dof)] -= w * q @ q.T
    scale = np.abs(dense).max()
    np.testing.assert_allclose(lower, np.tril(dense), atol=1e-12 * scale, rtol=0)
