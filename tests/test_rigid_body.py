"""The rigid-body strategy: few iterations whatever the panel length, a true descent.

Tolerances: a single actuated hinge is a compatible target (a zero-energy
state exists), so the fold-angle error is bounded by the stopping rule
(step ≤ 1e-10 × extent); 0.01° is the accuracy asked of every fold. The
iteration bound (50) is the algorithm's property being tested — the paper's
map needs > 10⁴ iterations on these scenes. The Jacobian check
uses a forward difference with ε = 1e-6 (truncation O(ε) relative).
"""
from __future__ import annotations

import json

import numpy as np
import pytest

from foldcore import kinematics, patterns
from foldcore.cli import main
from foldcore.io import write_fold
from foldcore.simulation import Simulation
from foldcore.strategies.rigid import RigidOptions
from foldcore.strategies.rigid.residual import mv_side as mv_side_shape
from foldcore.thickening import thicken

from rigid_reference import apply, jacobian

H = 1.0  # mm


def long_hinge(ratio: float, angle: float = 90.0, assignment: str = "V"):
    pattern = patterns.single_hinge(panel_length=ratio * H, depth=10.0, angle=angle,
                                    width=2.0, assignment=assignment)
    return pattern, thicken(pattern, H, subdivisions=4)


@pytest.mark.parametrize("ratio", [5, 80, 320])
def test_long_panels_fold_in_few_iterations(ratio):
    pattern, mesh = long_hinge(ratio)
    result = Simulation(mesh, pattern, solver="rigid").run(tolerance=1e-10, max_iterations=50)
    assert result.converged
    assert abs(result.fold_angles_deg[0] - 90.0) < 0.01


def test_mountain_fold_and_panels_stay_rigid():
    pattern, mesh = long_hinge(20, angle=-135.0, assignment="M")
    sim = Simulation(mesh, pattern, solver="rigid")
    result = sim.run(tolerance=1e-10, max_iterations=50)
    assert abs(result.fold_angles_deg[0] + 135.0) < 0.01
    panels = mesh.groups["rigid_panel"]
    for p in range(len(panels)):  # rigid bodies by construction: edge lengths exact
        ids = panels.indices[panels.slots(p)]
        rest = mesh.rest_positions[ids]
        now = result.positions[ids]
        np.testing.assert_allclose(np.linalg.norm(now - now[0], axis=1),
                                   np.linalg.norm(rest - rest[0], axis=1), atol=1e-9)


def thin_vertex(mode="A", rho1=60.0):
    pattern = patterns.degree4_vertex(radius=10.0, widths=[0.02] * 4, mode=mode, rho1=rho1)
    return pattern, thicken(pattern, 0.01, subdivisions=4)


def test_energy_never_increases_on_a_closed_loop():
    pattern, mesh = thin_vertex()
    result = Simulation(mesh, pattern, solver="rigid").run(tolerance=0, max_iterations=30)
    energy = result.energy
    assert np.all(np.diff(energy) <= 1e-12 * energy[0])
    assert energy[-1] < 0.05 * energy[0]


def test_jacobian_matches_finite_differences():
    pattern, mesh = thin_vertex()
    sim = Simulation(mesh, pattern, solver="rigid")
    for _ in range(5):  # away from the flat state
        sim.step()
    solver = sim.strategy.engine
    lay = solver.layout
    start = solver.state()
    jac, res = jacobian(solver, start)
    rng = np.random.default_rng(1)
    eps = 1e-6
    blocks = {"panels": (0, lay.rot_col), "rotations": (lay.rot_col, lay.phi_col),
              "angles": (lay.phi_col, lay.n_unknowns)}
    for name, (a, b) in blocks.items():
        direction = np.zeros(lay.n_unknowns)
        direction[a:b] = rng.normal(size=b - a)
        _, moved = jacobian(solver, apply(solver, start, eps * direction))
        linear = jac @ direction
        error = np.abs((moved - res) / eps - linear).max() / np.abs(linear).max()
        assert error < 1e-3, name


def test_thin_vertex_panels_close_the_spherical_loop():
    # all four creases actuated to the closed form: the rigid panels' measured
    # angles must satisfy the degree-4 relation (a rigid loop closes), and the
    # run converges in few iterations despite R/H = 1000
    pattern, mesh = thin_vertex()
    rho = kinematics.degree4_deg(135.0, 90.0, 60.0, "A")
    sim = Simulation(mesh, pattern, solver="rigid")
    sim.set_fold_angles({i: rho[i] for i in range(4)})
    result = sim.run(tolerance=1e-10, max_iterations=100)
    assert result.converged
    measured = result.fold_angles_deg[:4]
    expected = kinematics.degree4_deg(135.0, 90.0, measured[0], "A")
    np.testing.assert_allclose(measured, expected, atol=0.02)


def test_cli_solver_option(tmp_path):
    pattern, _ = long_hinge(80)
    src = tmp_path / "hinge.fold"
    write_fold(src, pattern, thickness=H)
    report = tmp_path / "r.json"
    assert main(["simulate", str(src), "--solver", "rigid", "--subdivisions", "4",
                 "--tolerance", "1e-10", "--report", str(report)]) == 0
    data = json.loads(report.read_text())
    assert data["converged"] and data["iterations"] <= 50
    assert abs(data["fold_angles_deg"][0] - 90.0) < 0.01
    assert set(data["timings_s"]) >= {"setup", "projection", "solve", "total"}
    assert main(["simulate", str(src), "--solver", "steepest"]) == 2  # not a strategy


@pytest.mark.parametrize("accepted, ratio, factor", [
    (True, 1.0, 1 / 3),           # the model was exact: λ falls by lambda_down
    (True, 0.5, 1.0),             # half right: λ stays
    (True, 0.0, 2.0),             # no gain although accepted: λ doubles
    (True, float("nan"), 1.0),    # predicted decrease rounded to 0: no verdict
    (False, -10.0, 5.0),          # rejected: × lambda_up, whatever ρ
])
def test_damping_follows_the_gain_ratio(accepted, ratio, factor):
    options = RigidOptions()
    assert (options.lambda_down, options.lambda_up) == (3.0, 5.0)  # the table's factors
    pattern, mesh = long_hinge(5)
    lm = Simulation(mesh, pattern, solver="rigid").strategy.engine.lm
    lm.lam, lm.accepted, lm.gain_ratio = 1e-6, accepted, ratio
    lm.update_damping()
    assert lm.lam == pytest.approx(1e-6 * factor, rel=1e-12)


def test_a_step_reports_its_gain_ratio_and_damped_share():
    pattern, mesh = thin_vertex()
    sim = Simulation(mesh, pattern, solver="rigid")
    lm = sim.strategy.engine.lm
    for _ in range(5):
        sim.step()
        assert 0.0 <= lm.damped_share <= 1.0  # ‖Jv‖² and 2λvᵀDv are both ≥ 0
        if lm.accepted:  # E fell, the model predicted a fall: ρ ≥ 0
            assert lm.gain_ratio >= 0.0


def test_mv_side_rows_are_continuous_through_a_flat_fold():
    """An M/V side row's shape g(t), t the dihedral signed toward the assigned side:
    0 on that side, t + slack crossing it, and 0 again at t = ±π (one dihedral: a
    flat fold), continuous on the circle, its slope the derivative."""
    options = RigidOptions()
    MV_SLACK = options.mv_slack

    def mv_side(t):
        return mv_side_shape(t, options.mv_wall, MV_SLACK)

    assigned = np.array([-0.5 * MV_SLACK, 0.0, 1.0, np.pi - 1e-12, np.pi])
    value, slope = mv_side(assigned)
    assert not value.any() and not slope.any()
    value, slope = mv_side(np.array([-0.1]))
    assert value[0] == pytest.approx(-0.1 + MV_SLACK, rel=1e-12) and slope[0] == 1.0
    past_flat = mv_side(np.array([-np.pi + 1e-9]))[0]
    assert abs(past_flat[0]) <= 2e-9  # not √μ·(−π): a valley a hair past flat
    t = np.linspace(-np.pi + 1e-6, np.pi, 20001)
    value, slope = mv_side(t)
    assert np.abs(np.diff(value)).max() <= 1.01 * (t[1] - t[0])  # no jump anywhere
    h = 1e-7
    for point in (-0.3, -2.0, -3.0):
        numeric = (mv_side(np.array([point + h]))[0] - mv_side(np.array([point - h]))[0]) / (2 * h)
        assert numeric[0] == pytest.approx(mv_side(np.array([point]))[1][0], rel=1e-6)


def test_shape_derivatives_are_the_central_difference_of_the_bent_shapes():
    """dT/dφ, computed on demand, is bent_shapes' central difference over
    ``SHAPE_STEP`` bit for bit, agrees with one over 1e-4 rad to its truncation
    (~1e-8·W), and follows a new angle."""
    from elements.bending_hinge import SHAPE_STEP

    pattern, mesh = long_hinge(4.0, angle=70.0)
    engine = Simulation(mesh, pattern, solver="rigid").strategy.engine
    residual = engine.residual
    phi = np.linspace(0.3, 1.1, len(engine.layout.ids))

    def shape_at(angles):
        residual.update_shapes(angles)
        return residual.shape.copy()

    exact = (shape_at(phi + SHAPE_STEP) - shape_at(phi - SHAPE_STEP)) / (2.0 * SHAPE_STEP)
    coarse = (shape_at(phi + 1e-4) - shape_at(phi - 1e-4)) / 2e-4
    residual.update_shapes(phi)
    d_shape = residual.shape_derivatives().copy()
    assert np.array_equal(d_shape, exact)
    width = float(np.nanmax(mesh.hinge_width))
    assert np.abs(coarse - d_shape).max() < 1e-6 * width
    residual.update_shapes(phi - 1e-4)  # a new angle makes the kept derivative stale
    assert not np.array_equal(residual.shape_derivatives(), d_shape)
