"""The rigid-body strategy's coarse start (strategies/rigid/twin.py): a run from rest
steps the one-strip twin first, then the mesh's own engine from the twin's state."""
from __future__ import annotations

import numpy as np
import pytest

from foldcore import patterns, thicken
from foldcore.simulation import Simulation
from foldcore.strategies.hybrid import HybridOptions
from foldcore.strategies.rigid import RigidOptions
from foldcore.strategies.rigid.twin import hand_over, twin_mesh

TOL = 1e-8


def miura(n=4, a=20.0):
    """Thin Miura n × n (H = 1e-3 a, W = 3H, 4 sub-strips per crease), one zig-zag
    crease driven to its angle at tilt 30°: (pattern, mesh, closed form, creases)."""
    h = 1e-3 * a
    pattern = patterns.miura_one_crease(n, n, a=a, b=a, width=3 * h)
    creases = np.flatnonzero(patterns.miura_edge_kinds(n, n) != "boundary")
    expected = patterns.miura_fold_angles(n, n, 60.0, 30.0)[creases]
    return pattern, thicken(pattern, h), expected, creases


def phase(sim) -> str:
    """"coarse" while the twin steps, else the strategy's phase."""
    rigid = sim.strategy.rigid if sim.solver == "hybrid" else sim.strategy
    return "coarse" if rigid is not None and rigid.twin is not None else sim.strategy.phase


def simulation(mesh, pattern, coarse: bool, solver: str = "hybrid"):
    """A simulation whose rigid phase starts on the coarse twin or not."""
    rigid = RigidOptions(coarse_start=coarse)
    options = rigid if solver == "rigid" else HybridOptions(rigid=rigid)
    return Simulation(mesh, pattern, solver=solver, options=options)


def fold(pattern, mesh, coarse: bool, **run):
    phases = []
    sim = simulation(mesh, pattern, coarse)
    result = sim.run(tolerance=TOL, callback=lambda s, moved: phases.append(phase(s)), **run)
    return sim, result, phases


def test_the_twin_has_one_strip_per_crease_and_the_same_panels():
    pattern, mesh, _, _ = miura()
    twin = twin_mesh(mesh, pattern)
    creases = mesh.subdivisions > 0
    assert (mesh.subdivisions[creases] == 4).all() and (twin.subdivisions[creases] == 1).all()
    assert np.array_equal(twin.hinge_width[creases], mesh.hinge_width[creases])

    def centroids(m):
        g, rest = m.groups["rigid_panel"], m.rest_positions
        return np.array([rest[g.indices[g.slots(p)]].mean(axis=0) for p in m.panel_of_face])

    assert np.allclose(centroids(twin), centroids(mesh), rtol=0, atol=1e-12 * 80.0)
    assert twin_mesh(twin, pattern) is None  # already one strip wide: no twin of its own


def test_a_fold_from_rest_steps_the_twin_and_ends_where_the_mesh_agrees():
    """Axis hinges: the twin's equilibrium is the mesh's, so the hand-over leaves every
    strip of the mesh on its bent shape (within the run's limit) and the run ends
    there, with no step of the mesh's own engine (no factorisation of its much
    larger normal matrix)."""
    pattern, mesh, expected, creases = miura()
    sim, result, phases = fold(pattern, mesh, True)
    assert result.converged
    assert phases[0] == "coarse" and "rigid" not in phases
    engine = sim.strategy.rigid_phase.engine
    assert engine.lm.factor is None  # the mesh's engine never stepped
    size = float(np.ptp(pattern.vertices, axis=0).max())
    residual = engine.residual.strip_rows(engine.x, engine.rot_e) \
        / engine.residual.sqrt_w[:, None, None]
    assert np.abs(residual).max() <= TOL * size
    # both models meet the closed form; 1e-6° is far above the tolerance's 1e-8 × size
    assert np.abs(result.fold_angles_deg[creases] - expected).max() < 1e-6
    # the positions are the mesh engine's, hinge interiors included (not the rest state)
    assert np.array_equal(sim.x, sim.strategy.rigid_phase.engine.x)
    assert np.abs(sim.x - mesh.rest_positions).max() > 1.0


def test_the_coarse_start_lands_where_the_mesh_alone_lands():
    pattern, mesh, _, _ = miura()
    alone, a, phases = fold(pattern, mesh, False)
    assert "coarse" not in phases
    coarse, b, _ = fold(pattern, mesh, True)
    size = float(np.ptp(pattern.vertices, axis=0).max())
    # two runs settled within TOL × size of one equilibrium: a few times that apart
    assert np.abs(a.positions - b.positions).max() < 100 * TOL * size
    assert np.nanmax(np.abs(a.fold_angles_deg - b.fold_angles_deg)) < 1e-5


def test_handing_over_places_the_hinge_interiors_on_their_strips():
    """After the twin's fold the mesh's strips are unstrained: the placed interiors
    (chained strip by strip from a panel) close on the far panel."""
    pattern, mesh, _, _ = miura(3)
    fine = simulation(mesh, pattern, False, solver="rigid")
    twin = Simulation(twin_mesh(mesh, pattern), pattern, solver="rigid", branch_floor_deg=0.0,
                      options=RigidOptions(coarse_start=False))
    assert twin.run(tolerance=1e-10).converged
    engine = fine.strategy.engine
    hand_over(twin.strategy.engine, engine)
    engine.residual.update_shapes(engine.phi)
    engine.residual.fit_rotations(engine.x, engine.rot_e)
    residual = engine.residual.strip_rows(engine.x, engine.rot_e)
    size = float(np.ptp(pattern.vertices, axis=0).max())
    # every strip row within 1e-10 × size (the twin's tolerance) of its target
    assert np.abs(residual / engine.residual.sqrt_w[:, None, None]).max() < 1e-10 * size


def test_an_interrupted_coarse_phase_ends_at_the_twins_state():
    pattern, mesh, _, _ = miura()
    sim = simulation(mesh, pattern, True)
    result = sim.run(tolerance=TOL, callback=lambda s, moved: s.iterations < 12)
    assert result.reason == "callback" and result.iterations == 12
    assert sim.strategy.rigid is None or sim.strategy.rigid.twin is None  # handed over
    assert np.abs(sim.x - mesh.rest_positions).max() > 1e-3  # moved off the rest state


def test_no_coarse_start_with_position_targets_or_from_a_state_the_mesh_reached():
    pattern, mesh, _, _ = miura(3)
    sim = simulation(mesh, pattern, True)
    sim.add_position_target([0])
    phases = []
    sim.run(tolerance=1e-6, callback=lambda s, m: phases.append(phase(s)))
    assert "coarse" not in phases
    sim = Simulation(mesh, pattern)  # (coarse start on: the default)
    sim.add_position_target([0], name="pin")
    assert sim.run(tolerance=1e-6).converged  # the mesh's own steps
    sim.remove_position_target("pin")
    sim.set_fold_percent(80.0)
    phases = []
    sim.run(tolerance=1e-6, callback=lambda s, m: phases.append(phase(s)))
    assert phases and "coarse" not in phases


def run_phases(sim, percent, tolerance=TOL):
    sim.set_fold_percent(percent)
    phases = []
    result = sim.run(tolerance=tolerance, callback=lambda s, m: phases.append(phase(s)))
    return result, phases


def test_a_run_after_the_twins_certified_hand_over_goes_on_on_the_twin():
    """A sweep's next frame starts where the twin handed over (the mesh has not moved
    since): it steps the twin again, predictor included, and ends at the mesh's
    equilibrium as the mesh's own steps find it."""
    pattern, mesh, expected, creases = miura(3)
    size = Simulation(mesh, pattern).length_scale
    runs = {}
    for coarse in (False, True):
        sim = simulation(mesh, pattern, coarse)
        first, _ = run_phases(sim, 40.0)
        second, phases = run_phases(sim, 45.0)
        assert sim.predict(1.0)  # the last two ends: 40 %, 45 %
        third, phases3 = run_phases(sim, 50.0)
        assert first.converged and second.converged and third.converged
        assert ("coarse" in phases and "coarse" in phases3) == coarse
        runs[coarse] = (second, third)
    for plain, twin in zip(runs[False], runs[True]):
        # each within the run's limit of the one equilibrium
        assert np.abs(twin.positions - plain.positions).max() < 2 * TOL * size
    angles = runs[True][1].fold_angles_deg[creases]
    half = patterns.miura_fold_angles(3, 3, 60.0, 30.0)[creases] * 0.5
    assert np.isfinite(angles).all() and np.sign(angles).tolist() == np.sign(half).tolist()


def test_the_twin_is_left_once_the_mesh_moves_on_its_own():
    """After a certified hand-over, positions the mesh reached otherwise (here a bare
    step of the finishing strategy) start the next run on the mesh itself."""
    pattern, mesh, _, _ = miura(3)
    sim = simulation(mesh, pattern, True)
    run_phases(sim, 40.0)
    sim.set_fold_percent(45.0)
    sim.step()
    _, phases = run_phases(sim, 45.0)
    assert phases and "coarse" not in phases


@pytest.mark.parametrize("solver", ["rigid", "hybrid"])
def test_a_binding_vertex_settles_from_the_twin_as_from_rest(solver):
    """W/H = 0.3: the hinge model binds 2.7° short of the closed form; with k sub-strips
    its equilibrium is not the twin's, and the mesh's own steps finish the run."""
    pattern = patterns.degree4_vertex(radius=10.0, widths=[0.3 * 0.01] * 4, mode="A", rho1=70.0)
    mesh = thicken(pattern, 0.01)
    results, phases = [], []
    for coarse in (False, True):
        sim = simulation(mesh, pattern, coarse, solver=solver)
        results.append(sim.run(tolerance=TOL, max_iterations=500,
                               callback=lambda s, moved: phases.append(phase(s))))
    assert all(r.converged for r in results)
    # its strips do not meet their shapes at the hand-over: the mesh's steps follow it
    assert phases[phases.index("coarse"):].count("rigid") >= 1
    assert np.nanmax(np.abs(results[0].fold_angles_deg - results[1].fold_angles_deg)) < 1e-4


def test_a_fold_from_rest_frees_its_twins_factor_and_a_sweep_keeps_it():
    """The twin's normal factor is freed at the certified hand-over of a run from rest
    (the mesh's certificate needs the memory at that peak); a sweep's next frames
    build it once more and keep it (their steps reuse the analysis)."""
    pattern, mesh, _, _ = miura(3)
    sim = simulation(mesh, pattern, True)
    first, _ = run_phases(sim, 40.0)
    rigid = sim.strategy.rigid_phase
    assert first.converged and rigid.kept_twin and rigid.kept_twin.engine.lm.factor is None
    second, phases = run_phases(sim, 45.0)
    assert second.converged and "coarse" in phases
    assert rigid.kept_twin.engine.lm.factor is not None
