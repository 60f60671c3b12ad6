"""The thin bar-and-hinge sheet (:mod:`foldcore.sheet`): kernels, build, equilibrium.

Ground truth: finite differences for the kernels; zero-thickness closed forms
(:mod:`foldcore.kinematics`) where the targets are rigidly compatible (then the
energy's minimum is zero and every crease meets its target exactly).
"""
import numpy as np
import pytest

from foldcore import kinematics, patterns
from foldcore.sheet import Stiffness, build_sheet, fold_sheet
from foldcore.sheet import kernels
from foldcore.sheet.build import BAR, HINGE, TRIANGLE

# Newton's last steps end with forces ~1e-9 (normalised units): the angles then
# carry errors of that order in radians, far below this (degrees).
EXACT_DEG = 1e-6


def _element(kind, size, rng):
    p = rng.normal(size=(size, 3))
    nodes = np.zeros((1, 4), dtype=np.int64)
    nodes[0, :size] = np.arange(size)
    rest = np.array([[0.9, 1.0, 1.1]]) if kind == TRIANGLE else np.array([[0.7, 0.0, 0.0]])
    reference = np.array([kernels.fold_angle(p, 0.0) if kind == HINGE else 0.0])
    return p, nodes, rest, reference


def _evaluate(kind, size, p, nodes, rest, reference, hessian=False):
    energy, gradient, hess = np.empty(1), np.zeros((1, 12)), np.zeros((1, 12, 12))
    kernels.evaluate(p, nodes, np.array([size]), np.array([kind]), np.array([1.3]), rest,
                     reference, energy, gradient, hess, hessian)
    return energy[0], gradient[0, :3 * size], hess[0, :3 * size, :3 * size]


def test_a_sliver_corner_meets_a_barrier_that_keeps_its_facet_from_collapsing():
    """A triangle whose corner closes below SLIVER of its rest angle: its energy is
    the corner springs' plus k (SLIVER / r − 1)² per sliver corner (r = α / α₀),
    growing without bound as the corner closes, and its gradient and Hessian are
    still the energy's (central differences); above SLIVER nothing is added."""
    rest = np.array([[1.0, 1.0, np.pi - 2.0]])
    nodes = np.array([[0, 1, 2, 0]])
    k = 1.3

    def triangle(alpha):  # corner 0 at the origin, its sides 1 long, angle alpha
        return np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0],
                         [np.cos(alpha), np.sin(alpha), 0.0]])

    def springs(p):
        angles = [np.arctan2(
            np.linalg.norm(np.cross(p[j] - p[i], p[l] - p[i])), np.dot(p[j] - p[i], p[l] - p[i]))
            for i, j, l in ((0, 1, 2), (1, 2, 0), (2, 0, 1))]
        return 0.5 * k * np.sum((np.array(angles) - rest[0]) ** 2), angles

    for alpha in (0.5, 0.05, 1e-3):
        p = triangle(alpha)
        energy, gradient, _ = _evaluate(TRIANGLE, 3, p, nodes, rest, np.zeros(1))
        spring, angles = springs(p)
        ratios = np.array(angles) / rest[0]
        barrier = sum(k * (kernels.SLIVER / r - 1.0) ** 2 for r in ratios if r < kernels.SLIVER)
        assert energy == pytest.approx(spring + barrier, rel=1e-12)
        assert (barrier > 0) == (alpha / 1.0 < kernels.SLIVER)
        h = 1e-7 * alpha
        fd = np.zeros(9)
        for i in range(9):
            plus, minus = p.copy(), p.copy()
            plus.ravel()[i] += h
            minus.ravel()[i] -= h
            fd[i] = (_evaluate(TRIANGLE, 3, plus, nodes, rest, np.zeros(1))[0]
                     - _evaluate(TRIANGLE, 3, minus, nodes, rest, np.zeros(1))[0]) / (2 * h)
        assert np.max(np.abs(gradient - fd)) <= 1e-5 * np.max(np.abs(fd))
        _, _, hessian = _evaluate(TRIANGLE, 3, p, nodes, rest, np.zeros(1), True)
        fd_h = np.zeros((9, 9))
        for i in range(9):
            plus, minus = p.copy(), p.copy()
            plus.ravel()[i] += h
            minus.ravel()[i] -= h
            fd_h[:, i] = (_evaluate(TRIANGLE, 3, plus, nodes, rest, np.zeros(1))[1]
                          - _evaluate(TRIANGLE, 3, minus, nodes, rest, np.zeros(1))[1]) / (2 * h)
        assert np.max(np.abs(hessian - fd_h)) <= 1e-5 * np.max(np.abs(fd_h))
    assert energy > 1e3 * k  # closed to 1e-3 of its rest angle: the barrier dominates


@pytest.mark.parametrize("kind,size", [(BAR, 2), (HINGE, 4), (TRIANGLE, 3)])
def test_gradient_and_hessian_match_finite_differences(kind, size):
    rng = np.random.default_rng(kind)
    for _ in range(5):
        p, nodes, rest, reference = _element(kind, size, rng)
        _, gradient, hessian = _evaluate(kind, size, p, nodes, rest, reference, True)
        h = 1e-6
        fd_g, fd_h = np.zeros(3 * size), np.zeros((3 * size, 3 * size))
        for i in range(3 * size):
            plus, minus = p.copy(), p.copy()
            plus.ravel()[i] += h
            minus.ravel()[i] -= h
            e_plus, g_plus, _ = _evaluate(kind, size, plus, nodes, rest, reference)
            e_minus, g_minus, _ = _evaluate(kind, size, minus, nodes, rest, reference)
            fd_g[i] = (e_plus - e_minus) / (2 * h)
            fd_h[:, i] = (g_plus - g_minus) / (2 * h)
        # central differences at h = 1e-6 on O(1) values: error ~1e-9 relative
        assert np.max(np.abs(gradient - fd_g)) <= 1e-7 * np.max(np.abs(fd_g))
        assert np.max(np.abs(hessian - fd_h)) <= 1e-6 * np.max(np.abs(fd_h))
        assert np.array_equal(hessian, hessian.T)


def test_fold_angle_is_valley_positive_and_unwraps():
    # c left of a → b (counter-clockwise triangle), d lifted towards +z: a valley
    for angle in (0.3, 2.9, -1.2):
        p = np.array([[0, 0, 0], [1, 0, 0], [0.5, 1, 0],
                      [0.5, -np.cos(angle), np.sin(angle)]], dtype=float)
        assert kernels.fold_angle(p, 0.0) == pytest.approx(angle, abs=1e-12)
    past = np.array([[0, 0, 0], [1, 0, 0], [0.5, 1, 0], [0.5, 0.9, -0.1]], dtype=float)  # d through c: past 180°
    assert kernels.fold_angle(past, 3.0) > np.pi  # unwrapped near 3.0, not atan2's −174°
    assert kernels.fold_angle(past, 0.0) < 0.0


def test_sheet_of_a_miura_cuts_each_parallelogram_along_its_shorter_diagonal():
    pattern = patterns.miura(2, 2, gamma=60.0)
    sheet = build_sheet(pattern)
    assert len(sheet.triangles) == 8
    diagonals = sheet.hinges[sheet.hinge_edge < 0]
    assert len(diagonals) == 4
    xy = np.asarray(pattern.vertices)
    for a, b, c, d in diagonals:
        other = np.linalg.norm(xy[c] - xy[d])
        assert np.linalg.norm(xy[a] - xy[b]) <= other
    # every interior crease is a sprung hinge at its target; the boundary is not
    interior = np.flatnonzero(np.asarray(pattern.assignments) != "B")
    assert set(sheet.hinge_edge[sheet.hinge_edge >= 0]) == set(interior)
    assert sheet.radius == pytest.approx(np.max(np.linalg.norm(
        xy - 0.5 * (xy.min(0) + xy.max(0)), axis=1)))


def _miura_at(tilt, n=3, m=3, gamma=60.0):
    angles = patterns.miura_fold_angles(n, m, gamma, tilt)
    return patterns.miura(n, m, gamma=gamma).replace(fold_angles=angles), angles


@pytest.mark.parametrize("tilt,percent", [(30.0, 100.0), (60.0, 100.0), (60.0, 50.0)])
def test_rigidly_compatible_miura_meets_every_target(tilt, percent):
    pattern, angles = _miura_at(tilt)
    fold = fold_sheet(build_sheet(pattern), percent, pattern_edges=len(pattern.edges))
    assert fold.converged
    interior = ~np.isnan(angles)
    if percent == 100.0:
        assert np.max(np.abs(fold.fold_angles_deg[interior] - angles[interior])) < EXACT_DEG
        assert fold.energy < 1e-16
    else:  # half of every target is not rigidly compatible: the facets bend
        assert fold.energy > 0
        assert np.all(np.sign(fold.fold_angles_deg[interior]) == np.sign(angles[interior]))


def test_degree4_vertex_meets_its_closed_form():
    sectors = (135.0, 90.0, 45.0, 90.0)
    rho = kinematics.degree4_deg(sectors[0], sectors[1], 100.0, "A")
    pattern = patterns.single_vertex(sectors, patterns.degree4_assignments(sectors, "A"),
                                     fold_angles=rho)
    fold = fold_sheet(build_sheet(pattern), 100.0, pattern_edges=len(pattern.edges))
    creases = np.flatnonzero(np.asarray(pattern.assignments) != "B")
    assert fold.converged
    assert np.max(np.abs(fold.fold_angles_deg[creases] - rho)) < EXACT_DEG


def test_shape_does_not_depend_on_the_unit():
    pattern, _ = _miura_at(45.0)
    half = pattern.replace(fold_angles=np.asarray(pattern.fold_angles) * 0.7)
    micro = half.replace(vertices=np.asarray(half.vertices) * 1000.0)
    mm = fold_sheet(build_sheet(half), 80.0, pattern_edges=len(half.edges))
    um = fold_sheet(build_sheet(micro), 80.0, pattern_edges=len(half.edges))
    assert mm.iterations == um.iterations
    assert np.allclose(mm.fold_angles_deg, um.fold_angles_deg, atol=EXACT_DEG, equal_nan=True)
    assert np.allclose(um.positions, 1000.0 * mm.positions, atol=1e-6 * 1000.0 * 60)


def test_flat_at_zero_percent_and_stiffer_creases_meet_targets_closer():
    pattern, angles = _miura_at(50.0)
    sheet = build_sheet(pattern.replace(fold_angles=np.asarray(pattern.fold_angles) * 0.6))
    flat = fold_sheet(sheet, 0.0)
    assert flat.iterations == 0 and flat.converged
    soft = fold_sheet(sheet, 100.0, pattern_edges=len(pattern.edges))
    stiff_sheet = build_sheet(pattern.replace(fold_angles=np.asarray(pattern.fold_angles) * 0.6),
                              Stiffness(crease=7.0))
    stiff = fold_sheet(stiff_sheet, 100.0, pattern_edges=len(pattern.edges))
    target = 0.6 * angles
    interior = ~np.isnan(angles)
    miss = [np.max(np.abs(f.fold_angles_deg[interior] - target[interior])) for f in (soft, stiff)]
    assert soft.converged and stiff.converged
    assert miss[1] < miss[0]


def _with_midpoints(pattern, edges, bend=0.0):
    """``pattern`` with a vertex added at the middle of each of ``edges`` (moved
    ``bend`` × the edge's length off its line), each half keeping the edge's
    assignment and target."""
    from foldcore.pattern import CreasePattern

    xy = [np.asarray(v, float) for v in pattern.vertices]
    kept = [e for e in range(pattern.n_edges) if e not in edges]
    new_edges = [tuple(pattern.edges[e]) for e in kept]
    kinds = [pattern.assignments[e] for e in kept]
    angles = [pattern.fold_angles[e] for e in kept]
    for e in edges:
        a, b = pattern.edges[e]
        d = xy[b] - xy[a]
        xy.append(0.5 * (xy[a] + xy[b]) + bend * np.array([-d[1], d[0]]))
        m = len(xy) - 1
        new_edges += [(a, m), (m, b)]
        kinds += [pattern.assignments[e]] * 2
        angles += [pattern.fold_angles[e]] * 2
    return CreasePattern(np.array(xy), new_edges, kinds, fold_angles=angles)


def test_a_straight_degree2_vertex_is_left_out_as_origami_simulator_does():
    """A vertex splitting a crease or a boundary edge in two (degree 2, straight) is
    no node of the sheet when asked, as Origami Simulator leaves it out of a drawing:
    the fold is the unsplit pattern's, both halves report its crease's angle, and the
    vertex lies on its merged edge. A vertex whose edges meet at 170° (|cos + 1| =
    0.015, the rule's bound 0.01) stays."""
    sectors = (135.0, 90.0, 45.0, 90.0)
    rho = kinematics.degree4_deg(sectors[0], sectors[1], 60.0, "A")
    plain = patterns.single_vertex(sectors, patterns.degree4_assignments(sectors, "A"),
                                   fold_angles=rho)
    crease = next(e for e in range(plain.n_edges) if plain.assignments[e] != "B")
    border = next(e for e in range(plain.n_edges) if plain.assignments[e] == "B")
    split = _with_midpoints(plain, [crease, border])
    sheet = build_sheet(split, merge_straight=True)
    assert len(sheet.flat) == len(plain.vertices) and len(sheet.merged) == 2
    whole = fold_sheet(build_sheet(plain), 100.0, pattern_edges=plain.n_edges)
    parts = fold_sheet(sheet, 100.0, pattern_edges=split.n_edges)
    assert parts.converged and whole.converged
    n = len(plain.vertices)

    def distances(x):
        return np.linalg.norm(x[:, None] - x[None], axis=2)
    # the same shape (the sheet floats free: compared up to a rigid motion)
    assert np.allclose(distances(parts.positions[:n]), distances(whole.positions), atol=1e-6)
    for v, a, b in sheet.merged:  # midpoints: half way along their merged edges
        assert np.allclose(parts.positions[v], 0.5 * (parts.positions[a] + parts.positions[b]))
    halves = [e for e in range(split.n_edges) if split.assignments[e] != "B"
              and n - 1 < max(split.edges[e])]
    assert len(halves) == 2
    assert np.allclose(parts.fold_angles_deg[halves], whole.fold_angles_deg[crease],
                       atol=EXACT_DEG)
    bent = _with_midpoints(plain, [border], bend=np.tan(np.radians(5.0)) / 2)
    assert len(build_sheet(bent, merge_straight=True).merged) == 0
    assert len(build_sheet(split).merged) == 0  # kept unless asked (a FOLD file's)


def test_a_degree2_vertex_between_two_assignments_stays():
    """Origami Simulator merges only edges of one assignment: a straight line that
    is a mountain on one side of a degree-2 vertex and a valley on the other keeps
    its vertex."""
    from foldcore.pattern import CreasePattern

    xy = np.array([[0, 0], [2, 0], [2, 0.5], [2, 1], [0, 1], [0, 0.5], [1, 0.5]], float)
    edges = [(0, 1), (1, 2), (2, 3), (3, 4), (4, 5), (5, 0), (5, 6), (6, 2)]
    kinds = ["B"] * 6 + ["M", "V"]
    pattern = CreasePattern(xy, edges, kinds, fold_angles=[np.nan] * 6 + [-30.0, 30.0])
    assert len(build_sheet(pattern, merge_straight=True).merged) == 0
    same = CreasePattern(xy, edges, ["B"] * 6 + ["V", "V"],
                         fold_angles=[np.nan] * 6 + [30.0, 30.0])
    assert build_sheet(same, merge_straight=True).merged.tolist() == [[6, 5, 2]]


def test_a_cut_lets_two_flaps_fold_opposite_ways():
    """A 100 mm square, its lower half cut in two flaps along x = 50 (a kirigami cut):
    the left flap folds +90° (valley), the right −90° (mountain) about y = 50. Uncut,
    the targets fight; cut, each flap turns alone, as rigid panels: both creases meet
    their targets and the cut's lower end opens to 2 × 50 mm."""
    import warnings

    from foldcore.pattern import CreasePattern

    xy = [(0, 0), (50, 0), (100, 0), (100, 50), (100, 100), (0, 100), (0, 50), (50, 50)]
    border = [(0, 1), (1, 2), (2, 3), (3, 4), (4, 5), (5, 6), (6, 0)]
    edges = border + [(6, 7), (7, 3), (1, 7)]
    kinds = ["B"] * 7 + ["V", "M", "C"]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        pattern = CreasePattern(xy, edges, kinds, fold_angles=[None] * 7 + [90, -90, None])
    assert pattern.copied_from.tolist() == [1]
    fold = fold_sheet(build_sheet(pattern), 100.0, pattern_edges=pattern.n_edges)
    assert fold.converged
    assert np.allclose(fold.fold_angles_deg[[7, 8]], [90.0, -90.0], atol=EXACT_DEG)
    ends = fold.positions[[1, 8]]  # the cut's lower end and its copy
    assert abs(np.linalg.norm(ends[0] - ends[1]) - 100.0) < 1e-3


def test_a_crease_ending_inside_a_face_folds_as_a_crease():
    """A valley from the middle of a square's left side to its centre (a dangling crease,
    as in Origami Simulator's curved and kirigami files): the face is cut into triangles
    on both sides of it, so it is a hinge; folded to 20°, the facets beyond its tip bend
    to let it, and the sheet settles with the crease folded the valley way."""
    from foldcore.pattern import CreasePattern

    xy = [(0, 0), (100, 0), (100, 100), (0, 100), (0, 50), (50, 50)]
    edges = [(0, 1), (1, 2), (2, 3), (3, 4), (4, 0), (4, 5)]
    pattern = CreasePattern(xy, edges, list("BBBBBV"), fold_angles=[None] * 5 + [20.0])
    sheet = build_sheet(pattern)
    assert (sheet.hinge_edge == 5).sum() == 1  # one hinge: triangles on both sides
    fold = fold_sheet(sheet, 100.0, pattern_edges=pattern.n_edges)
    assert fold.converged and 0.0 < fold.fold_angles_deg[5] < 20.0


def test_straight_vertices_merge_unless_their_chord_would_cross_a_line():
    """A valley line drawn in four pieces with a crease up from its middle vertex: its
    two other degree-2 vertices merge (their chords run on along the line, past the
    rest of it). A near-straight vertex whose chord would cut across a crease's end
    (a crease from the bottom stops between the chord and the vertex) stays."""
    from foldcore.pattern import CreasePattern

    xy = [(0, 0), (100, 0), (100, 100), (0, 100), (0, 50), (30, 50), (60, 50), (70, 50),
          (100, 50), (60, 100)]
    edges = [(0, 1), (1, 8), (8, 2), (2, 9), (9, 3), (3, 4), (4, 0),
             (4, 5), (5, 6), (6, 7), (7, 8), (6, 9)]
    kinds = ["B"] * 7 + ["V"] * 4 + ["M"]
    line = CreasePattern(xy, edges, kinds, fold_angles=[None] * 7 + [10.0] * 4 + [-10.0])
    assert build_sheet(line, merge_straight=True).merged[:, 0].tolist() == [5, 7]
    xy = [(0, 0), (40, 0), (100, 0), (100, 50), (100, 100), (0, 100), (0, 50), (50, 53),
          (40, 51)]
    edges = [(0, 1), (1, 2), (2, 3), (3, 4), (4, 5), (5, 6), (6, 0), (6, 7), (7, 3), (1, 8)]
    bent = CreasePattern(xy, edges, ["B"] * 7 + ["V", "V", "M"],
                         fold_angles=[None] * 7 + [10.0, 10.0, -10.0])
    sheet = build_sheet(bent, merge_straight=True)   # |cos + 1| = 0.007 at vertex 7
    assert len(sheet.merged) == 0
    assert fold_sheet(sheet, 100.0, pattern_edges=bent.n_edges).converged
