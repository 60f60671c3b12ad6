"""`converged` means the fold was reached (issue 18's first item, for the rigid-body
strategies): a stall of small steps is not a verdict.

Reproducer: a thin Miura from flat, one crease driven. Its hinges are so stiff
against the sheet's size that Levenberg–Marquardt leaves the flat state in steps
far below tolerance × size while still lowering the energy by percents per step;
the length-only rule stopped there "converged" 59.8° (H = 1e-4 a) and 60° (H =
1e-5 a, after 3 iterations) short of the rigid-origami closed form.
"""
from __future__ import annotations

import numpy as np
import pytest

from foldcore import patterns, thicken
from foldcore.simulation import Simulation

A = 20.0  # mm, facet side


def thin_miura(h_over_a: float, scale: float = 1.0):
    pattern = patterns.miura_one_crease(5, 5, a=A * scale, b=A * scale,
                                        width=3 * h_over_a * A * scale)
    creases = np.flatnonzero(patterns.miura_edge_kinds(5, 5) != "boundary")
    expected = patterns.miura_fold_angles(5, 5, 60.0, 30.0)[creases]
    return pattern, thicken(pattern, h_over_a * A * scale), creases, expected


@pytest.mark.parametrize("solver", ["hybrid", "rigid"])
@pytest.mark.parametrize("h_over_a", [1e-4, 1e-5])
def test_a_converged_thin_fold_is_the_closed_form(solver, h_over_a):
    pattern, mesh, creases, expected = thin_miura(h_over_a)
    result = Simulation(mesh, pattern, solver=solver).run(tolerance=1e-8, max_iterations=3000)
    assert result.converged
    assert np.abs(result.fold_angles_deg[creases] - expected).max() <= 0.01


def test_the_verdict_and_the_angles_do_not_depend_on_the_length_unit():
    runs = []
    for scale in (1.0, 1e-3, 1e3):  # mm, the same sheet in m and in µm
        pattern, mesh, creases, expected = thin_miura(1e-3, scale)
        result = Simulation(mesh, pattern).run(tolerance=1e-8, max_iterations=3000)
        runs.append((result.converged, result.fold_angles_deg[creases]))
    assert all(converged for converged, _ in runs)
    for _, angles in runs[1:]:
        np.testing.assert_allclose(angles, runs[0][1], atol=1e-7)  # measured 1.8e-9°


def test_a_budget_that_ends_is_not_convergence():
    pattern, mesh, creases, expected = thin_miura(1e-3)
    sim = Simulation(mesh, pattern, solver="rigid")
    assert not sim.run(tolerance=1e-8, max_iterations=3).converged
    assert not sim.run(tolerance=1.0, max_iterations=0).converged
