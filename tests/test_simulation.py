"""Simulation core: actuation reaches its targets, constraints hold, runs are deterministic.

Scenes are short-panel single hinges (panel length 5 H) where the paper's plain
iteration converges in ~10⁴ iterations. Units: mm, degrees.

Tolerances: a converged exact-arc hinge is a compatible target (zero-energy
state exists), so the achieved angle is limited only by the stopping rule
(step ≤ 1e-9 × extent): measured errors are ~3e-4°, the acceptance bound is
0.05°. Rigid panels at a compatible state are undeformed up to the same
stopping rule: 1e-6 relative on edge lengths.
"""
from __future__ import annotations

import numpy as np
import pytest

from foldcore import SimulationError, patterns
from foldcore.simulation import Simulation
from foldcore.thickening import thicken

H = 1.0          # mm
PANEL = 5.0 * H  # panel length from the crease line, mm
WIDTH = 2.0      # hinge width, mm (2k·atan(W/kH) = 212° ≥ 180° for k = 4)


def hinge(angle=None, assignment="V", max_angle=180.0, model=None, k=4):
    pattern = patterns.single_hinge(panel_length=PANEL, depth=2.0, angle=angle,
                                    assignment=assignment, width=WIDTH, max_angle=max_angle)
    return pattern, thicken(pattern, H, subdivisions=k, hinge=model)


def converge(sim, max_iterations=60_000, **kw):
    result = sim.run(tolerance=1e-9, max_iterations=max_iterations, **kw)
    assert result.converged, f"not converged after {result.iterations} iterations"
    return result


@pytest.mark.parametrize("target", [30.0, 90.0, 150.0, 180.0])
def test_single_hinge_reaches_target(target):
    pattern, mesh = hinge(angle=target)
    result = converge(Simulation(mesh, pattern))
    assert abs(result.fold_angles_deg[0] - target) < 0.05
    # each sub-strip carries its share of the target
    np.testing.assert_allclose(result.strip_angles_deg, target / 4, rtol=1e-12)


def test_mountain_target_is_negative_fold():
    pattern, mesh = hinge(angle=-120.0, assignment="M")
    result = converge(Simulation(mesh, pattern))
    assert abs(result.fold_angles_deg[0] + 120.0) < 0.05


def test_energy_never_increases_with_fixed_targets():
    # local step minimises over targets, global step over positions: E must not grow
    pattern, mesh = hinge(angle=90.0)
    result = Simulation(mesh, pattern).run(tolerance=0, max_iterations=2000)
    energy = result.energy
    assert np.all(np.diff(energy) <= 1e-12 * energy[0])
    assert energy[-1] < 0.1 * energy[0]  # and it does decrease


def test_rigid_panels_keep_their_edge_lengths():
    pattern, mesh = hinge(angle=90.0)
    result = converge(Simulation(mesh, pattern))
    panels = mesh.groups[mesh.panel_group]
    rest = mesh.rest_positions
    for e in range(len(panels)):
        ids = panels.indices[panels.slots(e)]
        n = len(ids) // 2
        ring = np.r_[np.arange(n), np.arange(n)]
        pairs = [(ids[i], ids[(i + 1) % n]) for i in range(n)]            # top
        pairs += [(ids[n + i], ids[n + (i + 1) % n]) for i in range(n)]  # bottom
        pairs += [(ids[i], ids[n + i]) for i in ring[:n]]                 # vertical
        a, b = np.array(pairs).T
        before = np.linalg.norm(rest[a] - rest[b], axis=1)
        after = np.linalg.norm(result.positions[a] - result.positions[b], axis=1)
        np.testing.assert_allclose(after, before, rtol=1e-6)


def test_fold_percent_scales_targets():
    pattern, mesh = hinge(angle=90.0)
    sim = Simulation(mesh, pattern)
    sim.set_fold_percent(50.0)
    assert abs(converge(sim).fold_angles_deg[0] - 45.0) < 0.05


def test_set_fold_angles_changes_target_mid_run():
    pattern, mesh = hinge(angle=90.0)
    sim = Simulation(mesh, pattern)
    sim.run(tolerance=0, max_iterations=500)
    sim.set_fold_angles({0: 60.0})
    assert abs(converge(sim).fold_angles_deg[0] - 60.0) < 0.05


def test_changed_targets_reach_the_prepared_bent_shapes():
    """After set_fold_angles / set_fold_percent mid-run, one step from the same x is
    bit for bit the step of a simulation built with those targets (no stale shapes)."""
    pattern, mesh = hinge(angle=90.0)
    sim = Simulation(mesh, pattern, solver="paper")
    sim.run(tolerance=0, max_iterations=50)
    sim.set_fold_angles({0: 60.0})
    sim.set_fold_percent(50.0)
    fresh = Simulation(mesh, pattern.replace(fold_angles=np.where(
        np.isnan(pattern.fold_angles), np.nan, 60.0)), solver="paper")
    fresh.set_fold_percent(50.0)
    fresh.set_positions(sim.positions)
    sim.step()
    fresh.step()
    np.testing.assert_array_equal(sim.positions, fresh.positions)


def _pull_far_panel(sim, angle_deg, alpha=1.0, decay=1.0):
    """Pin the left panel's far end; pull the right panel's far end to ``angle_deg``
    rotated about the crease (valley > 0 lifts it)."""
    x = sim.positions
    sim.add_position_target(np.flatnonzero(x[:, 0] < -0.6 * PANEL), name="pin")
    far = np.flatnonzero(x[:, 0] > 0.98 * PANEL)
    pivot = np.array([WIDTH / 2, 0.0, 0.0])
    t = np.radians(angle_deg)
    rot = np.array([[np.cos(t), 0, -np.sin(t)], [0, 1, 0], [np.sin(t), 0, np.cos(t)]])
    sim.add_position_target(far, (x[far] - pivot) @ rot.T + pivot, alpha=alpha,
                            decay=decay, name="pull")


@pytest.mark.parametrize("solver", ["paper", "lbfgs", "hybrid"])
def test_passive_creases_fold_on_their_assigned_side(solver):
    """Degree-4 vertex, crease 1 actuated to 60°, creases 2–4 passive (V, V, M).

    The flat state is a bifurcation; M/V must select the branch from the first
    iteration on. Strip angles used are on the right side by construction
    (§4.2 projection); with the paper's small steps the panels' measured
    angles may dip past flat only by the elastic slack of the first
    iterations: bound 0.1° on every iterate. L-BFGS's long early steps
    overshoot further (measured 0.38°), so for it (and for ``hybrid``, whose
    rigid phase holds the panels' M/V sides itself) the bound holds where the
    run ends.
    """
    pattern = patterns.degree4_vertex(radius=10.0, widths=[2.0] * 4, rho1=60.0)
    mesh = thicken(pattern, H, subdivisions=4)
    sign = np.where(pattern.assignments[:4] == "V", 1.0, -1.0)
    worst = np.full(4, np.inf)

    def track(sim, moved):
        np.minimum(worst, sign * sim.fold_angles()[:4], out=worst)

    sim = Simulation(mesh, pattern, solver=solver)
    sim.run(tolerance=0, max_iterations=3000, callback=track if solver == "paper" else None)
    if solver == "paper":
        assert worst.min() > -0.1
    assert np.all(sign * sim.fold_angles()[:4] > 5.0)   # on its side, and folding


def test_passive_hinge_stays_valley_when_pulled_up():
    pattern, mesh = hinge(assignment="V")
    sim = Simulation(mesh, pattern)
    _pull_far_panel(sim, 60.0)
    worst = []
    sim.run(tolerance=1e-9, max_iterations=5000,
            callback=lambda s, moved: worst.append(s.fold_angles()[0]))
    assert min(worst) > -1e-6
    assert np.all(sim.strip_angles() >= 0.0)


def test_passive_hinge_folds_on_its_side_when_pulled():
    pattern, mesh = hinge(assignment="V")
    sim = Simulation(mesh, pattern)
    _pull_far_panel(sim, 60.0)
    result = sim.run(tolerance=1e-9, max_iterations=5000)
    assert result.fold_angles_deg[0] > 55.0


def test_max_angle_holds_against_a_pull_beyond_it():
    """θmax = 90°, the target pulls toward 120° with the §3.2 α schedule (α: 1 → 0)."""
    pattern, mesh = hinge(assignment="V", max_angle=90.0)
    sim = Simulation(mesh, pattern)
    _pull_far_panel(sim, 120.0, alpha=1.0, decay=0.99)
    result = converge(sim)
    assert 88.0 < result.fold_angles_deg[0] <= 90.5
    assert np.all(np.abs(result.strip_angles_deg) <= 90.0 / 4 + 1e-12)


def test_results_identical_with_one_and_two_threads():
    import numba

    if numba.config.NUMBA_NUM_THREADS < 2:
        pytest.skip("numba was started with fewer than 2 threads")
    pattern = patterns.degree4_vertex(rho1=60.0)
    mesh = thicken(pattern, 2.0)
    runs = []
    for threads in (1, 2):
        sim = Simulation(mesh, pattern, threads=threads)
        sim.run(tolerance=0, max_iterations=300)
        runs.append(sim.positions.copy())
    numba.set_num_threads(numba.config.NUMBA_NUM_THREADS)
    scale = np.abs(runs[0]).max()
    assert np.abs(runs[0] - runs[1]).max() <= 1e-12 * scale


def test_position_target_can_be_moved_and_removed():
    pattern, mesh = hinge(assignment="U")
    sim = Simulation(mesh, pattern)
    corner = sim.nearest_vertex([PANEL, 2.0, H / 2])
    name = sim.add_position_target([corner], alpha=1.0)
    sim.move_position_target(name, sim.positions[corner] + [0.0, 0.0, 0.5])
    sim.run(tolerance=0, max_iterations=50)
    assert sim.positions[corner, 2] > H / 2
    sim.remove_position_target(name)
    assert not sim.model.position_targets


@pytest.mark.parametrize("call, message", [
    (lambda s: s.set_fold_angles({0: -30.0}), "not allowed"),
    (lambda s: s.set_fold_angles({1: 30.0}), "boundary"),
    (lambda s: s.set_fold_angles({99: 30.0}), "does not exist"),
    (lambda s: s.set_fold_percent(150.0), "fold percent"),
    (lambda s: s.add_position_target([10**6]), "vertex ids"),
    (lambda s: s.add_position_target([0], alpha=-1.0), "alpha"),
])
def test_bad_actuation_is_refused_clearly(call, message):
    pattern, mesh = hinge(angle=30.0)
    sim = Simulation(mesh, pattern)
    with pytest.raises(SimulationError, match=message):
        call(sim)


def test_unknown_solver_is_refused():
    pattern, mesh = hinge(angle=30.0)
    with pytest.raises(SimulationError, match="unknown solver"):
        Simulation(mesh, pattern, solver="magic")


def test_scipy_fallback_matches_cholmod():
    from foldcore.linsolve import cholmod_available

    if not cholmod_available():
        pytest.skip("scikit-sparse not installed")
    pattern, mesh = hinge(angle=90.0)
    a = Simulation(mesh, pattern, backend="cholmod").run(tolerance=0, max_iterations=200)
    b = Simulation(mesh, pattern, backend="scipy").run(tolerance=0, max_iterations=200)
    assert np.abs(a.positions - b.positions).max() <= 1e-9 * PANEL


def test_branch_stage_runs_from_flat_only_and_releases_its_floor():
    """Pehrson's vertex (mode A) driven to 3°: its passive creases' closed-form
    angles are 1.24° and 3°, partly under the 2° floor of the branch stage; the
    run starts with that stage (from flat, a crease driven) and ends on the closed
    form after releasing it. Continuing from the folded state has no stage, and
    nothing driven (0 %) has none either."""
    from foldcore import kinematics

    pattern = patterns.degree4_vertex(radius=10.0, widths=[0.03] * 4, rho1=3.0)
    mesh = thicken(pattern, 0.01)
    sim = Simulation(mesh, pattern)
    result = sim.run(tolerance=1e-10, max_iterations=2_000)
    closed = kinematics.degree4_deg(135.0, 90.0, 3.0, "A")
    assert 0 < sim.branch_iterations < result.iterations
    assert np.abs(result.fold_angles_deg[:4] - closed).max() < 1e-4
    sim.set_fold_angles({0: 6.0})
    before = sim.branch_iterations
    sim.run(tolerance=1e-10, max_iterations=2_000)
    assert sim.branch_iterations == before
    flat = Simulation(mesh, pattern)
    flat.set_fold_percent(0.0)
    flat.run(tolerance=1e-10, max_iterations=50)
    assert flat.branch_iterations == 0
    assert np.abs(flat.fold_angles()[:4]).max() < 1e-6


def test_angle_actuation_stiffens_the_actuated_strips_only():
    """actuation="angle": actuated strips weigh ACTUATION_STIFFNESS × their volume,
    passive ones their volume; making a crease passive drops its factor."""
    from foldcore.actuation import ACTUATION_STIFFNESS

    pattern = patterns.degree4_vertex(rho1=40.0)
    mesh = thicken(pattern, 2.0)
    g = mesh.groups["bending_hinge"]
    sim = Simulation(mesh, pattern, actuation="angle")
    weights = sim.system.weights[sim.model.hinge_index]
    np.testing.assert_array_equal(weights, np.where(g.source == 0, ACTUATION_STIFFNESS, 1.0)
                                  * g.weights)
    sim.set_fold_angles({0: None})
    np.testing.assert_array_equal(sim.system.weights[sim.model.hinge_index], g.weights)
    equal = Simulation(mesh, pattern)
    np.testing.assert_array_equal(equal.system.weights[equal.model.hinge_index], g.weights)
    with pytest.raises(SimulationError, match="unknown actuation 'motor'"):
        Simulation(mesh, pattern, actuation="motor")


def test_k_is_factorised_at_its_first_use_and_then_matches_the_current_weights():
    """The rigid-body model asked for by name never solves with K: it is not
    factorised (and the run reports no bare-solve time). Weights and pins changed
    before the first use are in the factor that use builds, as in one built from
    them at once."""
    from foldcore.linsolve import Factor

    pattern = patterns.degree4_vertex(radius=10.0, widths=[0.03] * 4, rho1=40.0)
    mesh = thicken(pattern, 0.01)
    sim = Simulation(mesh, pattern, solver="rigid")
    result = sim.run(tolerance=1e-8)
    assert result.converged and not sim.system.factored
    assert "bare_solve" not in result.timings_s
    sim = Simulation(mesh, pattern, solver="lbfgs")
    sim.add_position_target([3], alpha=2.0)  # new pins before K's first use
    sim.set_fold_percent(50.0)
    assert not sim.system.factored
    result = sim.run(tolerance=0, max_iterations=2)
    assert sim.system.factored and result.timings_s["bare_solve"] > 0
    rhs = np.random.default_rng(3).standard_normal((mesh.n_vertices, 3))
    fresh = Factor(sim.system.with_pins(), sim.system.backend)
    np.testing.assert_allclose(sim.system.factor.solve(rhs), fresh.solve(rhs), rtol=1e-10,
                               atol=1e-12 * np.abs(fresh.solve(rhs)).max())


def settle(sim, max_iterations=3_000):
    """A run that ends at a state its strategies cannot leave: converged, or stalled
    where the equilibrium certificate refuses it."""
    result = sim.run(tolerance=1e-9, max_iterations=max_iterations)
    assert result.reason in ("converged", "stalled"), result.reason
    return result


def test_the_result_says_how_far_each_position_target_is_and_why():
    """The left panel held, a right corner lifted where the hinge can take it: met
    (stopped_by None); pulled away in the sheet's plane, which would stretch the
    rigid panels and the hinge: a compromise with them ("pull"). The rigid phase's
    equilibrium is not the mesh's (its elastic panels give 0.014 mm to the pull), and
    ``newton``, which goes on from it, stops where no damping lowers E while the
    passive hinge's Eq. 9 target still leaves a lower state: the run says
    ``stalled`` rather than ``converged`` (docs/architecture.md#the-equilibrium-certificate);
    what the result says of the targets holds either way."""
    pattern, mesh = hinge(assignment="U")
    sim = Simulation(mesh, pattern)
    x = sim.positions
    sim.add_position_target(np.flatnonzero(x[:, 0] < -0.6 * PANEL), name="held")
    corner = sim.nearest_vertex([PANEL, 2.0, H / 2])
    sim.add_position_target([corner], x[corner] + [0.0, 0.0, 0.5], name="lift")
    met = {t["name"]: t for t in settle(sim).position_targets}
    assert met["lift"]["vertices"] == 1 and met["lift"]["stopped_by"] is None
    assert met["held"]["stopped_by"] is None
    sim.move_position_target("lift", x[corner] + [2.0, 0.0, 0.0])
    pulled = {t["name"]: t for t in settle(sim).position_targets}
    assert pulled["lift"]["stopped_by"] == "pull" and 0.1 < pulled["lift"]["miss_mm"] < 2.0
    assert Simulation(mesh, pattern).run(max_iterations=2).position_targets is None
