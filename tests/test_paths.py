"""A fold-percent path continues from converged states: one rigid-body engine
serves every run and each frame starts from the extrapolation of the previous
two, so a fine path costs few steps per frame and ends where a single fold does
(docs/architecture.md#paths-one-engine-and-a-predictor)."""
from __future__ import annotations

import numpy as np
import pytest

from foldcore import patterns, thicken
from foldcore.animate import fold_sweep, percent_schedule
from foldcore.simulation import Simulation


def miura():
    """A thin Miura 5 × 5: on a 3 × 3 the continuation from the last state already
    takes 2 steps per 5 % frame (measured: 57 steps with the predictor off, 68 on),
    here it takes 8 (median) per frame and the predictor cuts that to 3."""
    return patterns.miura_one_crease(5, 5, a=20.0, b=20.0, width=0.06)


def sweep(predict: bool, solver: str):
    pattern = miura()
    sim = Simulation(thicken(pattern, 0.02), pattern, solver=solver)
    results = fold_sweep(sim, percent_schedule(20, start=5.0), predict=predict,
                         progress=False)
    return sim, results


@pytest.mark.parametrize("solver", ["hybrid", "rigid"])
def test_the_predictor_saves_steps_and_lands_on_the_same_fold(solver):
    plain_sim, plain = sweep(False, solver)
    sim, predicted = sweep(True, solver)
    assert all(r.converged for r in plain + predicted)
    assert predicted[-1].iterations < plain[-1].iterations  # measured 82 vs 183 (hybrid)
    for a, b in zip(plain, predicted):
        np.testing.assert_allclose(a.fold_angles_deg, b.fold_angles_deg, atol=1e-5)
    pattern = miura()
    once = Simulation(thicken(pattern, 0.02), pattern, solver=solver).run(tolerance=1e-8)
    np.testing.assert_allclose(predicted[-1].fold_angles_deg, once.fold_angles_deg, atol=1e-5)


def test_predict_needs_two_converged_runs_and_a_finite_ratio():
    pattern = patterns.miura_one_crease(3, 3, width=0.06)
    sim = Simulation(thicken(pattern, 0.02), pattern)
    assert sim.predict(1.0) is False  # nothing to extrapolate from yet
    with pytest.raises(Exception, match="finite"):
        sim.predict(np.nan)
    lbfgs = Simulation(thicken(pattern, 0.02), pattern, solver="lbfgs")
    assert lbfgs.predict(1.0) is False  # only the rigid-body strategies keep ends


def test_a_sweep_from_flat_selects_its_branch_once():
    """The branch stage (passive M/V creases held on their side) ran at every frame
    while the sheet was within the 2° floor, though the first frame had chosen the
    branch: a thin Miura 8 × 8 swept in 0.5 % steps spent 35, 17, 8, 4, 4, 4, 4 of
    its first frames' 44, 26, 18, 14, 11, 8, 8 steps there. Now only the first frame
    runs it, and every frame still lands on the fold a single run reaches."""
    pattern = patterns.miura_one_crease(8, 8, a=20.0, b=20.0, width=0.06)
    mesh = thicken(pattern, 0.02)
    sim = Simulation(mesh, pattern)
    staged, steps = [], []
    for percent in (0.5, 1.0, 1.5, 2.0, 2.5):
        before, branch = sim.iterations, sim.branch_iterations
        sim.set_fold_percent(percent)
        result = sim.run(tolerance=1e-8)
        assert result.converged
        staged.append(sim.branch_iterations - branch)
        steps.append(sim.iterations - before)
    assert staged[0] > 0 and staged[1:] == [0, 0, 0, 0]
    assert max(steps[1:]) <= 6  # measured 4 each
    alone = Simulation(mesh, pattern)
    alone.set_fold_percent(2.5)
    np.testing.assert_allclose(result.fold_angles_deg, alone.run(tolerance=1e-8)
                               .fold_angles_deg, atol=1e-5)


def test_a_frame_ends_on_its_simplified_correction_within_the_bound_it_states():
    """After a frame's first step the simplified correction (the step's factorisation
    applied to the new residual) contracts by Θ ≪ 1 and ends the frame: a thin
    Miura 8 × 8 in 0.5 % frames takes 1 step a frame (3 on the step's length alone,
    2 on Θ from two steps; StoppingRule.distance_left). The distance it states is a
    bound: a run continued to a tighter tolerance moves less (measured 5.0e-11 ×
    the size against a stated 7.0e-10)."""
    pattern = patterns.miura_one_crease(8, 8, a=20.0, b=20.0, width=0.06)
    sim = Simulation(thicken(pattern, 0.02), pattern)
    results = fold_sweep(sim, [0.5, 1.0, 1.5, 2.0], progress=False)
    steps = np.diff([0] + [r.iterations for r in results])
    assert all(r.converged for r in results)
    assert list(steps[2:]) == [1, 1]
    size = sim.length_scale
    stated = results[-1].residual * size  # mm
    assert stated <= 1e-8 * size  # the run's tolerance
    x = sim.x.copy()
    sim.set_fold_percent(2.0)  # the same targets, rigid steps again (not L-BFGS's verdict)
    tighter = sim.run(tolerance=1e-9, max_iterations=50)
    assert tighter.converged
    assert np.abs(tighter.positions - x).max() <= stated
