"""Crease-pattern generators: counts, areas, M/V checked by the closure oracle."""
import numpy as np
import pytest

from foldcore import kinematics as k
from foldcore import patterns as p
from foldcore.errors import PatternError
from foldcore.pattern import CreasePattern


def _signs(pattern):
    return np.select([pattern.assignments == "V", pattern.assignments == "M"], [1.0, -1.0], 0.0)


# ------------------------------------------------------------- degree-4
def test_pehrson_default():
    cp = p.degree4_vertex()
    assert isinstance(cp, CreasePattern)
    assert (cp.n_vertices, cp.n_edges, len(cp.faces)) == (7, 10, 4)
    assert list(cp.assignments[:4]) == ["V", "V", "V", "M"]
    assert np.all(cp.assignments[4:] == "B")
    # the 16 mm hinge on the wrapping crease (opposite the odd M), 8 mm opposite it
    assert np.allclose(cp.widths[:4], [4, 16, 4, 8]) and np.isnan(cp.widths[4:]).all()
    ends = cp.vertices[cp.edges[:4, 1]] - cp.vertices[cp.edges[:4, 0]]
    assert np.allclose(np.hypot(*ends.T), 76.2)
    assert np.allclose(np.degrees(np.arctan2(ends[:, 1], ends[:, 0])) % 360, [0, 135, 225, 270])
    rim_area = 0.5 * 76.2 ** 2 * (4 * np.sin(np.radians(45)) + 2 * np.sin(np.radians(90)))
    assert np.isclose(cp.area(), rim_area)
    assert np.isnan(cp.fold_angles).all()


@pytest.mark.parametrize("mode", ["A", "B"])
@pytest.mark.parametrize("sectors", [(135, 90, 45, 90), (60, 100, 120, 80), (80, 50, 100, 130)])
def test_degree4_assignment_matches_closed_form(mode, sectors):
    cp = p.degree4_vertex(sectors, mode=mode, widths=None)
    a, b = np.radians(sectors[:2])
    fn = k.degree4_mode_a if mode == "A" else k.degree4_mode_b
    rho = np.abs(fn(a, b, np.radians(70.0))) * _signs(cp)[:4]
    assert k.closure_residual(k.crease_star(cp, 0)[1], rho[k.crease_star(cp, 0)[0]]) < 1e-9
    odd = [i for i in range(4) if sum(cp.assignments[:4] == cp.assignments[i]) == 1]
    assert len(odd) == 1 and odd[0] in ((1, 3) if mode == "A" else (0, 2))
    assert cp.assignments[0] == "V"


def test_wrapping_crease_is_opposite_the_odd_assignment():
    assert p.wrapping_crease(p.degree4_vertex(mode="A").assignments[:4]) == 1
    assert p.wrapping_crease(p.degree4_vertex(mode="B").assignments[:4]) == 0
    assert p.wrapping_crease(["M", "M", "M", "V"]) == 1
    assert np.allclose(p.degree4_vertex(mode="B").widths[:4], [16, 4, 8, 4])
    with pytest.raises(PatternError, match="exactly one"):
        p.wrapping_crease(["V", "V", "M", "M"])
    with pytest.raises(PatternError, match="'pehrson'"):
        p.degree4_vertex(widths="wide")


def test_pehrson_mode_b_and_mirror():
    assert list(p.degree4_vertex(mode="B").assignments[:4]) == ["V", "V", "M", "V"]
    cp = p.degree4_vertex(rho1=-30.0)
    assert list(cp.assignments[:4]) == ["M", "M", "M", "V"]
    assert cp.fold_angles[0] == -30.0 and np.isnan(cp.fold_angles[1:]).all()


def test_degree4_rho1_and_override():
    cp = p.degree4_vertex(rho1=45.0)
    assert cp.fold_angles[0] == 45.0 and cp.actuated.sum() == 1
    cp = p.degree4_vertex(assignments=["U"] * 4)
    assert list(cp.assignments[:4]) == ["U"] * 4
    general = p.degree4_vertex((100, 100, 80, 80), flat_foldable=False,
                               assignments=["V", "V", "V", "M"])
    assert general.n_edges == 4 + 3 + 3 + 1 + 1


def test_degree4_degenerate_mode_keeps_creases_flat():
    assert list(p.degree4_vertex((90, 90, 90, 90)).assignments[:4]) == ["V", "F", "V", "F"]


@pytest.mark.parametrize("kwargs,match", [
    (dict(sectors=(135, 90, 45, 80)), "sum to"),
    (dict(sectors=(135, 90, 90, 45)), "flat-foldable"),
    (dict(sectors=(200, 90, -20, 90)), r"\(0, 180\)"),
    (dict(sectors=(90, 90, 180)), "4 sector"),
    (dict(mode="C"), "mode"),
    (dict(radius=0.0), "radius"),
    (dict(sectors=(100, 100, 80, 80), flat_foldable=False), "assignments"),
])
def test_degree4_bad_parameters(kwargs, match):
    with pytest.raises(PatternError, match=match):
        p.degree4_vertex(**kwargs)


# ------------------------------------------------------------ waterbomb
@pytest.mark.parametrize("n_creases", [4, 6, 8])
def test_waterbomb(n_creases):
    cp = p.waterbomb(n_creases, radius=50.0)
    assert (cp.n_vertices, cp.n_edges, len(cp.faces)) == (n_creases + 1, 2 * n_creases,
                                                          n_creases)
    assert list(cp.assignments[:n_creases]) == ["M", "V"] * (n_creases // 2)
    assert np.all(cp.assignments[n_creases:] == "B")
    half = np.pi / n_creases
    assert np.isclose(cp.area(), n_creases * 50.0 ** 2 * np.sin(half) * np.cos(half))
    assert np.allclose(cp.vertices[1], [50.0, 0.0])


def test_waterbomb_closes_with_closed_form():
    cp = p.waterbomb(6)
    major = np.radians(82.0)
    minor = k.waterbomb_minor(6, major)
    rho = np.where(cp.assignments == "M", -major, minor)
    assert max(k.vertex_closure_residuals(cp, rho).values()) < 1e-9


def test_waterbomb_major_actuation():
    cp = p.waterbomb(6, major="V", major_angle=60.0, width=2.0)
    assert np.allclose(cp.fold_angles[[1, 3, 5]], 60.0)
    assert np.isnan(cp.fold_angles[[0, 2, 4]]).all()
    assert np.allclose(cp.widths[:6], 2.0)
    cp = p.waterbomb(6, major="M", major_angle=60.0)
    assert np.allclose(cp.fold_angles[[0, 2, 4]], -60.0)


@pytest.mark.parametrize("kwargs,match", [(dict(n_creases=5), "even"), (dict(n_creases=2), "even"),
                                          (dict(major="X"), "major"),
                                          (dict(radius=-1.0), "radius")])
def test_waterbomb_bad_parameters(kwargs, match):
    with pytest.raises(ValueError, match=match):
        p.waterbomb(**kwargs)


# ----------------------------------------------------------------- Miura
@pytest.mark.parametrize("n,m", [(1, 1), (3, 3), (4, 2), (5, 6)])
def test_miura_counts_and_area(n, m):
    cp = p.miura(n, m, a=20.0, b=15.0, gamma=60.0)
    assert cp.n_vertices == (n + 1) * (m + 1)
    assert cp.n_edges == n * (m + 1) + m * (n + 1)
    assert len(cp.faces) == n * m
    assert np.isclose(cp.area(), n * m * 20.0 * 15.0 * np.sin(np.radians(60)))
    kinds = p.miura_edge_kinds(n, m)
    assert len(kinds) == cp.n_edges
    assert np.array_equal(kinds == "boundary", cp.assignments == "B")


def test_miura_edge_kinds_geometry():
    cp = p.miura(4, 3, a=20.0, b=10.0, gamma=50.0)
    kinds = p.miura_edge_kinds(4, 3)
    lengths = cp.edge_lengths()
    assert np.allclose(lengths[kinds == "straight"], 20.0)
    assert np.allclose(lengths[kinds == "zigzag"], 10.0)
    d = cp.vertices[cp.edges[:, 1]] - cp.vertices[cp.edges[:, 0]]
    assert np.allclose(d[kinds == "straight", 1], 0.0)  # straight lines along x


@pytest.mark.parametrize("gamma", [45.0, 60.0, 75.0])
def test_miura_vertices_close_at_theta_30(gamma):
    cp = p.miura(4, 4, a=20.0, b=12.0, gamma=gamma)
    kinds = p.miura_edge_kinds(4, 4)
    z, s = k.miura_angles(np.radians(gamma), np.radians(30.0))
    rho = np.where(kinds == "zigzag", z, s) * _signs(cp)
    residuals = k.vertex_closure_residuals(cp, rho)
    assert len(residuals) == 9 and max(residuals.values()) < 1e-9
    # the assignment is essential: flipping the zig-zag creases breaks closure
    flipped = np.where(kinds == "zigzag", -rho, rho)
    assert max(k.vertex_closure_residuals(cp, flipped).values()) > 1e-2


@pytest.mark.parametrize("gamma, tilt", [(60.0, 30.0), (45.0, 50.0)])
def test_miura_fold_angles_are_the_signed_closing_rigid_fold_angles(gamma, tilt):
    """miura_fold_angles = the closed-form magnitudes signed by the pattern's own M/V:
    every interior vertex closes (1e-9 rad, rounding), NaN on the boundary."""
    cp = p.miura(4, 3, a=20.0, b=12.0, gamma=gamma)
    rho = p.miura_fold_angles(4, 3, gamma, tilt)
    boundary = cp.assignments == "B"
    assert np.isnan(rho[boundary]).all() and np.isfinite(rho[~boundary]).all()
    assert (np.sign(rho[~boundary]) == _signs(cp)[~boundary]).all()
    residuals = k.vertex_closure_residuals(cp, np.radians(np.nan_to_num(rho)))
    assert max(residuals.values()) < 1e-9


def test_miura_assignment_pattern():
    cp = p.miura(4, 4)
    kinds = p.miura_edge_kinds(4, 4)
    a = cp.assignments
    zig = cp.edges[kinds == "zigzag"]
    col = zig[:, 0] % 5
    for i in np.unique(col):  # same along a zig-zag line, alternating between lines
        assert len(set(a[kinds == "zigzag"][col == i])) == 1
    assert a[kinds == "zigzag"][col == 1][0] == "M" and a[kinds == "zigzag"][col == 2][0] == "V"
    straight = cp.edges[kinds == "straight"]
    row_a = a[kinds == "straight"][straight[:, 0] // 5 == 1]
    assert list(row_a) == ["V", "M", "V", "M"]


@pytest.mark.parametrize("kwargs,match", [(dict(gamma=0.0), "gamma"), (dict(gamma=90.0), "gamma"),
                                          (dict(gamma=120.0), "gamma"), (dict(n=0), "n must"),
                                          (dict(m=2.5), "m must"), (dict(a=0.0), "a must")])
def test_miura_bad_parameters(kwargs, match):
    with pytest.raises(PatternError, match=match):
        p.miura(**kwargs)


# ------------------------------------------------------- simple patterns
def test_single_hinge():
    cp = p.single_hinge(panel_length=10.0, depth=5.0, angle=90.0, width=1.0, max_angle=120.0)
    assert (cp.n_vertices, cp.n_edges, len(cp.faces)) == (6, 7, 2)
    assert cp.assignments[0] == "V" and np.all(cp.assignments[1:] == "B")
    assert cp.fold_angles[0] == 90.0 and cp.widths[0] == 1.0 and cp.max_angles[0] == 120.0
    assert np.allclose(cp.vertices[cp.edges[0]], [[0, 0], [0, 5]])
    assert np.isclose(cp.area(), 100.0)
    assert np.isnan(p.single_hinge().fold_angles).all()
    with pytest.raises(PatternError, match="contradicts"):
        p.single_hinge(angle=-30.0, assignment="V")


def test_grid():
    cp = p.grid(3, 2, size=5.0)
    assert (cp.n_vertices, cp.n_edges, len(cp.faces)) == (12, 17, 6)
    assert np.isclose(cp.area(), 150.0)
    assert np.count_nonzero(cp.assignments == "U") == 7


def test_miura_one_crease_drives_only_the_middle_zigzag_edge():
    pattern = p.miura_one_crease(4, 3, tilt=20.0)
    driven = np.flatnonzero(np.isfinite(pattern.fold_angles))
    zigzag = np.flatnonzero(p.miura_edge_kinds(4, 3) == "zigzag")
    assert driven.tolist() == [int(zigzag[len(zigzag) // 2])]
    assert pattern.fold_angles[driven[0]] == p.miura_fold_angles(4, 3, 60.0, 20.0)[driven[0]]


def test_single_vertex_of_degree_five_and_its_refusals():
    pattern = p.single_vertex((120.0, 90.0, 30.0, 30.0, 90.0), list("VVVMV"),
                              [60.0, 60.0, None, None, None], radius=10.0)
    assert pattern.assignments[:5].tolist() == list("VVVMV")
    assert len(pattern.faces) == 5 and pattern.fold_angles[0] == 60.0
    starts = np.degrees(np.arctan2(pattern.vertices[1:6, 1], pattern.vertices[1:6, 0])) % 360
    np.testing.assert_allclose(starts, [0.0, 120.0, 210.0, 240.0, 270.0], atol=1e-9)
    with pytest.raises(PatternError, match="single_vertex: .* sum to 350"):
        p.single_vertex((120.0, 90.0, 30.0, 20.0, 90.0), list("VVVMV"))
    with pytest.raises(PatternError, match="4 assignments for 5 creases"):
        p.single_vertex((120.0, 90.0, 30.0, 30.0, 90.0), list("VVVM"))
    with pytest.raises(PatternError, match="at least 3"):
        p.single_vertex((180.0, 180.0), list("VV"))


def test_a_panel_row_puts_its_creases_first_and_its_panels_side_by_side():
    row = p.panel_row([6.0, 10.0, 6.0], depth=10.0)
    assert [tuple(e) for e in row.edges[:2]] == [(1, 5), (2, 6)]
    assert list(row.assignments) == ["V", "V"] + ["B"] * 8
    assert len(row.faces) == 3 and row.area() == pytest.approx(220.0)
    with pytest.raises(PatternError, match=r"lengths\[1\] must be > 0"):
        p.panel_row([6.0, 0.0])
    with pytest.raises(PatternError, match="at least 2"):
        p.panel_row([6.0])
