"""Reading at scale: the vectorised checks equal the one-by-one ones.

The planar helpers are compared with their one-by-one twins in
``tests/naive.py``, the FOLD reader's at-once paths with its row-by-row paths,
a 10⁵-vertex grid is read (its speed is measured in bench/reading.py, not
here), and a 10⁴-vertex grid read as FOLD and as OBJ peaks below 20 × its size.
"""
import json
import os
import tracemalloc
import warnings

import numpy as np
import pytest
from grids import grid_fold
from naive import crossing_pairs as naive_crossings
from naive import derive_faces as naive_derive
from naive import trace_faces as naive_trace

import foldcore
from foldcore import planar
from foldcore.errors import PatternError, PatternWarning
from foldcore.io import fold, read_fold, write_hinges, write_obj
from foldcore.io.fold import parse_fold, pattern_from_fold_dict
from foldcore.pattern import CreasePattern


def random_segments(rng, lattice: int = 4, scale: float = 1.0):
    """Up to 14 distinct non-degenerate edges on a small integer lattice: many
    touch, overlap collinearly, meet in T-junctions or cross at end points."""
    n = int(rng.integers(3, 12))
    pts = rng.integers(0, lattice, size=(n, 2)).astype(float) * scale
    e = rng.integers(0, n, size=(int(rng.integers(2, 15)), 2))
    e = e[(e[:, 0] != e[:, 1]) & (np.abs(pts[e[:, 0]] - pts[e[:, 1]]).sum(axis=1) > 0)]
    _, first = np.unique(np.sort(e, axis=1), axis=0, return_index=True)
    return pts, e[np.sort(first)]


@pytest.mark.parametrize("path", ["grid", "tree"])
@pytest.mark.parametrize("scale", [1.0, 0.1, 1e-7, 3e5])
def test_crossings_equal_brute_force(monkeypatch, path, scale):
    if path == "tree":  # the STRtree fallback for edges of very different sizes
        monkeypatch.setattr(planar, "_GRID_PAIRS_PER_EDGE", -1)
    rng = np.random.default_rng(18 + int(scale * 10) % 7)
    for _ in range(150):
        pts, e = random_segments(rng, scale=scale)
        if len(e):
            assert planar.crossing_pairs(pts, e) == naive_crossings(pts, e), (pts, e)


def test_crossings_touching_collinear_t_junction():
    # edges 0 (0–1) and 1 (2–3) cross; 2 (4–5) ends on 0 (a T-junction); 3 (6–7) and
    # 5 (5–7) overlap, sharing vertex 7; 4 (7–8) continues 3 and 2 continues 5
    # the other way from a shared vertex (legal)
    pts = np.array([[0, 0], [4, 0], [2, -1], [2, 1], [1, 0], [1, 2], [1, 3], [1, 5],
                    [1, 7.0]])
    e = np.array([[0, 1], [2, 3], [4, 5], [6, 7], [7, 8], [5, 7]])
    expected = naive_crossings(pts, e)
    assert planar.crossing_pairs(pts, e) == expected == [(0, 1), (0, 2), (3, 5)]


def test_crossings_of_a_mesh_none_then_the_added_edge():
    d = grid_fold(30, flaw="cross")
    v, e = np.array(d["vertices_coords"]), np.array(d["edges_vertices"])
    assert planar.crossing_pairs(v, e) == [(len(e) - 2, len(e) - 1)]
    assert planar.crossing_pairs(v, e[:-1]) == []


def delaunay_graph(rng, n: int):
    from scipy.spatial import Delaunay

    pts = rng.random((n, 2)) * 100
    tri = Delaunay(pts).simplices
    e = np.concatenate([tri[:, [0, 1]], tri[:, [1, 2]], tri[:, [2, 0]]])
    e = np.unique(np.sort(e, axis=1), axis=0)
    return pts, e[rng.permutation(len(e))]


@pytest.mark.parametrize("seed", range(5))
def test_faces_equal_the_edge_walk(seed):
    rng = np.random.default_rng(seed)
    pts, e = delaunay_graph(rng, 60)
    mine, theirs = planar.trace_faces(pts, e), naive_trace(pts, e)
    assert len(mine) == len(theirs)
    assert all(np.array_equal(a, b) for a, b in zip(mine, theirs))
    boundary = rng.random(len(e)) < 0.3
    mine, theirs = planar.derive_faces(pts, e, boundary, "x"), naive_derive(pts, e, boundary)
    assert len(mine) == len(theirs) and all(np.array_equal(a, b) for a, b in zip(mine, theirs))


def test_faces_of_a_grid_with_holes_equal_the_edge_walk():
    d = grid_fold(12, faces=False)
    v, e = np.array(d["vertices_coords"]), np.array(d["edges_vertices"])
    keep = np.ones(len(e), bool)
    keep[[200, 250, 300]] = False  # diagonals: merge triangles into squares
    e = e[keep]
    boundary = np.array(d["edges_assignment"])[keep] == "B"
    mine, theirs = planar.derive_faces(v, e, boundary, "x"), naive_derive(v, e, boundary)
    assert len(mine) == len(theirs) and all(np.array_equal(a, b) for a, b in zip(mine, theirs))


def test_loop_areas_keep_every_sign_and_zero():
    rng = np.random.default_rng(3)
    v = rng.integers(-3, 4, size=(40, 2)).astype(float)
    v[:5] = [[0, 0], [1e-200, 0], [2e-200, 0], [1, 1e-17], [2, 2e-17]]  # degenerate
    loops = [rng.integers(0, 40, size=int(k)) for k in rng.integers(1, 7, size=300)]
    loops += [np.array([0, 1, 2]), np.array([0, 3, 4]), np.array([3, 0, 4])]
    lengths = np.array([len(f) for f in loops])
    areas = planar.signed_areas(v, np.concatenate(loops), lengths)
    old = np.array([planar.signed_area(v[f]) for f in loops])
    assert (np.sign(areas) == np.sign(old)).all()
    np.testing.assert_allclose(areas, old, rtol=1e-12, atol=1e-12)


def same_pattern(p: CreasePattern, q: CreasePattern):
    for name in ("vertices", "edges", "assignments", "fold_angles", "widths", "max_angles",
                 "edge_faces"):
        np.testing.assert_array_equal(getattr(p, name), getattr(q, name), err_msg=name)
        assert getattr(p, name).dtype == getattr(q, name).dtype, name
    assert len(p.faces) == len(q.faces)
    assert all(np.array_equal(a, b) for a, b in zip(p.faces, q.faces))


def slow_rows(d: dict) -> dict:
    """``d`` with every array in a form the reader checks row by row (float
    ids, a 3-number vertex row, an int angle), same values."""
    d = json.loads(json.dumps(d))
    d["vertices_coords"][0] = d["vertices_coords"][0] + [0]
    d["edges_vertices"][0] = [float(x) for x in d["edges_vertices"][0]]
    d["faces_vertices"][0] = [float(x) for x in d["faces_vertices"][0]]
    d["edges_assignment"][0] = d["edges_assignment"][0].lower()
    d["edges_foldAngle"] = [None if x is None else int(x) if x == int(x) else x
                            for x in d["edges_foldAngle"]]
    return d


def test_fast_and_slow_reader_paths_build_the_same_pattern():
    d = grid_fold(40, size=2.5, unit="cm")
    same_pattern(pattern_from_fold_dict(d, "g"), pattern_from_fold_dict(slow_rows(d), "g"))
    derived = dict(d)
    del derived["faces_vertices"]
    p, q = pattern_from_fold_dict(d, "g"), pattern_from_fold_dict(derived, "g")
    assert p.n_edges == q.n_edges and len(p.faces) == len(q.faces)
    v = np.array(d["vertices_coords"], float) * 10
    e = np.array(d["edges_vertices"])
    faces = naive_derive(v, e, np.array(d["edges_assignment"]) == "B")
    assert all(np.array_equal(a, b) for a, b in zip(q.faces, faces))


def test_default_assignments_at_once_equal_face_sides():
    d = grid_fold(15)
    del d["edges_assignment"], d["edges_foldAngle"], d["faces_vertices"]
    p = pattern_from_fold_dict(d, "g")
    expected = np.array(grid_fold(15)["edges_assignment"])
    np.testing.assert_array_equal(p.assignments == "B", expected == "B")
    assert set(p.assignments[expected != "B"]) == {"U"}


def test_clockwise_faces_reversed_with_a_warning_each():
    d = grid_fold(5)
    d["faces_vertices"][3] = d["faces_vertices"][3][::-1]
    d["faces_vertices"][7] = d["faces_vertices"][7][::-1]
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        p = pattern_from_fold_dict(d, "g")
    assert [str(w.message) for w in caught if w.category is PatternWarning] == [
        "g: face 3 was clockwise; reversed to counter-clockwise",
        "g: face 7 was clockwise; reversed to counter-clockwise"]
    same_pattern(p, pattern_from_fold_dict(grid_fold(5), "g"))


@pytest.mark.parametrize(("flaw", "message"), [
    ("cross", "edges {e} and {e1} cross or overlap"),
    ("twin_vertex", "edge {e} belongs to no face"),  # its edges lie on edges as a slit's
    ("z", "vertex {v} has z = 1 where other rows are 2D; give every vertex 2 coordinates, or 3 on one plane")])
def test_flawed_grid_refused_naming_the_item(flaw, message):
    n = 60
    d = grid_fold(n, flaw=flaw)
    e = len(d["edges_vertices"]) - 2
    with pytest.raises(PatternError) as info:
        pattern_from_fold_dict(d, "g")
    assert str(info.value) == "g: " + message.format(e=e, e1=e + 1, v=n * n - 1)


def test_a_1e5_vertex_grid_reads(tmp_path):
    path = tmp_path / "grid.fold"
    path.write_text(json.dumps(grid_fold(317)))
    p = read_fold(path)
    assert p.n_vertices == 317 ** 2 == 100_489
    assert p.n_edges == 3 * 317 ** 2 - 4 * 317 + 1 and len(p.faces) == 2 * 316 ** 2
    assert (p.edge_faces >= 0).sum() == 2 * p.n_edges - 4 * 316
    assert abs(p.area() - 316.0 ** 2) < 1e-6


def grid_files(folder, n: int, fmt: str):
    """The n × n grid as ``folder``/grid.fold, or as grid.obj + grid.hinges; the path
    and the input's size in bytes (OBJ: both files)."""
    path = folder / "grid.fold"
    path.write_text(json.dumps(grid_fold(n)))
    if fmt == "fold":
        return path, path.stat().st_size
    pattern = read_fold(path)
    path = folder / "grid.obj"
    write_obj(path, pattern)
    write_hinges(path.with_suffix(".hinges"), pattern)
    return path, path.stat().st_size + path.with_suffix(".hinges").stat().st_size


@pytest.mark.parametrize("fmt", ["fold", "obj"])
def test_a_read_peaks_below_20_times_the_files_size(tmp_path, monkeypatch, fmt):
    """The peak of a read's Python allocations (NumPy's arrays included), measured
    by tracemalloc, is at most 20 × the input's size; bench/reading.py measures the
    process's resident memory from 10³ to 10⁶ vertices."""
    (tmp_path / "first").mkdir()
    foldcore.read(grid_files(tmp_path / "first", 3, fmt)[0])  # imports, first-use caches
    path, size = grid_files(tmp_path, 100, fmt)
    # read_bytes asks for a buffer as large as the file limit, resident only as far
    # as the file fills it; tracemalloc counts all of it, so the limit is the files'
    monkeypatch.setattr(fold, "MAX_FILE_BYTES", max(os.path.getsize(p) for p in
                                                    tmp_path.glob("grid.*")))
    was_tracing = tracemalloc.is_tracing()
    tracemalloc.start()
    tracemalloc.reset_peak()
    before = tracemalloc.get_traced_memory()[0]
    try:
        pattern = foldcore.read(path)
        peak = tracemalloc.get_traced_memory()[1] - before
    finally:
        if not was_tracing:
            tracemalloc.stop()
    assert pattern.n_vertices == 100 ** 2
    assert peak <= 20 * size, f"peak {peak / size:.1f} × the input's {size} bytes"


def test_huge_number_still_refused_by_the_hook():
    d = grid_fold(4)
    text = json.dumps(d).replace("[1.0, 0.0]", "[1e400, 0.0]", 1)
    with pytest.raises(PatternError, match="number 1e400 is out of range of a 64-bit float"):
        parse_fold(text.encode(), "g")
    digits = json.dumps(d).replace("[1.0, 0.0]", "[" + "9" * 400 + ".0, 0.0]", 1)
    with pytest.raises(PatternError, match="out of range of a 64-bit float"):
        parse_fold(digits.encode(), "g")


def old_merge(tris, source):
    """The STL reader's vertex merge facet by facet (as for ASCII STL)."""
    from foldcore.io.obj import _merge_vertices

    return _merge_vertices([(f"{source}, facet {i}", t.tolist()) for i, t in enumerate(tris)])


@pytest.mark.parametrize("seed", range(4))
def test_binary_stl_merge_at_once_equals_facet_by_facet(seed):
    from foldcore.io.obj import _merge_triangles

    rng = np.random.default_rng(seed)
    tris = np.zeros((200, 3, 3))
    tris[:, :, :2] = rng.integers(-2, 3, size=(200, 3, 2)) * 0.5
    xy = tris[:, :, :2]  # a view
    xy[rng.random((200, 3, 2)) < 0.2 * (seed % 2 + 1)] *= -1.0  # -0.0 beside 0.0
    if seed >= 2:  # one bad vertex (a NaN or a z), maybe after others
        f, k = rng.integers(0, 200), rng.integers(0, 3)
        tris[f, k, 2 if seed == 2 else 0] = 1.0 if seed == 2 else np.nan
        tris[min(f + 7, 199), 0, 2] = 2.0
    outcomes = []
    for merge in (old_merge, _merge_triangles):
        try:
            outcomes.append(merge(tris, "m.stl"))
        except PatternError as exc:
            outcomes.append(str(exc))
    old, new = outcomes
    if isinstance(old, str):
        assert new == old
    else:
        np.testing.assert_array_equal(new[0], old[0])
        assert np.array_equal(np.signbit(new[0]), np.signbit(old[0]))
        assert len(new[1]) == len(old[1]) and all(
            np.array_equal(a, b) for a, b in zip(new[1], old[1]))
