"""The rigid-body step's normal equations assembled strip by strip (foldcore.rigid_normal)
equal the ones of the sparse Jacobian it replaces: JᵀJ, Jᵀr, J·v and Jᵀu, with and
without position targets and M/V side rows acting, to rounding."""
from __future__ import annotations

import numpy as np
import pytest
import scipy.sparse as sp

from foldcore import patterns, thicken
from foldcore.simulation import Simulation


def engine_after(pattern, thickness, steps, pin=False):
    mesh = thicken(pattern, thickness)
    sim = Simulation(mesh, pattern, solver="rigid")
    if pin:  # a panel vertex and a hinge-interior one, pulled off their places
        engine = sim.strategy.engine
        ids = np.array([engine.on_panel[0], engine.free[len(engine.free) // 2]])
        sim.add_position_target(ids, mesh.rest_positions[ids] + [0.0, 0.0, 0.5])
    sim.run(tolerance=0.0, max_iterations=steps)
    return sim.strategy.engine


def compare(engine):
    state = engine._state()
    jac, residual = engine._jacobian(state)
    lin = engine._linearise(state)
    n = engine.n_unknowns
    normal = sp.csc_matrix((lin.normal, engine.csc_indices, engine.csc_indptr), shape=(n, n))
    reference = sp.tril(jac.T @ jac).tocsc()  # the stored triangle
    scale = abs(reference).max()
    assert abs(normal - reference).max() <= 1e-12 * scale
    assert np.array_equal(lin.residual, residual)
    grad = jac.T @ residual
    assert np.abs(lin.grad - grad).max() <= 1e-12 * np.abs(grad).max()
    rng = np.random.default_rng(0)
    v, u = rng.standard_normal(n), rng.standard_normal(len(residual))
    assert np.abs(lin.apply(v) - jac @ v).max() <= 1e-12 * np.abs(jac @ v).max()
    assert np.abs(lin.apply_transpose(u) - jac.T @ u).max() <= 1e-12 * np.abs(jac.T @ u).max()


@pytest.mark.parametrize("steps", [1, 4])
def test_miura_normal_equations_match_the_sparse_jacobian(steps):
    pattern = patterns.miura_one_crease(3, 3, width=0.06)
    compare(engine_after(pattern, 0.02, steps))


def test_position_targets_and_their_panel_layout_match():
    pattern = patterns.miura_one_crease(3, 3, width=0.06)
    engine = engine_after(pattern, 0.02, 2, pin=True)
    assert (engine.panel_col >= 0).all()  # pinned: no panel holds the rigid motion
    compare(engine)


def test_mv_side_rows_acting_match():
    # mode B of a thin vertex, 2 steps in: two M/V side rows act (a crease on its
    # wrong side), which is what keeps it off mode A
    pattern = patterns.degree4_vertex(radius=10.0, widths=[0.03] * 4, mode="B", rho1=60.0)
    engine = engine_after(pattern, 0.01, 2)
    rows, _ = engine._mv_terms(engine.rot_p)
    assert np.count_nonzero(rows) == 2
    compare(engine)
