"""A fold-percent path continues from converged states (issue 17, item 3): one
rigid-body engine serves every run and each frame starts from the extrapolation
of the previous two, so a fine path costs few steps per frame and ends where a
single fold does."""
from __future__ import annotations

import numpy as np
import pytest

from foldcore import patterns, thicken
from foldcore.animate import fold_sweep, percent_schedule
from foldcore.simulation import Simulation


def sweep(predict: bool, solver: str):
    pattern = patterns.miura_one_crease(3, 3, width=0.06)
    sim = Simulation(thicken(pattern, 0.02), pattern, solver=solver)
    results = fold_sweep(sim, percent_schedule(20, start=5.0), predict=predict,
                         progress=False)
    return sim, results


@pytest.mark.parametrize("solver", ["hybrid", "rigid"])
def test_the_predictor_saves_steps_and_lands_on_the_same_fold(solver):
    plain_sim, plain = sweep(False, solver)
    sim, predicted = sweep(True, solver)
    assert all(r.converged for r in plain + predicted)
    assert predicted[-1].iterations < plain[-1].iterations  # measured 84 vs 94 (hybrid)
    for a, b in zip(plain, predicted):
        np.testing.assert_allclose(a.fold_angles_deg, b.fold_angles_deg, atol=1e-5)
    pattern = patterns.miura_one_crease(3, 3, width=0.06)
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
