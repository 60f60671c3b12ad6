"""Hinge surface strain and fracture against the closed forms of foldcore.strain.

Tolerances: a single hinge actuated with exact arcs is compatible, so once
converged (step ≤ 1e-10 × extent) each sub-strip's shape is its target and
the strain matches the closed form to 1e-6 relative (the Eq. 9 estimate
inverts the target exactly); Eq. 8 see the test. Fracture: the paper's map
folds the strips gradually (45° in 730 iterations, 0.06° per iteration on
average, measured), so the first failing iteration's angle lies within about
one step of the closed-form failure angle; 0.1° is the bound asked of it.
"""
from __future__ import annotations

import json

import numpy as np
import pytest

from foldcore import patterns
from foldcore.errors import SimulationError
from foldcore.outputs import report_dict
from foldcore.simulation import Simulation
from foldcore.strain import StrainLimits
from foldcore.thickening import thicken

H, W, K = 1.0, 2.0, 4  # mm, mm, sub-strips


def hinge(angle: float, model: str, assignment: str = "V"):
    pattern = patterns.single_hinge(panel_length=5 * H, depth=10.0, angle=angle, width=W,
                                    assignment=assignment)
    return pattern, thicken(pattern, H, subdivisions=K, hinge=model)


@pytest.mark.parametrize("model", ["axis", "arc", "eq8"])
@pytest.mark.parametrize("angle", [60.0, -120.0])
def test_actuated_hinge_strain_matches_the_closed_form(model, angle):
    """Below θ* = 2·atan(W/H) = 126.9° the axis hinge's neutral axis is W·f(θ),
    f(θ) = (θ/2)/tan(θ/2): both faces also shorten by 1 − f."""
    pattern, mesh = hinge(angle, model, "V" if angle > 0 else "M")
    result = Simulation(mesh, pattern, solver="rigid").run(tolerance=1e-10, max_iterations=50)
    phi, ratio = np.radians(angle) / K, H / (W / K)
    bend = ratio * np.tan(0.5 * phi) if model == "eq8" else 0.5 * phi * ratio
    theta = K * phi
    axial = (theta / 2) / np.tan(theta / 2) - 1.0 if model == "axis" else 0.0
    # arcs are compatible: to the stopping tolerance; Eq. 8 trapezoids are not
    # (slanted end faces against a panel's square one): their outer sub-strips settle
    # O(φ²) away, bounded by (φ/2)² relative
    rtol = (0.5 * phi) ** 2 if model == "eq8" else 1e-6
    np.testing.assert_allclose(result.strip_strains[:, 1], axial + bend, rtol=rtol)
    np.testing.assert_allclose(result.strip_strains[:, 0], axial - bend, rtol=rtol)


THETA_F = 45.0  # degrees: the first-failure angle the limits below are chosen for


def eq8_limit(theta_f: float) -> float:
    """Eq. 8: |ε| = (kH/W)·tan(θ/2k) on both faces, so a limit ε fails at
    θ_f = 2k·atan(εW/(kH)); the limit that fails at ``theta_f`` degrees."""
    return (K * H / W) * np.tan(np.radians(theta_f) / (2 * K))


@pytest.mark.parametrize("assignment, side", [("V", "tension"), ("M", "compression")])
def test_first_failure_angle_matches_eq8(assignment, side):
    """The paper's iterations follow a quasi-static path and are checked one by one:
    the first failure is at θ_f to 0.1°."""
    limit = eq8_limit(THETA_F)
    sign = 1.0 if assignment == "V" else -1.0
    pattern, mesh = hinge(sign * 90.0, model="eq8", assignment=assignment)
    limits = StrainLimits(**{side: limit})
    sim = Simulation(mesh, pattern, solver="paper", strain_limits=limits)
    result = sim.run(tolerance=0, max_iterations=20_000,
                     callback=lambda s, moved: not s.result(False).failures)
    (failure,) = result.failures
    assert failure["edge"] == 0 and failure["mode"] == side
    assert abs(abs(failure["fold_angle_deg"]) - THETA_F) < 0.1
    assert abs(failure["strain"]) == pytest.approx(limit, rel=0.01)


def test_accelerated_strategy_finds_the_first_failure_by_a_fold_percent_sweep():
    """lbfgs is checked where each run ends (its iterates are not physical states), so
    a sweep of the target in 1 % steps of 90° finds θ_f within one step (0.9°) plus
    the converged hinge's own error (< 0.1°, either side: the 50 % step's target
    is θ_f itself, so the reported mean angle is θ_f ± that error)."""
    pattern, mesh = hinge(90.0, model="eq8", assignment="V")
    sim = Simulation(mesh, pattern, solver="lbfgs",
                     strain_limits=StrainLimits(tension=eq8_limit(THETA_F)))
    for percent in range(0, 101):
        sim.set_fold_percent(percent)
        result = sim.run(tolerance=1e-10, max_iterations=2_000)
        if result.failures:
            break
    (failure,) = result.failures
    assert failure["fold_percent"] == percent
    assert THETA_F - 0.1 <= failure["fold_angle_deg"] < THETA_F + 0.9 + 0.1


def test_no_failure_below_the_limits_and_report_lists_strains():
    pattern, mesh = hinge(30.0, model="arc")
    limits = StrainLimits(tension=1.0, compression=1.0)  # far above (H/W)·θ/2 = 0.26
    result = Simulation(mesh, pattern, solver="rigid", strain_limits=limits).run(
        tolerance=1e-10, max_iterations=50)
    assert result.failures == []
    report = json.loads(json.dumps(report_dict(result, pattern, mesh, {})))
    assert len(report["strip_strains"]["top"]) == K and report["failures"] == []


@pytest.mark.parametrize("bad", [StrainLimits(tension=0.0), StrainLimits(compression=-1),
                                 StrainLimits(tension=np.nan), (0.1, 0.1)])
def test_bad_limits_are_refused(bad):
    pattern, mesh = hinge(30.0, model="arc")
    with pytest.raises(SimulationError, match="strain"):
        Simulation(mesh, pattern, strain_limits=bad)


def test_render_can_colour_by_strain(tmp_path):
    pytest.importorskip("pyvista")
    from foldcore import scenes
    from foldcore.cli import main

    scenes.write(scenes.run("waterbomb", quick=True), tmp_path, png=False)
    out = tmp_path / "strain.png"
    assert main(["render", str(tmp_path / "waterbomb.fold"), "-o", str(out),
                 "--color-by", "strain", "--size", "320x240"]) == 0
    assert out.stat().st_size > 0


def test_accelerated_strategy_checks_limits_when_a_result_is_taken_after_bare_steps():
    """step() alone does not check (an lbfgs iterate is not a physical state); the
    state is checked when its result is taken: a hinge driven to 90° against a
    limit that fails at 45° is reported once the result is read."""
    pattern, mesh = hinge(90.0, model="eq8", assignment="V")
    sim = Simulation(mesh, pattern, solver="lbfgs",
                     strain_limits=StrainLimits(tension=eq8_limit(THETA_F)))
    for _ in range(300):
        sim.step()
    assert sim.failures == []
    (failure,) = sim.result(False).failures
    assert failure["mode"] == "tension" and failure["fold_angle_deg"] > THETA_F
