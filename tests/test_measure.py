"""Measurements on a deformed thick mesh (foldcore.measure): panel rotations and the
sign of fold angles (valley > 0, the FOLD convention)."""
from __future__ import annotations

import numpy as np
import pytest
from naive import kabsch_of

from foldcore import patterns, thicken
from foldcore.measure import best_rotations, fold_angles
from foldcore.pattern import CreasePattern

RNG = np.random.default_rng(18)


def random_rotation(rng):
    q, r = np.linalg.qr(rng.normal(size=(3, 3)))
    q = q * np.sign(np.diag(r))
    return q if np.linalg.det(q) > 0 else -q


def reflected_covariance(rng):
    """A covariance whose SVD U·S·Vᵀ has det(U Vᵀ) = −1 (distinct singular values
    3, 2, 1, so the best rotation is unique): what a panel fitted through a mirror
    image gives."""
    mirror = np.diag([1.0, 1.0, -1.0])
    return random_rotation(rng) @ mirror @ np.diag([3.0, 2.0, 1.0]) @ random_rotation(rng)


def test_best_rotations_of_reflected_covariances_are_proper_and_optimal():
    reflected = [reflected_covariance(RNG) for _ in range(4)]
    plain = [random_rotation(RNG) @ np.diag([3.0, 2.0, 1.0]) @ random_rotation(RNG)
             for _ in range(2)]
    covs = np.array(reflected + plain)
    u, _, vt = np.linalg.svd(covs[:4])
    assert np.all(np.linalg.det(u @ vt) < 0)   # the case under test
    rotations = best_rotations(covs.copy())
    # rounding only: orthonormal products of 3 × 3 factors of norm ≤ 3
    assert np.allclose(np.linalg.det(rotations), 1.0, atol=1e-12)
    for r, cov in zip(rotations, covs):
        assert np.allclose(r.T @ r, np.eye(3), atol=1e-12)
        assert np.allclose(r, kabsch_of(cov), atol=1e-12)
        best = np.trace(r.T @ cov)
        others = [np.trace(random_rotation(RNG).T @ cov) for _ in range(200)]
        assert best >= max(others) - 1e-12


def lift(points, side, rho_deg):
    """Rigidly rotate the points with ``side`` · x > 0 about the crease x = 0 (the y
    axis) so that they rise (+z) for ρ > 0: a valley, the top faces turning toward
    each other."""
    rho = np.radians(rho_deg)
    out = points.copy()
    moved = side * points[:, 0] > 0
    x, z = side * points[moved, 0], points[moved, 2]
    out[moved, 0] = side * (x * np.cos(rho) - z * np.sin(rho))
    out[moved, 2] = x * np.sin(rho) + z * np.cos(rho)
    return out


@pytest.fixture(scope="module")
def hinge():
    pattern = patterns.single_hinge(panel_length=5.0, angle=90.0)
    return pattern, thicken(pattern, 1.0, hinge_width=2.0, subdivisions=1)


@pytest.mark.parametrize("side", [1, -1], ids=["right-panel", "left-panel"])
@pytest.mark.parametrize("rho", [60.0, -60.0, 150.0], ids=["valley", "mountain", "valley150"])
def test_a_lifted_panel_measures_a_valley_and_a_lowered_one_a_mountain(hinge, side, rho):
    pattern, mesh = hinge
    x = lift(mesh.rest_positions, side, rho)
    # rotation fits of exact rigid motions: rounding only
    assert fold_angles(pattern, mesh, x)[0] == pytest.approx(rho, abs=1e-9)
    spin = random_rotation(RNG)   # the sign does not depend on how the whole sheet lies
    assert fold_angles(pattern, mesh, x @ spin.T)[0] == pytest.approx(rho, abs=1e-9)


def test_the_sign_does_not_depend_on_which_way_an_edge_is_listed(hinge):
    pattern, _ = hinge
    edges = pattern.edges.copy()
    edges[0] = edges[0][::-1]
    flipped = CreasePattern(pattern.vertices, edges, pattern.assignments,
                            fold_angles=pattern.fold_angles, widths=pattern.widths)
    mesh = thicken(flipped, 1.0, hinge_width=2.0, subdivisions=1)
    x = lift(mesh.rest_positions, 1, 60.0)
    assert fold_angles(flipped, mesh, x)[0] == pytest.approx(60.0, abs=1e-9)


def test_the_solver_folds_a_valley_hinge_by_lifting_its_free_panel():
    """Ties the convention to the simulated geometry: the valley target +90° lifts
    the right panel's far edge (x = 5 at rest) to z = +5 above the crease."""
    from folded import scene

    _, mesh, result = scene("hinge")
    far = mesh.rest_positions[:, 0] > 4.0
    assert result.fold_angles_deg[0] == pytest.approx(90.0, abs=1e-6)
    # converged to 1e-10 on a 5 mm panel held vertical: 1e-6 mm is loose
    assert result.positions[far, 2].mean() == pytest.approx(5.0, abs=1e-6)


@pytest.mark.parametrize("sign, excess_deg", [(-1.0, 30.0), (1.0, -90.0)],
                         ids=["mountain-strip", "valley-strip"])
def test_a_mountain_strip_past_its_max_angle_has_a_positive_excess(hinge, sign, excess_deg):
    """The max-angle stop measures a strip on its own side: folded 60° mountain, a
    mountain strip allowed 30° is 30° past its stop, a valley strip 90° short."""
    from elements.bending_hinge import MAX_ANGLE, SIGN, TARGET, limit_excess

    pattern, mesh = hinge
    strips = mesh.groups["bending_hinge"]
    params = strips.params.copy()
    params[:, TARGET], params[:, SIGN], params[:, MAX_ANGLE] = np.nan, sign, np.radians(30.0)
    x = lift(mesh.rest_positions, 1, -60.0)
    out = np.empty(len(strips))
    limit_excess(x, strips.indptr, strips.indices, params, out)
    # one strip spans the whole hinge, its far side turned rigidly: Eq. 9 gives the
    # turn to rounding
    assert np.degrees(out) == pytest.approx(np.full(len(strips), excess_deg), abs=1e-9)
