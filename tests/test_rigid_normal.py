"""The rigid-body step's normal equations assembled strip by strip
(strategies/rigid/normal.py) equal the ones of the sparse Jacobian
(tests/rigid_reference.py): JᵀJ, Jᵀr, J·v and Jᵀu, with and without position
targets and M/V side rows acting, to rounding."""
from __future__ import annotations

import numpy as np
import pytest
import scipy.sparse as sp

from foldcore import patterns, thicken
from foldcore.simulation import Simulation
from foldcore.strategies.rigid import normal as rigid_normal
from foldcore.strategies.rigid.state import exp_so3, procrustes, skew

from rigid_reference import jacobian


def engine_after(pattern, thickness, steps, pin=False):
    mesh = thicken(pattern, thickness)
    sim = Simulation(mesh, pattern, solver="rigid")
    if pin:  # a panel vertex and a hinge-interior one, pulled off their places
        lay = sim.strategy.engine.layout
        ids = np.array([lay.on_panel[0], lay.free[len(lay.free) // 2]])
        sim.add_position_target(ids, mesh.rest_positions[ids] + [0.0, 0.0, 0.5])
    sim.run(tolerance=0.0, max_iterations=steps)
    return sim.strategy.engine


def compare(engine):
    state = engine.state()
    jac, residual = jacobian(engine, state)
    lin = engine.residual.linearise(state)
    lay = engine.layout
    n = lay.n_unknowns
    normal = sp.csc_matrix((lin.normal, lay.csc_indices, lay.csc_indptr), shape=(n, n))
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
    assert (engine.layout.panel_col >= 0).all()  # pinned: no panel holds the rigid motion
    compare(engine)


def test_mv_side_rows_acting_match():
    # mode B of a thin vertex, 2 steps in: two M/V side rows act (a crease on its
    # wrong side), which is what keeps it off mode A
    pattern = patterns.degree4_vertex(radius=10.0, widths=[0.03] * 4, mode="B", rho1=60.0)
    engine = engine_after(pattern, 0.01, 2)
    rows, _ = engine.residual.mv_terms(engine.rot_p)
    assert np.count_nonzero(rows) == 2
    compare(engine)


def test_the_panel_motion_kernels_match_their_definitions():
    """rotate_by is exp([w]×)·R (Rodrigues, small angles by series); move_panels keeps
    each panel's joints where the linear step puts them, in the weighted least-squares
    sense: the joints' weighted mean of (rigid − linear) motion is zero; to rounding."""
    rng = np.random.default_rng(7)
    n_panels, n_joints = 6, 40
    rot = exp_so3(rng.standard_normal((n_panels, 3)))
    w = np.column_stack([0.3 * rng.standard_normal((n_panels, 3)),
                         rng.standard_normal((n_panels, 3))])
    w[0, :3] = 1e-10  # the series branch
    out = np.empty_like(rot)
    rigid_normal.rotate_by(w[:, :3], rot, out)
    np.testing.assert_allclose(out, exp_so3(w[:, :3]) @ rot, rtol=0, atol=1e-14)
    np.testing.assert_allclose(exp_so3(np.array([[0.0, 0.0, np.pi / 2]]))[0] @ [1.0, 0, 0],
                               [0.0, 1.0, 0.0], atol=1e-15)
    panel = rng.integers(0, n_panels - 1, n_joints)  # the last panel has no joints
    body = 10.0 * rng.standard_normal((n_joints, 3))
    weight = rng.uniform(0.5, 2.0, n_joints)
    centre = rng.standard_normal((n_panels, 3))
    rot_new, c_new = np.empty_like(rot), np.empty_like(centre)
    rigid_normal.move_panels(rot, centre, w, panel, body, weight, rot_new, c_new)
    a = np.einsum("nij,nj->ni", rot[panel], body)
    linear = centre[panel] + a + np.einsum("nij,nj->ni", skew(w[panel, :3]), a) + w[panel, 3:]
    rigid = c_new[panel] + np.einsum("nij,nj->ni", rot_new[panel] @ rot[panel].transpose(0, 2, 1),
                                     a)
    gap = np.zeros((n_panels, 3))
    np.add.at(gap, panel, weight[:, None] * (rigid - linear))
    assert np.abs(gap[:-1]).max() < 1e-12 * np.abs(linear).max() * n_joints
    np.testing.assert_array_equal(c_new[-1], centre[-1])  # no joints: the centre stays
    x = np.zeros((n_joints + 2, 3))
    rigid_normal.place_on_panels(rot, centre, np.arange(n_joints), panel, body, x)
    np.testing.assert_allclose(x[:n_joints], a + centre[panel], rtol=0, atol=1e-13)


def test_place_sides_carries_a_shape_by_the_motion_that_fits_its_known_side():
    """A bent strip moved rigidly: its known side where the motion put it, the other
    side placed from the shape comes out where the same motion puts it (to rounding);
    with the known side perturbed, the fit is the Procrustes one (SVD reference)."""
    rng = np.random.default_rng(11)
    b = 5
    shape = rng.standard_normal((b, 8, 3)) * [3.0, 1.0, 0.1]  # mm, a strip's 8 points
    rot = exp_so3(rng.standard_normal((b, 3)))
    shift = 50.0 * rng.standard_normal((b, 1, 3))
    moved = np.einsum("nij,nkj->nki", rot, shape) + shift
    known = np.arange(8 * b).reshape(b, 8)[:, :4]
    unknown = np.arange(8 * b).reshape(b, 8)[:, 4:]
    x = np.zeros((8 * b, 3))
    x[known] = moved[:, :4]
    centre = shape[:, :4].mean(axis=1, keepdims=True)
    rigid_normal.place_sides(x, known, unknown, shape[:, :4] - centre, shape[:, 4:] - centre)
    np.testing.assert_allclose(x[unknown], moved[:, 4:], rtol=0, atol=1e-12)
    x[known] += 0.05 * rng.standard_normal((b, 4, 3))
    here = x[known]
    rigid_normal.place_sides(x, known, unknown, shape[:, :4] - centre, shape[:, 4:] - centre)
    fit = procrustes(here, shape[:, :4] - centre)
    reference = np.einsum("nij,nkj->nki", fit, shape[:, 4:] - centre) \
        + here.mean(axis=1, keepdims=True)
    np.testing.assert_allclose(x[unknown], reference, rtol=0, atol=1e-11)
