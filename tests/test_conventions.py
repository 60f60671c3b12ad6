"""Reading files made for Origami Simulator: M/V without angles,
sheets in any plane, folded forms, scaling, and angles against their assignment."""
from __future__ import annotations

import json
import warnings

import numpy as np
import pytest

from foldcore.errors import PatternError, PatternWarning
from foldcore.io import Reading, pattern_from_fold_dict
from foldcore.io.conventions import into_plane
from foldcore.io.fold import fold_file_from_dict
from foldcore.measure import on_assigned_side

from test_io import fold_json, four_squares, two_squares


def without_angles(pattern) -> dict:
    d = fold_json(pattern)
    del d["edges_foldAngle"]
    return d


def read_said(d, reading=None):
    """(pattern, messages of the PatternWarnings said while reading)."""
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        pattern = fold_file_from_dict(d, "f.fold", reading).pattern
    return pattern, [str(w.message) for w in caught if w.category is PatternWarning]


def test_mv_without_angles_fold_to_180_as_in_origami_simulator():
    d = without_angles(four_squares())  # creases 8..11: V, V, V, M
    del d["foldcore:edges_maxAngle"]
    pattern, said = read_said(d)
    np.testing.assert_array_equal(pattern.fold_angles[8:], [180.0, 180.0, 180.0, -180.0])
    assert np.isnan(pattern.fold_angles[:8]).all()  # boundary
    (message,) = said
    assert "f.fold" in message and "4 M/V creases" in message and "reading.mv_without_angle='passive'" in message


def test_an_assigned_crease_folds_to_its_own_largest_angle_below_180():
    d = without_angles(four_squares())  # max angles 90, 180, 120, 60 on creases 8..11
    np.testing.assert_array_equal(read_said(d)[0].fold_angles[8:], [90.0, 180.0, 120.0, -60.0])


def test_mv_passive_keeps_the_old_meaning_and_an_explicit_null_stays_passive():
    pattern, said = read_said(without_angles(four_squares()), Reading(mv_without_angle="passive"))
    assert np.isnan(pattern.fold_angles).all() and not said
    d = fold_json(four_squares())  # the key present, every entry null: the file said so
    d["edges_foldAngle"] = [None] * len(d["edges_vertices"])
    pattern, said = read_said(d)
    assert np.isnan(pattern.fold_angles).all() and not said


def test_fold_1_0_plural_key_is_read():
    d = without_angles(two_squares())
    d["edges_foldAngles"] = [0] * 6 + [45]
    assert read_said(d)[0].fold_angles[6] == 45.0


def as_origami_simulator_writes(d: dict) -> dict:
    """Origami Simulator's exports: (x, y) → (x, 0, y), the sheet in the xz-plane."""
    d = dict(d)
    d["vertices_coords"] = [[x, 0.0, y] for x, y in d["vertices_coords"]]
    d["frame_classes"] = ["foldedForm"]
    return d


@pytest.mark.parametrize("make", [two_squares, four_squares])
def test_a_sheet_in_the_xz_plane_reads_as_the_flat_pattern(make):
    """Rotated back exactly (a quarter turn about x), faces' top side up, so every
    crease keeps its sense; said once per change."""
    flat = make()
    pattern, said = read_said(as_origami_simulator_writes(fold_json(flat)))
    np.testing.assert_allclose(pattern.vertices, flat.vertices, atol=1e-12)
    np.testing.assert_array_equal(pattern.assignments, flat.assignments)
    np.testing.assert_array_equal(pattern.fold_angles, flat.fold_angles)
    assert any("rotated by 90°" in m for m in said)
    assert any("folded form" in m for m in said)


def test_a_tilted_plane_keeps_lengths_and_the_faces_orientation():
    flat = four_squares()
    rng = np.random.default_rng(19)
    q, _ = np.linalg.qr(rng.normal(size=(3, 3)))
    q *= np.sign(np.linalg.det(q))  # a rotation
    xyz = np.column_stack([flat.vertices, np.zeros(len(flat.vertices))]) @ q.T + [5, -3, 2]
    xy = into_plane(xyz, [f.tolist() for f in flat.faces], "t.fold")
    def distances(v):
        return np.linalg.norm(v[:, None] - v[None], axis=2)
    np.testing.assert_allclose(distances(xy), distances(flat.vertices), atol=1e-9)
    def area(v, f):  # shoelace: > 0 counter-clockwise
        p, q = v[f], np.roll(v[f], -1, axis=0)
        return 0.5 * float((p[:, 0] * q[:, 1] - p[:, 1] * q[:, 0]).sum())
    assert all(area(xy, f) > 0 for f in flat.faces)  # still counter-clockwise: same top


def test_a_folded_form_reads_its_flat_unfold_coordinates():
    cp = json.load(open("tests/data/real/diagonal-cp.fold"))
    folded = json.load(open("tests/data/real/diagonal-folded.fold"))
    a, _ = read_said(cp)
    b, said = read_said(folded)
    np.testing.assert_allclose(b.vertices, a.vertices)
    assert any("vertices_flatUnfoldCoords" in m for m in said)


@pytest.mark.parametrize("inherit", [True, False])
def test_a_folded_key_frame_reads_the_crease_pattern_frame_of_its_file_frames(inherit):
    """Rabbit Ear writes a flat-folded key frame (2D, its layers over each other:
    labelled foldedForm) and the crease pattern in file_frames, labelled creasePattern,
    inheriting the key frame's edges or holding its own."""
    cp = json.load(open("tests/data/real/diagonal-cp.fold"))
    folded = json.load(open("tests/data/real/diagonal-folded.fold"))
    flat, _ = read_said(cp)
    key = {k: v for k, v in folded.items() if k != "vertices_flatUnfoldCoords"}
    key["vertices_coords"] = [row[:2] for row in key["vertices_coords"]]
    frame = {"frame_classes": ["creasePattern"], "vertices_coords": cp["vertices_coords"]}
    if inherit:
        frame.update(frame_inherit=True, frame_parent=0)
    else:
        frame.update({k: v for k, v in cp.items() if k.startswith(("edges_", "faces_"))})
    pattern, said = read_said({**key, "file_frames": [{"frame_title": "other"}, frame]})
    np.testing.assert_allclose(pattern.vertices, flat.vertices)
    np.testing.assert_array_equal(pattern.edges, flat.edges)
    assert [m for m in said if "file_frames[1] (frame_classes: creasePattern)" in m]


@pytest.mark.parametrize("label", [["creasePattern"], None])
def test_a_key_frame_without_vertices_reads_the_pattern_from_its_file_frames(label):
    """A file whose top level holds only file metadata and whose crease pattern is in
    file_frames (labelled creasePattern, or the first frame with vertices) reads as
    that frame, said once; without any frame of vertices it is refused naming the
    missing key."""
    cp = json.load(open("tests/data/real/diagonal-cp.fold"))
    flat, _ = read_said(cp)
    geometry = {k: v for k, v in cp.items() if k.startswith(("vertices_", "edges_", "faces_"))}
    frame = {**geometry, **({"frame_classes": label} if label else {})}
    top = {"file_spec": 1.1, "file_creator": "test",
           "file_frames": [{"frame_title": "notes"}, frame]}
    pattern, said = read_said(top)
    np.testing.assert_allclose(pattern.vertices, flat.vertices)
    np.testing.assert_array_equal(pattern.edges, flat.edges)
    assert [m for m in said if "the key frame holds no vertices" in m and "file_frames[1]" in m]
    with pytest.raises(PatternError, match="vertices_coords"):
        read_said({"file_spec": 1.1, "file_frames": [{"frame_title": "notes"}]})


def _edge_lengths_3d(d: dict, pattern) -> np.ndarray:
    xyz = np.array(d["vertices_coords"], dtype=float)
    xyz = np.column_stack([xyz, np.zeros(len(xyz))]) if xyz.shape[1] == 2 else xyz
    return np.linalg.norm(xyz[pattern.edges[:, 0]] - xyz[pattern.edges[:, 1]], axis=1)


@pytest.mark.parametrize("name", ["simple.fold", "squaretwist.fold"])
def test_a_folded_form_without_flat_coordinates_is_unfolded_from_its_faces(name):
    """3D folded forms (the FOLD spec's example, a square twist): every edge keeps its
    length (to the file's digits), the faces lie flat without overlapping (the
    pattern's checks), and the sheet's area is the faces' area in 3D; said once."""
    d = json.load(open(f"tests/data/real/{name}"))
    pattern, said = read_said(d, Reading(scale=1.0))  # in the file's numbers
    extent = float(np.ptp(pattern.vertices, axis=0).max())
    assert np.abs(_edge_lengths_3d(d, pattern) - pattern.edge_lengths()).max() < 1e-5 * extent
    xyz = np.array(d["vertices_coords"], dtype=float)
    area_3d = sum(0.5 * np.linalg.norm(np.cross(xyz[f], np.roll(xyz[f], -1, axis=0)).sum(0))
                  for f in map(np.array, d["faces_vertices"]))
    assert pattern.area() == pytest.approx(area_3d, rel=1e-5)
    assert [m for m in said if "unfolded from its faces" in m]


def test_a_flat_folded_form_unfolds_to_its_crease_pattern():
    """The diagonal fold folded flat (2D, its two triangles on each other), without its
    flat coordinates: the second triangle is laid beside the first, mirrored."""
    cp = json.load(open("tests/data/real/diagonal-cp.fold"))
    folded = json.load(open("tests/data/real/diagonal-folded.fold"))
    del folded["vertices_flatUnfoldCoords"]
    flat, _ = read_said(cp)
    pattern, _ = read_said(folded)
    assert pattern.area() == pytest.approx(flat.area())
    distances = lambda p: np.linalg.norm(p.vertices[:, None] - p.vertices[None], axis=2)  # noqa
    np.testing.assert_allclose(distances(pattern), distances(flat), atol=1e-12)


def test_a_folded_form_its_faces_cannot_flatten_is_refused_naming_what():
    """A square pyramid's four sides (their corners' angles sum to less than 360°) land
    their last corner at two places; a bent quadrilateral is not flat; with no faces
    a folded form says which keys would do."""
    apex = [[0.5, 0.5, 0.5]]
    base = [[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]]
    pyramid = {"vertices_coords": base + apex, "faces_vertices": [[0, 1, 4], [1, 2, 4],
                                                                  [2, 3, 4], [3, 0, 4]],
               "edges_vertices": [[0, 1], [1, 2], [2, 3], [3, 0], [0, 4], [1, 4], [2, 4],
                                  [3, 4]],
               "edges_assignment": ["B"] * 4 + ["M"] * 4}
    with pytest.raises(PatternError, match=r"f\.fold: vertex \d unfolds to two places"):
        read_said(pyramid)
    bent = {**pyramid, "vertices_coords": base[:2] + [[1, 1, 0.3], [0, 1, 0]] + apex,
            "faces_vertices": [[0, 1, 2, 3]], "edges_vertices": pyramid["edges_vertices"][:4],
            "edges_assignment": ["B"] * 4}
    bent["vertices_coords"] = bent["vertices_coords"][:4]
    with pytest.raises(PatternError, match=r"face 0 is not flat"):
        read_said(bent)
    simple = json.load(open("tests/data/real/simple.fold"))
    del simple["faces_vertices"]
    with pytest.raises(PatternError) as info:
        read_said(simple)
    assert "not on one plane" in str(info.value)
    assert "vertices_flatUnfoldCoords" in str(info.value)


def test_scale_and_sheet_size_scale_every_length():
    d = fold_json(two_squares(), **{"foldcore:thickness": 0.1})
    scaled = fold_file_from_dict(d, "f", Reading(scale=50.0))
    np.testing.assert_allclose(scaled.pattern.vertices, 50.0 * two_squares().vertices)
    assert scaled.pattern.widths[6] == pytest.approx(50.0 * 2.5)
    assert scaled.thickness == pytest.approx(5.0)
    sized = fold_file_from_dict(d, "f", Reading(size=300.0))  # extent 2 → 300 mm
    assert np.ptp(sized.pattern.vertices, axis=0).max() == pytest.approx(300.0)
    assert sized.thickness == pytest.approx(15.0)
    with pytest.raises(ValueError):
        Reading(scale=2.0, size=3.0)


def test_an_angle_against_its_assignment_is_refused_or_trusted():
    d = fold_json(two_squares())
    d["edges_foldAngle"][6] = -90.0  # a V crease at -90: Rabbit Ear's kite writes M +90
    with pytest.raises(PatternError) as info:
        pattern_from_fold_dict(d, "k.fold")
    assert "edge 6" in str(info.value) and "reading.trust_assignment=True" in str(info.value)
    pattern, said = read_said(d, Reading(trust_assignment=True))
    assert pattern.fold_angles[6] == 90.0
    assert any("1 fold angles took their assignment's sign" in m for m in said)


def test_achieved_angles_keep_the_assignments_sign_past_flat():
    """A mountain 0.54° past flat is −180.54°, not +179.46° (which contradicted 'M'
    and was painted as a valley); U creases are left as measured."""
    kinds = np.array(list("MVUMV"))
    measured = np.array([179.46, -179.41, 179.46, -30.0, 30.0])
    np.testing.assert_allclose(on_assigned_side(measured, kinds),
                               [-180.54, 180.59, 179.46, -30.0, 30.0])


def test_a_2d_folded_form_without_faces_is_read_as_drawn_and_says_so():
    folded = json.load(open("tests/data/real/diagonal-folded.fold"))
    del folded["vertices_flatUnfoldCoords"], folded["faces_vertices"]
    with pytest.raises(PatternError):   # its two layers lie on each other
        read_said(folded)
    flat = json.load(open("tests/data/real/diagonal-cp.fold"))
    flat["frame_classes"] = ["foldedForm"]
    del flat["faces_vertices"]
    pattern, said = read_said(flat, Reading(scale=1.0))
    assert pattern.area() == pytest.approx(1.0)
    assert [m for m in said if "without vertices_flatUnfoldCoords or faces" in m]


def test_drive_keeps_only_the_given_targets_and_says_how_many_it_released():
    d = fold_json(four_squares())  # targets on creases 8, 10 and 11; 9 passive
    pattern, said = read_said(d, Reading(drive=[10]))
    assert pattern.fold_angles[10] == 45.5
    assert np.isnan(pattern.fold_angles[[8, 9, 11]]).all()
    assert any("2 creases with a target left passive" in m and "reading.drive" in m
               for m in said)


@pytest.mark.parametrize("drive, words", [([2], "edge 2: it is a boundary edge"),
                                          ([40], "edge 40: the pattern has 12 edges"),
                                          ([8, 99], "edge 99"),
                                          ([9], "edge 9: it has no target angle")])
def test_drive_refuses_an_edge_it_cannot_drive_naming_it(drive, words):
    with pytest.raises(PatternError, match=words):
        read_said(fold_json(four_squares()), Reading(drive=drive))


@pytest.mark.parametrize("drive", [[], [-1], [True], [1.5], "3", [0] * 1_000_001])
def test_drive_is_a_non_empty_list_of_edge_ids(drive):
    with pytest.raises(ValueError, match="drive"):
        Reading(drive=drive)


@pytest.mark.parametrize("suffix", [".svg", ".cp"])
def test_drive_applies_to_drawings_and_line_files_as_read(tmp_path, suffix):
    """The ids are the pattern's as read (an SVG's in Origami Simulator's order)."""
    from foldcore.io import read_file

    if suffix == ".svg":
        path = "tests/data/real/waterbombBase.svg"
    else:  # a square with its two diagonals: valley and mountain (ORIPA types 3, 2)
        path = tmp_path / "x.cp"
        path.write_text("1 0 0 10 0\n1 10 0 10 10\n1 10 10 0 10\n1 0 10 0 0\n"
                        "3 0 0 10 10\n2 10 0 0 10\n")
    every = read_file(path).pattern
    driven = np.flatnonzero(~np.isnan(every.fold_angles))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", PatternWarning)
        one = read_file(path, reading=Reading(drive=[int(driven[-1])])).pattern
    assert np.flatnonzero(~np.isnan(one.fold_angles)).tolist() == [int(driven[-1])]
    assert one.fold_angles[driven[-1]] == every.fold_angles[driven[-1]]
