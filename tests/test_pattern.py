"""CreasePattern validation: every malformed input is refused by a PatternError
naming the offending item; valid inputs derive the expected faces."""
import re
import warnings

import numpy as np
import pytest

from foldcore import patterns
from foldcore.errors import PatternError, PatternWarning
from foldcore.pattern import CreasePattern

# A 20 × 10 sheet split by one crease x = 10 into two squares.
#   3 ── 5 ── 2
#   │    │    │
#   0 ── 4 ── 1
SQ_V = [(0, 0), (20, 0), (20, 10), (0, 10), (10, 0), (10, 10)]
SQ_E = [(0, 4), (4, 1), (1, 2), (2, 5), (5, 3), (3, 0), (4, 5)]
SQ_A = ["B", "B", "B", "B", "B", "B", "V"]
SQ_F = [[0, 4, 5, 3], [4, 1, 2, 5]]


def make(vertices=SQ_V, edges=SQ_E, assignments=SQ_A, **kw):
    return CreasePattern(vertices, edges, assignments, **kw)


def refused(kind, index, *, also=(), **kw):
    """Build a pattern that must fail; check the message names ``kind index``."""
    with pytest.raises(PatternError) as info:
        make(**kw)
    msg = str(info.value)
    assert "np." not in msg, msg  # user messages show plain numbers, not numpy reprs
    assert re.search(rf"\b{kind}s?\b[^\n]*?(?<![\d.]){index}(?![\d.])", msg), msg
    for other in also:
        assert re.search(rf"(?<![\d.]){other}(?![\d.])", msg), msg
    return msg


def with_edge_value(name, e, value, n=len(SQ_E)):
    values = [None] * n
    values[e] = value
    return {name: values}


def rotations(loop):
    loop = [int(x) for x in loop]
    return {tuple(loop[i:] + loop[:i]) for i in range(len(loop))}


def same_faces(a, b):
    canon = lambda faces: sorted(min(rotations(f)) for f in faces)  # noqa: E731
    return canon(a) == canon(b)


# ------------------------------------------------------------- good input
def test_base_pattern_is_valid():
    cp = make()
    assert cp.n_vertices == 6 and cp.n_edges == 7 and len(cp.faces) == 2
    assert same_faces(cp.faces, SQ_F)
    assert cp.area() == pytest.approx(200.0)
    assert list(cp.creases) == [6]
    # crease 4→5: face 0 (x < 10) on its left
    assert tuple(cp.edge_faces[6]) == (0, 1)


def test_given_faces_are_kept_and_match_derived():
    given = make(faces=[[4, 5, 3, 0], [2, 5, 4, 1]])  # rotated starts
    derived = make()
    assert same_faces(given.faces, derived.faces)
    assert same_faces(given.faces, SQ_F)


@pytest.mark.parametrize("build", [
    lambda: patterns.grid(3, 3, assignment="V"),
    lambda: patterns.miura(3, 2),
    lambda: patterns.waterbomb(8),
    lambda: patterns.degree4_vertex(),
])
def test_derived_faces_equal_given_faces(build):
    cp = build()
    rng = np.random.default_rng(0)
    shuffled = [np.roll(f, rng.integers(len(f))) for f in cp.faces]
    again = cp.replace(faces=shuffled[::-1])
    assert same_faces(again.faces, cp.faces)
    assert np.isclose(again.area(), cp.area())
    # every face counter-clockwise
    for f in cp.faces:
        x, y = cp.vertices[f].T
        assert np.dot(x, np.roll(y, -1)) - np.dot(np.roll(x, -1), y) > 0


def test_grid_faces_exact():
    cp = patterns.grid(2, 2)
    assert same_faces(cp.faces, [[0, 1, 4, 3], [1, 2, 5, 4], [3, 4, 7, 6], [4, 5, 8, 7]])


def frame():
    """A square frame of 4 trapezoids around a square hole (all rim edges B)."""
    v = [(0, 0), (30, 0), (30, 30), (0, 30), (10, 10), (20, 10), (20, 20), (10, 20)]
    e = [(0, 1), (1, 2), (2, 3), (3, 0),        # outer rim
         (4, 5), (5, 6), (6, 7), (7, 4),        # hole rim
         (0, 4), (1, 5), (2, 6), (3, 7)]        # creases
    return v, e, ["B"] * 8 + ["V", "M", "V", "M"]


def test_hole_gives_four_faces_not_five():
    v, e, a = frame()
    cp = CreasePattern(v, e, a)
    assert len(cp.faces) == 4
    assert same_faces(cp.faces, [[0, 1, 5, 4], [1, 2, 6, 5], [2, 3, 7, 6], [3, 0, 4, 7]])
    assert cp.area() == pytest.approx(900 - 100)
    # hole rim edges have a face on one side only
    assert ((cp.edge_faces[4:8] >= 0).sum(axis=1) == 1).all()


def test_clockwise_face_reversed_with_warning():
    with pytest.warns(PatternWarning, match=r"face 1\b"):
        cp = make(faces=[[0, 4, 5, 3], [4, 5, 2, 1]])  # face 1 clockwise
    assert same_faces(cp.faces, SQ_F)
    x, y = cp.vertices[cp.faces[1]].T
    assert np.dot(x, np.roll(y, -1)) - np.dot(np.roll(x, -1), y) > 0


def test_counter_clockwise_faces_give_no_warning():
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        make(faces=SQ_F)


def test_z_zero_accepted():
    cp = make(vertices=[(x, y, 0.0) for x, y in SQ_V])
    assert cp.vertices.shape == (6, 2)


# ------------------------------------------------------ malformed geometry
def test_crossing_edges():
    # square with both diagonals: edges 4 (0-2) and 5 (1-3) cross at the centre
    v = [(0, 0), (10, 0), (10, 10), (0, 10)]
    e = [(0, 1), (1, 2), (2, 3), (3, 0), (0, 2), (1, 3)]
    refused("edge", 4, also=[5], vertices=v, edges=e, assignments=["B"] * 4 + ["V", "M"])


def test_crossing_edge_through_a_crease():
    # an extra crease 0→2 crosses crease 6 (4→5) of the base pattern
    refused("edge", 6, also=[7], edges=SQ_E + [(0, 2)], assignments=SQ_A + ["V"])


def test_overlapping_collinear_edges_sharing_an_end():
    # edge 7 runs from vertex 4 (10, 0) to (30, 0) along the bottom, overlapping edge 1
    v = SQ_V + [(30, 0), (30, 10)]
    e = SQ_E + [(4, 6), (6, 7), (7, 2)]
    refused("edge", 7, vertices=v, edges=e, assignments=SQ_A + ["B", "B", "B"])


def test_overlapping_collinear_edges_every_pair_sharing_an_end():
    # edge 5 (0→1) covers edges 0 (0→4) and 1 (4→1); each overlapping pair shares
    # an end vertex and nothing else touches
    v = [(0, 0), (20, 0), (20, 10), (0, 10), (10, 0)]
    e = [(0, 4), (4, 1), (1, 2), (2, 3), (3, 0), (0, 1)]
    refused("edge", 5, vertices=v, edges=e, assignments=["B"] * 6)


def test_overlapping_collinear_edges_disjoint_ends():
    # edge 7 (5,0)→(15,0) lies inside the bottom edges 0 and 1
    v = SQ_V + [(5, 0), (15, 0)]
    e = SQ_E + [(6, 7), (6, 3), (7, 2)]
    refused("edge", 7, vertices=v, edges=e, assignments=SQ_A + ["V", "V", "V"])


def test_t_junction():
    # vertex 6 = (5, 0) lies inside edge 0 (0→4) without splitting it
    v = SQ_V + [(5, 0)]
    e = SQ_E + [(6, 3), (6, 5)]
    refused("edge", 0, vertices=v, edges=e, assignments=SQ_A + ["V", "V"])


@pytest.mark.parametrize("dup", [(4, 5), (5, 4)])
def test_duplicate_edge(dup):
    refused("edge", 7, also=[6], edges=SQ_E + [dup], assignments=SQ_A + ["V"])


def test_zero_length_edge_same_vertex():
    refused("edge", 7, edges=SQ_E + [(5, 5)], assignments=SQ_A + ["V"])


def test_zero_length_edge_coincident_vertices():
    # vertex 6 sits on vertex 5; edge 7 joins them
    v = SQ_V + [(10, 10)]
    refused("edge", 7, vertices=v, edges=SQ_E + [(5, 6), (6, 0)], assignments=SQ_A + ["V", "V"])


def test_a_crease_ending_inside_a_face_is_a_pattern_that_a_thick_sheet_refuses():
    """A crease from a corner to a point inside a face (a dangling crease): a thin sheet
    folds it as Origami Simulator does; a thick sheet has no panel for it to end in.
    A dangling boundary edge is refused."""
    from foldcore import thicken

    v = SQ_V + [(5, 5)]
    pattern = make(vertices=v, edges=SQ_E + [(0, 6)], assignments=SQ_A + ["V"])
    assert pattern.dangling.tolist() == [7]
    assert pattern.edge_faces[7, 0] == pattern.edge_faces[7, 1] >= 0  # one face, both sides
    with pytest.raises(PatternError, match=r"edge 7 is a crease that ends inside a face"):
        thicken(pattern, 1.0)
    msg = refused("edge", 7, vertices=v, edges=SQ_E + [(0, 6)], assignments=SQ_A + ["B"])
    assert "only a crease may end inside a face" in msg


def test_isolated_vertex():
    refused("vertex", 6, vertices=SQ_V + [(5, 5)])


@pytest.mark.parametrize("bad", [-1, 6, 99])
def test_out_of_range_vertex_index(bad):
    e = list(SQ_E)
    e[3] = (2, bad)
    refused("edge", 3, edges=e)


def test_non_integer_vertex_index():
    e = [list(x) for x in SQ_E]
    e[3] = [2, 5.5]
    refused("edge", 3, edges=e)


@pytest.mark.parametrize("value", [np.nan, np.inf, -np.inf])
def test_non_finite_coordinate(value):
    v = [list(p) for p in SQ_V]
    v[2][1] = value
    refused("vertex", 2, vertices=v)


def test_vertex_with_nonzero_z():
    v = [(x, y, 0.0) for x, y in SQ_V]
    v[4] = (10, 0, 0.5)
    refused("vertex", 4, vertices=v)


def test_disconnected_pattern_derived_faces():
    # a second square (vertices 6..9, edges 7..10) far away: two pieces, faces for both
    v = SQ_V + [(40, 0), (50, 0), (50, 10), (40, 10)]
    e = SQ_E + [(6, 7), (7, 8), (8, 9), (9, 6)]
    pattern = make(vertices=v, edges=e, assignments=SQ_A + ["B"] * 4)
    assert pattern.pieces == 2
    assert sorted(map(sorted, pattern.faces))[-1] == [6, 7, 8, 9]


def test_disconnected_pattern_given_faces():
    v = SQ_V + [(40, 0), (50, 0), (50, 10), (40, 10)]
    e = SQ_E + [(6, 7), (7, 8), (8, 9), (9, 6)]
    pattern = make(vertices=v, edges=e, assignments=SQ_A + ["B"] * 4,
                   faces=SQ_F + [[6, 7, 8, 9]])
    assert pattern.pieces == 2 and len(pattern.faces) == len(SQ_F) + 1


def test_a_piece_inside_a_hole_of_another_is_apart_from_it():
    # a small square floating inside the frame's hole: two pieces, neither on the other
    v, e, a = frame()
    v = v + [(13, 13), (17, 13), (17, 17), (13, 17)]
    e = e + [(8, 9), (9, 10), (10, 11), (11, 8)]
    pattern = make(vertices=v, edges=e, assignments=a + ["B"] * 4)
    assert pattern.pieces == 2
    assert sorted(len(f) for f in pattern.faces)[-1] == 4  # the hole is no face
    assert abs(pattern.area() - (30 * 30 - 10 * 10 + 4 * 4)) < 1e-9


# ---------------------------------------------------- malformed edge data
@pytest.mark.parametrize("kind", ["X", "m", "", "MV"])
def test_unknown_assignment(kind):
    a = list(SQ_A)
    a[6] = kind
    refused("edge", 6, assignments=a)


def test_join_refused():
    a = list(SQ_A)
    a[6] = "J"
    msg = refused("edge", 6, assignments=a)
    assert "'J'" in msg


def test_a_cut_across_the_sheet_splits_it_in_two_pieces():
    """The square's middle line as a cut: each of its ends gets a second vertex, the cut
    a second side; both sides boundary; said once."""
    a = list(SQ_A)
    a[6] = "C"
    with pytest.warns(PatternWarning, match=r"1 cut edge \('C'\).*2 vertex copies"):
        pattern = make(assignments=a)
    assert pattern.n_vertices == len(SQ_V) + 2 and pattern.n_edges == len(SQ_E) + 1
    assert pattern.pieces == 2 and set(pattern.assignments) == {"B"}
    assert pattern.copied_from.tolist() == [4, 5]
    sides = pattern.edges[[6, len(SQ_E)]]
    assert np.array_equal(pattern.vertices[sides[0]], pattern.vertices[sides[1]])
    assert not set(sides[0]) & set(sides[1])  # no vertex shared: the sheet is apart
    assert (pattern.edge_faces[[6, len(SQ_E)]] >= 0).sum() == 2  # one face each
    again = pattern.replace(fold_angles=pattern.fold_angles)  # the split re-validates
    assert again.n_vertices == pattern.n_vertices


def test_a_cut_ending_inside_the_sheet_keeps_its_end_and_a_lone_segment_stays_shut():
    """A cut from the border to the centre of a 2 × 2 grid: its border end splits, its
    inner end (where the faces still go round) does not. A one-segment cut between
    two vertices no other cut reaches cannot open: a free hinge (U)."""
    xy = [(0, 0), (1, 0), (2, 0), (2, 1), (2, 2), (1, 2), (0, 2), (0, 1), (1, 1)]
    border = [(i, (i + 1) % 8) for i in range(8)]
    inner = [(8, 1), (8, 3), (8, 5), (8, 7)]
    kinds = ["B"] * 8 + ["C", "V", "V", "V"]
    with pytest.warns(PatternWarning, match="1 vertex copy"):
        pattern = make(vertices=xy, edges=border + inner, assignments=kinds)
    assert pattern.copied_from.tolist() == [1] and pattern.pieces == 1
    assert pattern.assignments[8] == "B" and pattern.assignments[12] == "B"
    shut = make(vertices=[(0, 0), (2, 0), (2, 2), (0, 2), (1, 0.5), (1, 1.5)],
                edges=[(0, 1), (1, 2), (2, 3), (3, 0), (0, 4), (4, 1), (3, 5), (5, 2),
                       (4, 5)],
                assignments=["B"] * 4 + ["V"] * 4 + ["C"])
    assert shut.n_vertices == 6 and shut.assignments[8] == "U"


def test_vertices_drawn_twice_off_a_slit_are_refused_naming_one():
    """Coincident vertices are the two sides of a slit only: two boundary edges on each
    other. A vertex drawn twice elsewhere is refused, naming it."""
    two = BOWTIE_V + [BOWTIE_V[0]]  # the bow-tie's second triangle on a vertex of its own
    edges = [(0, 1), (1, 2), (2, 0), (5, 3), (3, 4), (4, 5)]
    refused("vertex", 0, also=[5], vertices=two, edges=edges, assignments=["B"] * 6)
    # the right square on copies of the crease's ends: the crease lies on a boundary edge
    v = SQ_V + [SQ_V[4], SQ_V[5]]
    e = [(0, 4), (6, 1), (1, 2), (2, 7), (5, 3), (3, 0), (4, 5), (6, 7)]
    msg = refused("edges", 6, also=[7], vertices=v, edges=e, assignments=SQ_A + ["B"])
    assert "only the two boundary sides of a slit may" in msg


def test_wrong_number_of_assignments():
    with pytest.raises(PatternError, match="assignments"):
        make(assignments=SQ_A[:-1])


@pytest.mark.parametrize("kind, angle", [("M", 30.0), ("V", -30.0)])
def test_fold_angle_sign_contradicts_assignment(kind, angle):
    a = list(SQ_A)
    a[6] = kind
    refused("edge", 6, assignments=a, **with_edge_value("fold_angles", 6, angle))


@pytest.mark.parametrize("kind, angle", [("M", -30.0), ("V", 30.0), ("U", -30.0),
                                         ("U", 30.0), ("F", 0.0), ("V", 180.0)])
def test_fold_angle_sign_accepted(kind, angle):
    a = list(SQ_A)
    a[6] = kind
    cp = make(assignments=a, **with_edge_value("fold_angles", 6, angle))
    assert cp.fold_angles[6] == angle


def test_nonzero_angle_on_boundary_edge():
    refused("edge", 2, **with_edge_value("fold_angles", 2, 10.0))


def test_nonzero_angle_on_flat_edge():
    a = list(SQ_A)
    a[6] = "F"
    refused("edge", 6, assignments=a, **with_edge_value("fold_angles", 6, 10.0))


@pytest.mark.parametrize("z", [0.5, -0.5], ids=["above", "below"])
def test_a_vertex_off_the_sheet_is_refused(z):
    vertices = [(x, y, 0.0) for x, y in SQ_V]
    vertices[2] = (20.0, 10.0, z)
    msg = refused("vertex", 2, vertices=vertices)
    assert f"z = {z:g}" in msg and "flat" in msg, msg


@pytest.mark.parametrize("scale", [1e150, -1e150], ids=["positive", "negative"])
def test_a_coordinate_beyond_the_float64_safe_range_is_refused(scale):
    """Lengths² and areas of coordinates past 1e100 mm overflow; the sign does not matter."""
    vertices = [(x * scale / 20.0, y) for x, y in SQ_V]
    refused("vertex", 1, vertices=vertices, also=["1e\\+100"])


@pytest.mark.parametrize("kind, angle", [("V", 190.0), ("M", -200.0), ("U", 181.0)])
def test_angle_beyond_180(kind, angle):
    a = list(SQ_A)
    a[6] = kind
    refused("edge", 6, assignments=a, **with_edge_value("fold_angles", 6, angle))


def test_infinite_angle():
    refused("edge", 6, **with_edge_value("fold_angles", 6, np.inf))


def test_angle_above_max_angle():
    kw = with_edge_value("fold_angles", 6, 100.0)
    kw["max_angles"] = [180.0] * 6 + [90.0]
    refused("edge", 6, **kw)


def test_angle_just_above_max_angle():
    kw = with_edge_value("fold_angles", 6, 90.5)
    kw["max_angles"] = [180.0] * 6 + [90.0]
    refused("edge", 6, **kw)
    kw = with_edge_value("fold_angles", 6, 90.0)
    kw["max_angles"] = [180.0] * 6 + [90.0]
    assert make(**kw).fold_angles[6] == 90.0


@pytest.mark.parametrize("value", [0.0, -90.0, 181.0, np.nan])
def test_bad_max_angle(value):
    refused("edge", 6, max_angles=[180.0] * 6 + [value])


@pytest.mark.parametrize("value", [0.0, -2.0, np.inf])
def test_width_not_positive(value):
    refused("edge", 6, **with_edge_value("widths", 6, value))


def test_width_nan_means_auto():
    cp = make(**with_edge_value("widths", 6, np.nan))
    assert np.isnan(cp.widths[6])


def test_wrong_number_of_fold_angles():
    with pytest.raises(PatternError, match="fold_angles"):
        make(fold_angles=[None] * 3)


# ------------------------------------------------ faces not matching edges
def test_face_side_not_an_edge():
    # face 1 uses the diagonal 4→2, which is no edge
    refused("face", 1, faces=[[0, 4, 5, 3], [4, 2, 5], [4, 1, 2]])


def test_edge_in_no_face():
    # extra diagonal crease 4→2 (edge 7) but faces given without it
    refused("edge", 7, edges=SQ_E + [(4, 2)], assignments=SQ_A + ["V"], faces=SQ_F)


def test_boundary_edge_assigned_crease():
    a = list(SQ_A)
    a[2] = "V"
    refused("edge", 2, assignments=a)


def test_interior_edge_assigned_boundary():
    a = list(SQ_A)
    a[6] = "B"
    refused("edge", 6, assignments=a)


def test_interior_edge_assigned_boundary_given_faces():
    a = list(SQ_A)
    a[6] = "B"
    refused("edge", 6, assignments=a, faces=SQ_F)


def test_face_out_of_range():
    refused("face", 1, faces=[[0, 4, 5, 3], [4, 1, 2, 9]])


def test_face_too_short():
    refused("face", 0, faces=[[0, 4], [4, 1, 2, 5]])


def test_overlapping_faces():
    # the same face twice
    refused("face", 1, faces=[[0, 4, 5, 3], [0, 4, 5, 3]])


# Two triangles sharing vertex 0 only (a bow-tie), and two creased squares pinned at
# vertex 0: connected as a graph, but not one sheet joined along edges.
BOWTIE_V = [(0, 0), (10, 0), (10, 10), (-10, 0), (-10, -10)]
BOWTIE_E = [(0, 1), (1, 2), (2, 0), (0, 3), (3, 4), (4, 0)]
PINNED_V = [(0, 0), (10, 0), (10, 10), (0, 10), (-10, 0), (-10, -10), (0, -10)]
PINNED_E = [(0, 1), (1, 2), (2, 3), (3, 0), (1, 3), (0, 4), (4, 5), (5, 6), (6, 0), (4, 6)]
PINNED_A = ["B", "B", "B", "B", "V", "B", "B", "B", "B", "V"]


@pytest.mark.parametrize("faces", [[[0, 1, 2], [0, 3, 4]], None], ids=["given", "derived"])
def test_faces_meeting_only_at_a_vertex_are_refused_by_a_thick_sheet_naming_it(faces):
    """A bow-tie is a pattern (a thin sheet folds it, as Origami Simulator does); a thick
    sheet refuses it, naming the vertex."""
    from foldcore import thicken

    pattern = make(vertices=BOWTIE_V, edges=BOWTIE_E, assignments=["B"] * 6, faces=faces)
    assert pattern.pinched.tolist() == [0]
    with pytest.raises(PatternError) as info:
        thicken(pattern, 1.0)
    msg = str(info.value)
    assert "vertex 0" in msg and "bow-tie" in msg and "simulate each piece on its own" in msg


def test_creased_pieces_pinned_at_a_vertex_are_refused_by_a_thick_sheet_naming_it():
    from foldcore import thicken

    pattern = make(vertices=PINNED_V, edges=PINNED_E, assignments=PINNED_A)
    assert pattern.pinched.tolist() == [0]
    with pytest.raises(PatternError, match="vertex 0: faces meet only at this vertex"):
        thicken(pattern, 1.0)


def test_separate_pieces_are_a_pattern_that_a_thick_sheet_refuses_naming_a_vertex():
    """Two pieces apart: a pattern (a thin sheet folds both, as Origami Simulator
    does); a thick sheet needs one piece and says which vertex is not connected."""
    from foldcore import thicken

    vertices = PINNED_V[:4] + [(x + 30.0, y) for x, y in PINNED_V[4:]] + [(30.0, 0.0)]
    edges = [(7 if (u == 0 and i >= 5) else u, 7 if (v == 0 and i >= 5) else v)
             for i, (u, v) in enumerate(PINNED_E)]
    pattern = make(vertices=vertices, edges=edges, assignments=PINNED_A)
    assert pattern.pieces == 2 and len(pattern.faces) == 4   # two creased squares
    with pytest.raises(PatternError) as info:
        thicken(pattern, 1.0)
    msg = str(info.value)
    assert "not connected (2 separate pieces)" in msg and "vertex 4" in msg
    assert "simulate each piece on its own" in msg and "thin sheet" in msg


def test_a_piece_drawn_inside_another_is_refused_naming_a_vertex():
    outer = [(0, 0), (10, 0), (10, 10), (0, 10)]
    inner = [(4, 4), (6, 4), (6, 6), (4, 6)]
    edges = [(0, 1), (1, 2), (2, 3), (3, 0), (4, 5), (5, 6), (6, 7), (7, 4)]
    msg = refused("vertex", 4, vertices=outer + inner, edges=edges, assignments=["B"] * 8)
    assert "inside another piece" in msg


def test_a_boundary_vertex_with_one_fan_is_one_sheet():
    """Vertex 4 of the two squares has two faces and one crease between them; vertex 0
    one face: each a single fan."""
    assert len(make(faces=SQ_F).faces) == 2
