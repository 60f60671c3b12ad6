"""Property-based fuzzing of the crease-pattern readers.

Property: every reader either returns a valid :class:`CreasePattern` or raises
:class:`PatternError` whose message is non-empty and names the source given.
Any other exception, or the ``build_pattern`` safety net firing, is a bug.

Example counts: a few hundred per test by default (the whole file stays fast
for CI); ``FOLDCORE_FUZZ=long`` runs 10 000 per test::

    FOLDCORE_FUZZ=long python -m pytest -q tests/test_fuzz_readers.py \
        --hypothesis-show-statistics
"""
from __future__ import annotations

import copy
import json
import math
import os
import struct
import tempfile
import warnings
from contextlib import contextmanager

import numpy as np
import pytest
from hypothesis import HealthCheck, event, example, given, settings
from hypothesis import strategies as st

import foldcore.io as fio
import foldcore.files as output_files
from foldcore.errors import PatternError, PatternWarning
from foldcore.io import fold as fold_module
from foldcore.io import obj as obj_module
from foldcore.io.fold import parse_fold, pattern_from_fold_dict
from foldcore.io.obj import mesh_pattern, parse_hinges, parse_polygons
from foldcore.pattern import CreasePattern
from foldcore.planar import signed_area

# reversed clockwise faces warn by design (tests/test_io.py checks that); here only noise
pytestmark = pytest.mark.filterwarnings("ignore::foldcore.errors.PatternWarning")

_HEALTH = [HealthCheck.too_slow, HealthCheck.data_too_large, HealthCheck.filter_too_much,
           HealthCheck.function_scoped_fixture]
# CI's profile is derandomized (the same 300 inputs per test on every run: a red CI
# means a change, not a draw); the long profile explores with fresh randomness.
settings.register_profile("foldcore-fuzz", max_examples=300, deadline=None,
                          suppress_health_check=_HEALTH, derandomize=True)
settings.register_profile("foldcore-fuzz-long", max_examples=10_000, deadline=None,
                          suppress_health_check=_HEALTH)


def _profile(choice: str) -> settings:
    """``long`` → 10 000 examples per test, a number → that many, else the default."""
    if choice.isdigit():
        return settings(settings.get_profile("foldcore-fuzz"), max_examples=int(choice),
                        derandomize=False)
    return settings.get_profile("foldcore-fuzz-long" if choice == "long" else "foldcore-fuzz")


#: Applied per test (not loaded globally, so other test files keep their settings).
FUZZ = _profile(os.environ.get("FOLDCORE_FUZZ", ""))


# ------------------------------------------------------------------ property
def assert_valid(p: CreasePattern):
    """The invariants a CreasePattern promises its users."""
    assert isinstance(p, CreasePattern)
    v, e = p.vertices, p.edges
    assert v.ndim == 2 and v.shape[1] == 2 and len(v) >= 3 and np.isfinite(v).all()
    assert e.ndim == 2 and e.shape[1] == 2 and len(e) >= 3
    assert e.min() >= 0 and e.max() < len(v) and (e[:, 0] != e[:, 1]).all()
    lengths = p.edge_lengths()
    assert np.isfinite(lengths).all() and (lengths > 0).all()
    assert p.assignments.shape == (len(e),) and set(p.assignments) <= set("MVBFU")
    angles = p.fold_angles[~np.isnan(p.fold_angles)]
    assert (np.abs(angles) <= 180).all()
    widths = p.widths[~np.isnan(p.widths)]
    assert np.isfinite(widths).all() and (widths > 0).all()
    assert ((p.max_angles > 0) & (p.max_angles <= 180)).all()
    assert p.faces
    for f in p.faces:
        assert len(f) >= 3 and f.min() >= 0 and f.max() < len(v)
        area = signed_area(v[f])
        assert math.isfinite(area) and area > 0, (f, area)
    assert math.isfinite(p.area()) and p.area() > 0
    assert ((p.edge_faces >= 0).sum(axis=1) >= 1).all()


def outcome(call, *names):
    """Run a reader: the valid pattern it returns, or None when it refused.

    Fails the test on any exception but PatternError, on a refusal message
    that is empty, does not name one of ``names`` or is not printable UTF-8,
    and on the ``build_pattern`` safety net (an unexpected exception inside).
    Warnings other than PatternWarning (numpy overflow...) are errors.
    """
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        warnings.simplefilter("ignore", PatternWarning)
        try:
            result = call()
        except PatternError as exc:
            message = str(exc)
            assert message.strip(), "empty refusal message"
            assert any(name in message for name in names), (names, message)
            assert "unexpected malformed" not in message, message
            message.encode("utf-8")  # the CLI prints it
            event("refused")
            return None
    if isinstance(result, fio.FoldFile):
        assert result.thickness is None or 0 < result.thickness < math.inf, result.thickness
        assert result.frame_unit in fold_module.UNIT_MM
        result = result.pattern
    assert_valid(result)
    event("accepted")
    return result


# ----------------------------------------------------------------- base data
def _grid(nx: int, ny: int, size: float = 10.0) -> CreasePattern:
    """nx × ny squares, interior edges alternating M/V with angles."""
    vid = lambda i, j: j * (nx + 1) + i  # noqa: E731
    vertices = [[i * size, j * size] for j in range(ny + 1) for i in range(nx + 1)]
    edges, kinds, angles = [], [], []
    for j in range(ny + 1):
        for i in range(nx + 1):
            for di, dj, border in ((1, 0, j in (0, ny)), (0, 1, i in (0, nx))):
                if i + di <= nx and j + dj <= ny:
                    edges.append([vid(i, j), vid(i + di, j + dj)])
                    kind = "B" if border else "MV"[len(edges) % 2]
                    kinds.append(kind)
                    angles.append(None if kind == "B" else (-45.0 if kind == "M" else 60.0))
    return CreasePattern(vertices, edges, kinds, fold_angles=angles)


def _fan() -> CreasePattern:
    """A square cut into four triangles at its centre; creases V, V (passive), U, M."""
    vertices = [[0, 0], [2, 0], [2, 2], [0, 2], [1, 1]]
    edges = [[0, 1], [1, 2], [2, 3], [3, 0], [4, 0], [4, 1], [4, 2], [4, 3]]
    return CreasePattern(vertices, edges, list("BBBBVVUM"),
                         fold_angles=[None] * 4 + [30.0, None, -10.0, -30.0],
                         widths=[None] * 4 + [0.5, None, 0.25, 1.0],
                         max_angles=[180.0] * 4 + [90.0, 180.0, 45.0, 60.0])


BASES = [_grid(1, 1), _grid(2, 1), _grid(2, 2), _fan()]
BASE_FOLDS = [json.loads(json.dumps(fio.fold_dict(p, thickness=1.0))) for p in BASES]


def _obj_text(p: CreasePattern) -> str:
    return "".join(f"v {x!r} {y!r} 0\n" for x, y in p.vertices.tolist()) + "".join(
        "f " + " ".join(str(i + 1) for i in f.tolist()) + "\n" for f in p.faces)


def _hinge_text(p: CreasePattern) -> str:
    with tempfile.TemporaryDirectory() as folder:
        fio.write_hinges(os.path.join(folder, "h.hinges"), p)
        with open(os.path.join(folder, "h.hinges")) as fh:
            return fh.read()


def _triangles(p: CreasePattern) -> list[list[tuple[float, float]]]:
    """Fan triangulation of the faces (for STL)."""
    v = p.vertices.tolist()
    return [[tuple(v[f[0]]), tuple(v[f[k]]), tuple(v[f[k + 1]])]
            for f in p.faces for k in range(1, len(f) - 1)]


BASE_OBJS = [_obj_text(p) for p in BASES]
BASE_HINGES = [_hinge_text(p) for p in BASES]


# ---------------------------------------------------------------- strategies
NASTY_FLOATS = st.sampled_from([
    math.nan, math.inf, -math.inf, 1e308, -1e308, 1.7976931348623157e308,
    5e-324, -5e-324, 1e-300, 1e200, -1e200, 1e155, 0.0, -0.0,
    1e-12, 0.5, 180.0, 180.000001, -180.000001, 360.0])
NASTY_INTS = st.sampled_from([-1, 0, 1, 2, 3, 4, 8, 9, 24, 25, -(2 ** 63), 2 ** 63, 2 ** 64,
                              10 ** 400, True, False])
NASTY_TEXT = st.sampled_from(["", "M", "V", "B", "F", "U", "C", "J", "m", "v", "b", "f", "u",
                              "X", "MV", "ß", "ı", "\u0000", "\ud800", "Ｍ", "mm", "cm", "m",
                              "in", "pt", "um", "nm", "unit", "MM", "µm", "inch", "1", "null",
                              "NaN", "🦜"])
SCALARS = (st.none() | st.booleans() | st.integers() | NASTY_INTS | st.floats() | NASTY_FLOATS
           | st.text(max_size=6) | NASTY_TEXT)
GARBAGE = st.recursive(SCALARS, lambda kids: st.lists(kids, max_size=5)
                       | st.dictionaries(st.text(max_size=4), kids, max_size=4), max_leaves=10)
#: Python values a JSON parser never returns (pattern_from_fold_dict is public API).
#: Copied per draw: the mutations change lists in place.
PY_ODDITIES = st.sampled_from([(0, 0), (0, 1), {(1, 2): 3}, {1: "a"}, b"MV", 1 + 2j,
                               frozenset({1}), np.float64("nan"), np.float64(1.0), np.int64(1),
                               np.array([0.0, 1.0]), np.array([]), [[0, 1]] * 3,
                               float("nan"), object()]).map(copy.deepcopy)


def _vertex_count(d: dict) -> int:
    v = d.get("vertices_coords")
    return len(v) if isinstance(v, list) else 0


def _edge_lists(d: dict) -> list[str]:
    n = len(d["edges_vertices"]) if isinstance(d.get("edges_vertices"), list) else -1
    return [k for k, v in d.items() if isinstance(v, list) and len(v) == n
            and k.startswith(("edges_", "foldcore:edges_"))]


@st.composite
def fold_mutation(draw, d: dict) -> None:
    """Apply one corruption to the FOLD dict ``d`` in place."""
    keys = sorted(d) + ["frame_unit", "foldcore:thickness", "faces_vertices",
                        "foldcore:edges_targetAngle", "file_frames"]
    how = draw(st.sampled_from(["drop", "set", "item", "subitem", "truncate", "extend",
                                "dup_edge", "loop_edge", "twin_vertex", "move_vertex", "scale",
                                "unit", "assign", "face", "number", "oddity"]))
    key = draw(st.sampled_from(keys))
    nv = _vertex_count(d)
    if how == "drop":
        d.pop(key, None)
    elif how == "set":
        d[key] = draw(GARBAGE)
    elif how == "oddity":
        d[key] = draw(PY_ODDITIES) if draw(st.booleans()) or not isinstance(d.get(key), list) \
            or not d[key] else [draw(PY_ODDITIES)] + d[key][1:]
    elif how in ("item", "subitem", "truncate", "extend", "number"):
        rows = d.get(key)
        if not isinstance(rows, list) or not rows:
            d[key] = draw(GARBAGE)
            return
        i = draw(st.integers(0, len(rows) - 1))
        if how == "item":
            rows[i] = draw(GARBAGE)
        elif how == "truncate":
            d[key] = rows[:i]
        elif how == "extend":
            rows.extend(draw(st.lists(GARBAGE, min_size=1, max_size=3)))
        elif isinstance(rows[i], list) and rows[i]:
            j = draw(st.integers(0, len(rows[i]) - 1))
            rows[i][j] = draw(NASTY_FLOATS | NASTY_INTS | st.integers(-3, nv + 3)
                              if how == "number" else GARBAGE)
        else:
            rows[i] = draw(NASTY_FLOATS | NASTY_INTS)
    elif how in ("dup_edge", "loop_edge"):
        edges = d.get("edges_vertices")
        pairs = [e for e in edges if isinstance(e, (list, tuple)) and len(e) == 2] \
            if isinstance(edges, list) else []
        if not pairs or not nv:  # earlier mutations may have broken every row
            return
        extra = list(draw(st.sampled_from(pairs))) if how == "dup_edge" \
            else [draw(st.integers(0, nv - 1))] * 2
        if how == "dup_edge" and draw(st.booleans()) and isinstance(extra, list):
            extra = extra[::-1]
        for k in _edge_lists(d):
            d[k].append(extra if k == "edges_vertices" else d[k][-1])
    elif how == "twin_vertex" and nv:
        i = draw(st.integers(0, nv - 1))
        d["vertices_coords"].append(d["vertices_coords"][i])
        if isinstance(d.get("edges_vertices"), list) and d["edges_vertices"]:
            e = draw(st.integers(0, len(d["edges_vertices"]) - 1))
            if isinstance(d["edges_vertices"][e], list) and d["edges_vertices"][e]:
                d["edges_vertices"][e][0] = nv  # to the twin: maybe a zero-length edge
    elif how == "move_vertex" and nv:
        i = draw(st.integers(0, nv - 1))
        d["vertices_coords"][i] = [draw(st.floats(-30, 30) | NASTY_FLOATS)
                                   for _ in range(draw(st.integers(1, 4)))]
    elif how == "scale" and nv:
        factor = draw(st.sampled_from([1e-300, 1e-160, 1e-12, 1e100, 1e150, 1e200, 1e300, -1.0]))
        d["vertices_coords"] = [[x * factor if isinstance(x, (int, float)) else x for x in row]
                                if isinstance(row, list) else row
                                for row in d["vertices_coords"]]
    elif how == "unit":
        d["frame_unit"] = draw(NASTY_TEXT | GARBAGE)
    elif how == "assign" and isinstance(d.get("edges_assignment"), list) \
            and d["edges_assignment"]:
        i = draw(st.integers(0, len(d["edges_assignment"]) - 1))
        d["edges_assignment"][i] = draw(NASTY_TEXT)
    elif how == "face":
        faces = d.get("faces_vertices")
        if isinstance(faces, list) and faces:
            i = draw(st.integers(0, len(faces) - 1))
            faces[i] = draw(st.lists(st.integers(-3, nv + 3) | NASTY_INTS, max_size=6))
        else:
            d["faces_vertices"] = draw(st.lists(st.lists(st.integers(-1, nv), max_size=5),
                                                max_size=4))


@st.composite
def corrupted_folds(draw) -> dict:
    d = json.loads(json.dumps(draw(st.sampled_from(BASE_FOLDS))))
    for _ in range(draw(st.integers(1, 3))):
        draw(fold_mutation(d))
    return d


def _json_bytes(d) -> bytes | None:
    """``d`` as a FOLD file's bytes (NaN/Infinity literals kept), None if not JSON."""
    try:
        return json.dumps(d).encode("utf-8", "surrogatepass")
    except (TypeError, ValueError, RecursionError):
        return None


# ------------------------------------------------------------------ FOLD
@FUZZ
@given(st.one_of(st.binary(max_size=300), st.text(max_size=300).map(str.encode),
                 GARBAGE.map(lambda v: json.dumps(v).encode()),
                 corrupted_folds().map(lambda d: _json_bytes(d) or b"{}"),
                 st.sampled_from([b"[" * 100_000, b'{"a": 1e999}', b"\xef\xbb\xbf{}",
                                  b'{"vertices_coords": [[0, 0]], "edges_vertices": -0}',
                                  b"1" * 5000, b'"\\ud800"'])))
def test_fuzz_fold_bytes(data):
    """Random bytes, text and JSON (also corrupted FOLD) as a .fold file's contents."""
    outcome(lambda: parse_fold(data, "fuzz.fold"), "fuzz.fold")


@FUZZ
@given(corrupted_folds())
@example({**BASE_FOLDS[0], "frame_unit": "m", "foldcore:thickness": 1e308})  # thickness inf
@example({**BASE_FOLDS[0], "vertices_coords": [[0, 0, 0, 5], [10, 0], [10, 10], [0, 10]]})
@example({**BASE_FOLDS[0], "vertices_coords": [[0, 0], [1e200, 0], [1e200, 1e200], [0, 1e200]]})
@example({**BASE_FOLDS[0], "vertices_coords": [[0, 0], [1e-300, 0], [1e-300, 1e-300],
                                               [0, 1e-300]]})
@example({**BASE_FOLDS[0], "vertices_coords": [[0, 0], [{(1, 2): 3}], [10, 10], [0, 10]]})
@example({**BASE_FOLDS[0], "vertices_coords": [(0, 0), [10, 0], [0, 10], [10, 10]]})
@example({**BASE_FOLDS[0], "faces_vertices": np.array([])})
def test_fuzz_fold_dicts(d):
    """Corrupted FOLD dicts; the dict and its JSON file must agree."""
    got = outcome(lambda: pattern_from_fold_dict(d, "fuzz.fold"), "fuzz.fold")
    data = _json_bytes(d)
    if data is None:
        return
    from_file = outcome(lambda: parse_fold(data, "fuzz.fold"), "fuzz.fold")
    if got is not None and from_file is None:  # only JSON's lack of NaN/Infinity
        assert b"NaN" in data or b"Infinity" in data
    if from_file is not None:
        assert got is not None
        assert np.array_equal(got.vertices, from_file.vertices)
        assert np.array_equal(got.edges, from_file.edges)


@FUZZ
@given(GARBAGE | PY_ODDITIES | st.dictionaries(st.sampled_from(sorted(BASE_FOLDS[2])), GARBAGE))
def test_fuzz_fold_garbage(d):
    outcome(lambda: pattern_from_fold_dict(d, "fuzz.fold"), "fuzz.fold")


# ------------------------------------------------------------------ OBJ
OBJ_TOKENS = st.sampled_from(["0", "1", "-1", "2", "-2", "9", "0.5", "1e999", "nan", "inf",
                              "-inf", "1e308", "5e-324", "x", "", "1/1", "1//2", "2/1/1", "/1",
                              "1/", "1.0", "+1", "1_0", "٣", "９", "99999999999999999999",
                              "-99999999999999999999", "#", "\t", "\x00", "\ufffd"])


def _mutate_lines(draw, lines: list, new_line, token) -> None:
    """1–3 random edits of a file's ``lines`` in place: replace or insert a line
    drawn from ``new_line``, delete or duplicate one, or swap one of its tokens
    for one drawn from ``token``."""
    for _ in range(draw(st.integers(1, 3))):
        k = draw(st.integers(0, len(lines)))
        how = draw(st.sampled_from(["replace", "insert", "delete", "duplicate", "token"]))
        if how == "replace" and k < len(lines):
            lines[k] = draw(new_line)
        elif how == "insert":
            lines.insert(k, draw(new_line))
        elif how == "delete" and k < len(lines):
            del lines[k]
        elif how == "duplicate" and k < len(lines):
            lines.insert(k, lines[k])
        elif k < len(lines):
            tokens = lines[k].split()
            j = draw(st.integers(0, len(tokens)))
            tokens[j:j + 1] = [draw(token)]
            lines[k] = " ".join(tokens)


@st.composite
def obj_line(draw, n_vertices: int) -> str:
    kind = draw(st.sampled_from(["v", "f", "vt", "vn", "o", "g", "s", "usemtl", "V", "F", "#",
                                 "fo", "l", ""]))
    numbers = st.integers(-n_vertices - 2, n_vertices + 2).map(str) | OBJ_TOKENS \
        | st.floats().map(repr)
    return " ".join([kind] + draw(st.lists(numbers, max_size=6)))


@st.composite
def corrupted_objs(draw) -> tuple[str, str]:
    """(OBJ text, hinge text) of a base mesh with a few lines corrupted."""
    i = draw(st.integers(0, len(BASES) - 1))
    lines, hinges = BASE_OBJS[i].splitlines(), BASE_HINGES[i]
    _mutate_lines(draw, lines, obj_line(BASES[i].n_vertices),
                  OBJ_TOKENS | st.integers(-9, 9).map(str))
    newline = draw(st.sampled_from(["\n", "\r\n", "\r"]))
    return newline.join(lines) + newline, hinges


def _mesh(data: bytes, hinges: bytes, name: str = "fuzz.obj"):
    return mesh_pattern(*parse_polygons(data, name), hinges, name, "fuzz.hinges")


@FUZZ
@given(corrupted_objs())
@example(("v 0 0\nv 1 0\nv 1 1\nv 0 1\nf 1 2 3\nf 1 3 5\n", "2 1 V\n"))  # face out of range
@example(("v 0 0\nv 1 0\nv 1 1\nv 0 1\nf 1 2 3\nf 1 3 -5\n", "2 1 V\n"))  # negative too far
@example(("v 0 0\nv 1 0\nv 1 1\nf 1 2\n", ""))  # too few vertices
@example(("v 0 0\nv 1 0\nv 1 1\nf 1 1 1\n", ""))  # one vertex thrice
def test_fuzz_obj_text(case):
    obj, hinges = case
    outcome(lambda: _mesh(obj.encode("utf-8", "surrogatepass"), hinges.encode()),
            "fuzz.obj", "fuzz.hinges")


@FUZZ
@given(st.lists(st.integers(0, 3).flatmap(obj_line), max_size=12).map("\n".join),
       st.text(max_size=60))
def test_fuzz_obj_random(obj, hinges):
    outcome(lambda: _mesh(obj.encode(), hinges.encode("utf-8", "surrogatepass")),
            "fuzz.obj", "fuzz.hinges")


# ------------------------------------------------------------------ STL
STL_FLOATS = st.floats(width=32) | st.sampled_from([math.nan, math.inf, -math.inf, 3.4e38,
                                                    1e-45, -0.0])


def _binary_stl(tris, header: bytes = b"\0" * 80, count: int | None = None) -> bytes:
    count = len(tris) if count is None else count
    return header[:80].ljust(80, b"\0") + struct.pack("<I", count) + b"".join(
        struct.pack("<3f", 0, 0, 1) + b"".join(struct.pack("<3f", *xyz) for xyz in t) + b"\0\0"
        for t in tris)


def _ascii_stl(tris, fmt=repr) -> str:
    return "solid s\n" + "".join(
        "facet normal 0 0 1\n  outer loop\n" + "".join(
            f"    vertex {' '.join(fmt(c) for c in xyz)}\n" for xyz in t)
        + "  endloop\nendfacet\n" for t in tris) + "endsolid s\n"


STL_WORDS = st.sampled_from(["solid", "facet", "normal", "outer", "loop", "vertex", "endloop",
                             "endfacet", "endsolid", "VERTEX", "Outer", "0", "1", "-1", "nan",
                             "inf", "1e39", "x", "0.5"])


@st.composite
def corrupted_stls(draw) -> tuple[bytes, str]:
    """(STL bytes, hinge text): base triangles, ASCII or binary, with 0-2 corruptions."""
    p = draw(st.sampled_from(BASES))
    tris = [[(x, y, 0.0) for x, y in t] for t in _triangles(p)]
    faces = obj_module._merge_vertices([("", t) for t in tris])[1]
    hinges = "".join(f"{i} auto U\n" for i, n in enumerate(obj_module._edge_table(faces)[1])
                     if n == 2)
    bad = draw(st.sets(st.sampled_from(["coord", "header", "count", "lines", "cut", "tail",
                                        "hinges"]), max_size=2))
    if "coord" in bad:
        t, k, c = (draw(st.integers(0, len(tris) - 1)), draw(st.integers(0, 2)),
                   draw(st.integers(0, 2)))
        tris[t][k] = tris[t][k][:c] + (draw(STL_FLOATS),) + tris[t][k][c + 1:]
    if draw(st.booleans()):
        header = draw(st.sampled_from([b"", b"solid s", b"solid", b"\xff" * 80])) \
            if "header" in bad else b""
        count = draw(st.integers(0, 2 ** 32 - 1) | st.sampled_from(
            [len(tris) + 1, len(tris) - 1, 0])) if "count" in bad else None
        data = _binary_stl(tris, header, count)
    else:
        lines = _ascii_stl(tris, draw(st.sampled_from([repr, str, lambda c: f"{c:.3e}"]))) \
            .splitlines()
        for _ in range(draw(st.integers(1, 2)) if "lines" in bad else 0):
            k = draw(st.integers(0, len(lines) - 1))
            how = draw(st.sampled_from(["delete", "duplicate", "replace"]))
            if how == "delete":
                del lines[k]
            elif how == "duplicate":
                lines.insert(k, lines[k])
            else:
                lines[k] = " ".join(draw(st.lists(STL_WORDS, min_size=1, max_size=5)))
        data = "\n".join(lines).encode()
    if "cut" in bad:
        data = data[:draw(st.integers(0, len(data)))]
    if "tail" in bad:
        data += draw(st.binary(min_size=1, max_size=60))
    return data, draw(st.text(max_size=30)) if "hinges" in bad else hinges


@FUZZ
@given(corrupted_stls())
@example((_binary_stl([[(0, 0, 0), (1, 0, 0), (1, 1, 0)]] * 2)[:-10], ""))  # truncated
@example((_binary_stl([[(0, 0, 0), (1, 0, 0), (1, 1, 0)]], count=2), ""))  # wrong count
@example((_binary_stl([[(0, 0, 0), (math.nan, 0, 0), (1, 1, 0)]]), ""))  # NaN
@example((_ascii_stl([[(0, 0, 0), (1, 0, 0), (1, 1, 0)], [(0, 0, 0), (1, 1, 0), (0, 1, 0)]])
          .rsplit("endloop", 1)[0].encode(), "2 auto U\n"))  # truncated, last loop unclosed
def test_fuzz_stl(case):
    data, hinges = case
    outcome(lambda: _mesh(data, hinges.encode("utf-8", "surrogatepass"), "fuzz.stl"),
            "fuzz.stl", "fuzz.hinges")


# ------------------------------------------------------------------ hinges
HINGE_TOKENS = st.sampled_from(["0", "1", "2", "-1", "1.0", "99", "1e3", "auto", "AUTO", "Auto",
                                "0", "-0", "nan", "inf", "1e999", "1e308", "5e-324", "M", "V",
                                "F", "U", "B", "C", "m", "v", "ß", "90", "-90", "180", "180.5",
                                "-180", "+45", "max=", "max=0", "max=45", "MAX=90", "max=181",
                                "max=nan", "max=1e-300", "max=-5", "#", "x", "\ufffd", "٣"])


@st.composite
def corrupted_hinges(draw) -> tuple[int, str]:
    i = draw(st.integers(0, len(BASES) - 1))
    lines = BASE_HINGES[i].splitlines()
    n_edges = BASES[i].n_edges
    line = st.lists(HINGE_TOKENS | st.integers(-2, n_edges + 2).map(str)
                    | st.floats().map(repr), max_size=6).map(" ".join)
    _mutate_lines(draw, lines, line, HINGE_TOKENS)
    return i, "\n".join(lines) + "\n"


@FUZZ
@given(corrupted_hinges())
@example((0, "4 auto X\n"))  # unknown kind
@example((0, "99 auto V\n"))  # edge id out of range
@example((0, "-1 auto V\n"))  # negative edge id
@example((0, "4 auto V nan\n"))  # bad angle
@example((0, "4 auto M 200\n"))  # angle out of range
def test_fuzz_hinges(case):
    i, text = case
    outcome(lambda: mesh_pattern(*parse_polygons(BASE_OBJS[i].encode(), "base.obj"),
                                 text.encode("utf-8", "surrogatepass"), "base.obj",
                                 "fuzz.hinges"), "base.obj", "fuzz.hinges")


@FUZZ
@given(st.text(max_size=120), st.integers(-1, 20))
def test_fuzz_parse_hinges_text(text, n_edges):
    try:
        table = parse_hinges(text, "fuzz.hinges", n_edges)
    except PatternError as exc:
        assert "fuzz.hinges" in str(exc)
        return
    for edge, (width, kind, angle, max_angle, line) in table.items():
        assert 0 <= edge < n_edges and kind in "MVFU" and 0 < max_angle <= 180
        assert math.isnan(width) or width > 0
        assert math.isnan(angle) or abs(angle) <= 180


# ------------------------------------------------------------------- files
@pytest.fixture(scope="module")
def fuzz_dir():
    with tempfile.TemporaryDirectory() as folder:
        yield folder


SUFFIXES = {"fold": [".fold", ".FOLD"], "obj": [".obj", ".OBJ"], "stl": [".stl", ".Stl"],
            "other": [".txt", "", ".hinges", ".fold.bak"]}


@st.composite
def files(draw) -> tuple[str, bytes, bytes | None]:
    """(file name, contents, hinge contents or None): matching suffix most of the time."""
    kind = draw(st.sampled_from(["fold", "obj", "stl", "random"]))
    hinges = None
    if kind == "fold":
        blob = _json_bytes(draw(corrupted_folds())) or b"{}"
    elif kind == "obj":
        text, hinge_text = draw(corrupted_objs())
        blob, hinges = text.encode("utf-8", "surrogatepass"), hinge_text.encode()
    elif kind == "stl":
        blob, hinge_text = draw(corrupted_stls())
        hinges = hinge_text.encode("utf-8", "surrogatepass")
    else:
        blob = draw(st.binary(max_size=200))
    if kind == "random" or draw(st.integers(0, 4)) == 0:
        kind = draw(st.sampled_from(sorted(SUFFIXES)))
    if kind == "random" or draw(st.integers(0, 4)) == 0:
        hinges = draw(st.none() | st.binary(max_size=80))
    stem = draw(st.sampled_from(["p", "ünï cødé", "with space", "a.b", ""]))
    return (stem + draw(st.sampled_from(SUFFIXES[kind]))) or "p", blob, hinges


@FUZZ
@given(case=files(), explicit=st.booleans())
def test_fuzz_files(fuzz_dir, case, explicit):
    """Through real files and :func:`foldcore.io.read`, with or without hinge files."""
    name, blob, hinges = case
    path = os.path.join(fuzz_dir, name)
    hinge_path = os.path.join(fuzz_dir, "other.txt" if explicit else
                              os.path.splitext(name)[0] + ".hinges")
    for leftover in os.listdir(fuzz_dir):
        os.unlink(os.path.join(fuzz_dir, leftover))
    with open(path, "wb") as fh:
        fh.write(blob)
    if hinges is not None and hinge_path != path:
        with open(hinge_path, "wb") as fh:
            fh.write(hinges)
    kw = {"hinges": hinge_path} if explicit else {}
    outcome(lambda: fio.read(path, **kw), path, hinge_path)


# --------------------------------------------------------------------- svg
_SVG_NUMBERS = ["0", "50", "100", "-3.5", "1e308", "-1e308", "1e309", "nan", "inf", "-inf",
                "", "2em", "50%", "3mm", "1e-320", "0x10", "١٢", "5 5", "--1", ".5e"]
_SVG_STROKES = ["#f00", "#00f", "#000", "#ff0", "#f0f", "#0f0", "red", "none", "rgb(0,0,300)",
                "url(#x)", "#12345", ""]
_SVG_TRANSFORMS = ["scale({})", "translate({},{})", "rotate({})", "rotate({} 50 50)",
                   "matrix({},0,0,{},0,0)", "skewX({})", "scale({}) rotate(30)"]


@st.composite
def svg_shapes(draw, depth: int = 0) -> str:
    """One element: a stroked shape with numbers from the extremes, or a group of them
    (some transformed, some nested)."""
    number = st.sampled_from(_SVG_NUMBERS) | st.floats(-1e3, 1e3).map(repr)
    kind = draw(st.sampled_from(["line", "rect", "polyline", "path", "g", "text", "circle"]
                                if depth < 3 else ["line", "rect"]))
    attrs = {"stroke": draw(st.sampled_from(_SVG_STROKES)), "fill": "none"}
    if draw(st.booleans()):
        attrs[draw(st.sampled_from(["opacity", "stroke-opacity"]))] = draw(number)
    if draw(st.integers(0, 3)) == 0:
        form = draw(st.sampled_from(_SVG_TRANSFORMS))
        attrs["transform"] = form.format(*[draw(number) for _ in range(form.count("{}"))])
    if kind == "g":
        body = "".join(draw(st.lists(svg_shapes(depth + 1), max_size=3)))
    else:
        keys = {"line": ["x1", "y1", "x2", "y2"], "rect": ["x", "y", "width", "height"],
                "circle": ["cx", "cy", "r"], "text": ["x", "y"]}.get(kind, [])
        attrs.update({k: draw(number) for k in keys})
        if kind == "polyline":
            attrs["points"] = " ".join(f"{draw(number)},{draw(number)}"
                                       for _ in range(draw(st.integers(0, 4))))
        if kind == "path":
            attrs["d"] = "M" + " L".join(f"{draw(number)} {draw(number)}"
                                         for _ in range(draw(st.integers(1, 4))))
        body = "x" if kind == "text" else ""
    text = " ".join(f'{k}="{v}"' for k, v in attrs.items())
    return f"<{kind} {text}>{body}</{kind}>"


_SVG_OPENINGS = ['<svg xmlns="http://www.w3.org/2000/svg" width="100px" height="100px" '
                 'viewBox="0 0 100 100">', '<svg xmlns="http://www.w3.org/2000/svg">',
                 '<svg xmlns="http://www.w3.org/2000/svg" width="2em" height="1e309" '
                 'viewBox="0 0 nan 100">', '<svg width="100" height="100">',
                 '<html xmlns="http://www.w3.org/2000/svg">']
_SQUARE = '<rect x="0" y="0" width="100" height="100" fill="none" stroke="#000"/>'


@st.composite
def svg_documents(draw) -> bytes:
    """A drawing of the square sheet plus generated shapes, sometimes wrapped in
    deep groups, entity declarations or a long comment, sometimes cut short."""
    opening = draw(st.sampled_from(_SVG_OPENINGS))
    closing = "</html>" if opening.startswith("<html") else "</svg>"
    body = _SQUARE + "".join(draw(st.lists(svg_shapes(), max_size=6)))
    wrap = draw(st.integers(0, 9))
    if wrap == 0:
        body = "<g>" * 120 + body + "</g>" * 120
    elif wrap == 1:
        opening = '<!DOCTYPE svg [<!ENTITY a "aaaaaaaaaa"><!ENTITY b "&a;&a;&a;&a;">]>' \
            + opening
        body += "<desc>&b;</desc>"
    elif wrap == 2:
        body += "<!--" + "-" * draw(st.integers(0, 3)) + "x" * 10_000 + "-->"
    text = (opening + body + closing).encode()
    if draw(st.integers(0, 5)) == 0:
        text = text[:draw(st.integers(0, len(text)))]
    return text


def read_written(fuzz_dir, name: str, blob: bytes):
    """``blob`` written as ``name`` in ``fuzz_dir``, through :func:`foldcore.io.read`
    (:func:`outcome`)."""
    path = os.path.join(fuzz_dir, name)
    with open(path, "wb") as fh:
        fh.write(blob)
    return outcome(lambda: fio.read(path), path)


@FUZZ
@given(blob=svg_documents())
def test_fuzz_svg(fuzz_dir, blob):
    """Generated drawings through :func:`foldcore.io.read`: a valid pattern or one
    line naming the file."""
    read_written(fuzz_dir, "p.svg", blob)


_REAL_SVG = sorted(p for p in os.listdir("tests/data/real") if p.endswith(".svg"))


@FUZZ
@given(name=st.sampled_from(_REAL_SVG), cuts=st.lists(
    st.tuples(st.floats(0, 1), st.integers(0, 40), st.binary(max_size=12)), max_size=4))
def test_fuzz_svg_mutated_real_files(fuzz_dir, name, cuts):
    """Real drawings (Origami Simulator's among them) with bytes deleted and inserted
    at random places."""
    with open(os.path.join("tests/data/real", name), "rb") as fh:
        blob = bytearray(fh.read())
    for where, length, insert in cuts:
        at = int(where * len(blob))
        blob[at:at + length] = insert
    read_written(fuzz_dir, "m.svg", bytes(blob))


_CP_SQUARE = ["1 0 0 100 0", "1 100 0 100 100", "1 100 100 0 100", "1 0 100 0 0"]
_CP_NUMBERS = st.one_of(st.integers(-10, 110).map(str), st.floats(allow_nan=True,
                        allow_infinity=True).map(repr), st.sampled_from(
                        ["1e309", "-0", "1e-320", "0x10", "", "nan", "1_0"]))


@st.composite
def cp_texts(draw) -> bytes:
    """The square sheet plus generated lines: well-formed ones on a small grid (so they
    cross, overlap and meet), wrong field counts, garbage and odd numbers."""
    lines = list(_CP_SQUARE)
    grid = st.integers(0, 4).map(lambda i: str(25 * i))
    clean = draw(st.booleans())  # only well-formed lines: patterns to read, not refusals
    for _ in range(draw(st.integers(0, 12))):
        if clean or draw(st.integers(0, 3)):  # well formed, on a 25-unit grid
            kind = draw(st.sampled_from(["2", "3", "4", "1"]))
            lines.append(" ".join([kind] + [draw(grid) for _ in range(4)]))
            continue
        kind = draw(st.sampled_from(["0", "1", "2", "3", "4", "5", "-1", "x", "2.0"]))
        count = draw(st.sampled_from([4, 4, 4, 4, 3, 5, 0]))
        lines.append(" ".join([kind] + [draw(_CP_NUMBERS) for _ in range(count)]))
    if not clean and draw(st.integers(0, 6)) == 0:
        lines.append(draw(NASTY_TEXT))
    text = "\n".join(draw(st.permutations(lines))).encode("utf-8", "surrogatepass")
    if not clean and draw(st.integers(0, 6)) == 0:
        text = text[:draw(st.integers(0, len(text)))] + draw(st.binary(max_size=8))
    return text


@FUZZ
@given(blob=cp_texts())
def test_fuzz_cp(fuzz_dir, blob):
    """Generated .cp files through :func:`foldcore.io.read`: a valid pattern or one
    line naming the file."""
    read_written(fuzz_dir, "p.cp", blob)


@st.composite
def opx_texts(draw) -> bytes:
    """ORIPA's XML of generated ``.cp`` lines (:func:`cp_texts`, each field a property,
    escaped), sometimes with an element renamed, a DTD with entities, or cut short."""
    from xml.sax.saxutils import escape

    from test_opx import HEAD, TAIL

    lines = draw(cp_texts()).decode("utf-8", "replace").splitlines()
    body = []
    for i, line in enumerate(lines):
        fields = line.split()
        kinds = ["int"] + ["double"] * (len(fields) - 1)
        props = "".join(f'<void property="{name}"><{kind}>{escape(value)}</{kind}></void>'
                        for name, kind, value in zip(("type", "x0", "y0", "x1", "y1"), kinds,
                                                     fields))
        body.append(f'<void index="{i}"><object class="oripa.OriLineProxy">{props}</object>'
                    "</void>")
    text = HEAD.format(n=len(lines)) + "".join(body) + TAIL
    twist = draw(st.integers(0, 7))
    if twist == 0:
        text = text.replace("<double>", "<string>", 1).replace("</double>", "</string>", 1)
    elif twist == 1:
        text = text.replace("<java", '<!DOCTYPE java [<!ENTITY a "aaaa">]><java', 1)
    elif twist == 2:
        text = text.replace('class="oripa.OriLineProxy"', 'class="x"', 1)
    blob = text.encode("utf-8", "surrogatepass")
    if draw(st.integers(0, 6)) == 0:
        blob = blob[:draw(st.integers(0, len(blob)))]
    return blob


@FUZZ
@given(blob=opx_texts())
def test_fuzz_opx(fuzz_dir, blob):
    """Generated ORIPA .opx files through :func:`foldcore.io.read`: a valid pattern or
    one line naming the file."""
    read_written(fuzz_dir, "p.opx", blob)


# -------------------------------------------------------- plain regressions
@pytest.mark.parametrize("path", ["bad\0name.fold", "bad\0name.obj", "bad\0name.stl"])
def test_nul_in_path_refused(path):
    """Before: ValueError (embedded null byte) from os.stat."""
    with pytest.raises(PatternError, match="bad.name.*invalid path"):
        fio.read(path, hinges="h.hinges" if not path.endswith(".fold") else None)


@pytest.mark.parametrize("name", ["d.fold", "d.obj", "d.stl"])
def test_directory_refused(tmp_path, name):
    os.mkdir(tmp_path / name)
    with pytest.raises(PatternError, match="cannot read"):
        fio.read(tmp_path / name, hinges=tmp_path if name != "d.fold" else None)


@pytest.mark.parametrize("suffix", [".fold", ".obj", ".stl", ".hinges", ".cp", ".opx"])
def test_size_limit_every_reader(tmp_path, monkeypatch, suffix):
    """FOLD, OBJ, STL, .cp, .opx and hinge files are all refused above MAX_FILE_BYTES,
    unopened."""
    from test_opx import opx_text

    p = BASES[2]
    fio.write_fold(tmp_path / "p.fold", p)
    cp = [f"2 {a[0]} {a[1]} {b[0]} {b[1]}" for a, b in p.vertices[p.edges]]
    (tmp_path / "p.cp").write_text("".join(line + "\n" for line in cp))
    (tmp_path / "p.opx").write_text(opx_text(cp))
    fio.write_obj(tmp_path / "p.obj", p)
    fio.write_hinges(tmp_path / "p.hinges", p)
    (tmp_path / "p.stl").write_text(_ascii_stl([[(x, y, 0.0) for x, y in t]
                                                for t in _triangles(p)]))
    (tmp_path / "small.obj").write_text("v 0 0\nv 1 0\nv 0 1\nf 1 2 3\n")
    too_big = tmp_path / f"p{suffix}"
    size = os.path.getsize(too_big)
    monkeypatch.setattr(fold_module, "MAX_FILE_BYTES", size - 1)
    opened, real_open = [], open

    def spy(file, *args, **kw):
        opened.append(os.fspath(file))
        return real_open(file, *args, **kw)

    monkeypatch.setattr("builtins.open", spy)
    mesh = tmp_path / ("small.obj" if suffix == ".hinges" else f"p{suffix}")
    with pytest.raises(PatternError, match=rf"p\{suffix}: file is {size} bytes.*{size - 1}"):
        fio.read(mesh, hinges=tmp_path / "p.hinges" if suffix not in (".fold", ".cp", ".opx")
                 else None)
    assert str(too_big) not in opened


FOLD_REGRESSIONS = {  # name: (change to a valid FOLD dict, what the message must contain)
    # before: accepted, FoldFile.thickness = inf
    "thickness": ({"frame_unit": "m", "foldcore:thickness": 1e308},
                  ["foldcore:thickness = 1e+308 overflows", "frame_unit"]),
    # before: accepted, the 4th coordinate silently dropped (message said "z = 0" if nonzero)
    "4d": ({"vertices_coords": [[0, 0, 0, 5], [10, 0], [0, 10], [10, 10]]},
           ["vertex 0", "[0, 0, 0, 5]"]),
    # before: accepted with area inf (or "edge 0 has zero length"; numpy/shapely overflow)
    "huge": ({"vertices_coords": [[0, 0], [1e200, 0], [0, 1e200], [1e200, 1e200]]},
             ["vertex 1", "1e+200", "mm"]),
    # before: "vertex 1 has a non-finite coordinate (inf, 0.0)" for a finite 1e307 m
    "unit_overflow": ({"frame_unit": "m",
                       "vertices_coords": [[0, 0], [1e307, 0], [0, 1e307], [1e307, 1e307]]},
                      ["vertex 1", "1e+307", "overflows"]),
    # before: "edge 0 belongs to no face" (the areas underflow to 0)
    "tiny": ({"vertices_coords": [[0, 0], [1e-300, 0], [0, 1e-300], [1e-300, 1e-300]]},
             ["1e-300 mm across"]),
    # before: TypeError (json.dumps of a tuple key in the error message)
    "tuple_key": ({"vertices_coords": [[0, 0], {(1, 2): 3}, [0, 10], [10, 10]]},
                  ["vertices_coords[1]", "(1, 2)"]),
}


@pytest.mark.parametrize("name", sorted(FOLD_REGRESSIONS))
def test_fold_regressions(name):
    change, needles = FOLD_REGRESSIONS[name]
    with pytest.raises(PatternError) as info:
        fio.fold.fold_file_from_dict({**BASE_FOLDS[0], **change}, "r.fold")
    for needle in ["r.fold: "] + needles:
        assert needle in str(info.value), str(info.value)


def test_fold_dict_with_an_array_among_its_frame_classes():
    """A caller's dict whose ``frame_classes`` holds a numpy array: not a class name
    (``"foldedForm" in classes`` compared it element-wise and raised ValueError)."""
    d = copy.deepcopy(BASE_FOLDS[0])
    d["frame_classes"] = [np.array([0.0, 1.0])]
    assert_valid(pattern_from_fold_dict(d, "dict"))


def test_fold_dict_python_sequences():
    """A Python caller's tuples and an empty NumPy faces array read as the equivalent
    JSON file does."""
    d = BASE_FOLDS[0]
    expected = parse_fold(json.dumps(d).encode(), "r.fold").pattern
    for change in ({"vertices_coords": [tuple(v) for v in d["vertices_coords"]],
                    "edges_vertices": tuple(tuple(e) for e in d["edges_vertices"])},
                   {"faces_vertices": ()}):
        got = pattern_from_fold_dict({**d, **change}, "r.fold")
        assert np.array_equal(got.vertices, expected.vertices)
        assert np.array_equal(got.edges, expected.edges)
    with pytest.raises(PatternError, match="r.fold: faces_vertices must be a list, got ndarray"):
        pattern_from_fold_dict({**d, "faces_vertices": np.array([])}, "r.fold")


STL_TRIS = [[(0, 0, 0), (1, 0, 0), (1, 1, 0)], [(0, 0, 0), (1, 1, 0), (0, 1, 0)]]
STL_REGRESSIONS = {  # name: (file bytes, what the message must contain)
    # before: "the mesh has no faces" (read as ASCII)
    "binary_truncated": (_binary_stl(STL_TRIS)[:-10],
                         ["2 triangles", "184 bytes", "has 174 bytes"]),
    "binary_count": (_binary_stl(STL_TRIS, count=3), ["3 triangles", "234 bytes", "has 184"]),
    "binary_short": (b"\0" * 40, ["40 bytes", "too short"]),
    # before: accepted, the last facet silently dropped
    "ascii_truncated": (_ascii_stl(STL_TRIS).rsplit("endloop", 1)[0].encode(),
                        ["line 10", "no 'endloop'"]),
    # before: accepted, the first of the two loops silently dropped
    "ascii_nested": (_ascii_stl(STL_TRIS).replace("endloop", "", 1).encode(),
                     ["line 10", "'outer loop' before the 'endloop'", "line 3"]),
}


@pytest.mark.parametrize("name", sorted(STL_REGRESSIONS))
def test_stl_regressions(name):
    data, needles = STL_REGRESSIONS[name]
    with pytest.raises(PatternError) as info:
        parse_polygons(data, "r.stl")
    for needle in ["r.stl"] + needles:
        assert needle in str(info.value), str(info.value)


# ----------------------------------------------------------- atomic writes
class _Boom(RuntimeError):
    pass


def _writers(p):
    return {"fold": lambda path: fio.write_fold(path, p),
            "obj": lambda path: fio.write_obj(path, p),
            "hinges": lambda path: fio.write_hinges(path, p)}


@pytest.mark.parametrize("writer", ["fold", "obj", "hinges"])
@pytest.mark.parametrize("fail_at", ["write", "fsync", "interrupt"])
@pytest.mark.parametrize("existing", [False, True])
def test_writers_are_atomic(tmp_path, monkeypatch, writer, fail_at, existing):
    """A failure mid-write leaves no partial target, no temp file, and old data intact."""
    target = tmp_path / f"out.{writer}"
    if existing:
        target.write_text("old contents\n")
    written = []

    class Failing:
        """A file object that fails on the third write (after real data went out)."""
        def __init__(self, fh):
            self.fh = fh

        def write(self, text):
            written.append(text)
            if len(written) == 3:
                raise (KeyboardInterrupt if fail_at == "interrupt" else _Boom)("mid-write")
            return self.fh.write(text)

        def __getattr__(self, name):
            return getattr(self.fh, name)

    real = output_files.atomic_write

    @contextmanager
    def wrapped(path):
        with real(path) as fh:
            yield Failing(fh) if fail_at != "fsync" else fh

    if fail_at == "fsync":
        def failing_fsync(fd):
            raise _Boom("fsync failed")
        monkeypatch.setattr(os, "fsync", failing_fsync)
    monkeypatch.setattr(output_files, "atomic_write", wrapped)   # every writer's one way out
    with pytest.raises(KeyboardInterrupt if fail_at == "interrupt" else _Boom):
        _writers(BASES[2])[writer](target)
    assert sorted(os.listdir(tmp_path)) == ([target.name] if existing else [])
    if existing:
        assert target.read_text() == "old contents\n"
    if fail_at != "fsync":
        assert len(written) == 3  # it failed mid-write, not before


@pytest.mark.parametrize("existing", [False, True])
def test_serialisation_errors_are_atomic(tmp_path, monkeypatch, existing):
    """Real failures while serialising: an unserialisable extra key (written last), and
    a hinge line that cannot be formatted."""
    calls = []

    def failing_fields(pattern, e):
        calls.append(e)
        if len(calls) == 2:
            raise _Boom("cannot format")
        return real_fields(pattern, e)

    real_fields = obj_module._hinge_fields
    monkeypatch.setattr(obj_module, "_hinge_fields", failing_fields)
    for name, write, error in (
            ("out.fold", lambda t: fio.write_fold(t, BASES[2], extra={"x:bad": object()}),
             TypeError),
            ("out.hinges", lambda t: fio.write_hinges(t, BASES[2]), _Boom)):
        target = tmp_path / name
        if existing:
            target.write_text("old contents\n")
        with pytest.raises(error):
            write(target)
        assert sorted(os.listdir(tmp_path)) == ([name] if existing else [])
        if existing:
            assert target.read_text() == "old contents\n"
            target.unlink()


@pytest.mark.parametrize("writer", ["fold", "obj", "hinges"])
def test_writers_replace_whole_file(tmp_path, writer):
    target = tmp_path / f"out.{writer}"
    target.write_text("OLD\n" * 100_000)
    _writers(BASES[2])[writer](target)
    assert os.listdir(tmp_path) == [target.name]
    assert "OLD" not in target.read_text()


def test_atomic_write_long_name(tmp_path):
    """A legal 255-byte file name: the temporary name must not exceed NAME_MAX."""
    target = tmp_path / ("a" * 250 + ".fold")
    fio.write_fold(target, BASES[0])
    assert os.listdir(tmp_path) == [target.name]
    assert_valid(fio.read_fold(target))


def test_a_huge_bad_line_gives_a_short_message():
    """A refusal quotes at most ~60 characters of the offending line."""
    from foldcore.io.obj import parse_obj

    with pytest.raises(PatternError) as err:
        parse_obj("v 0 0\nv 1 0\nv 0 1\nf 1 2 " + "x" * 100_000 + "\n", "big.obj")
    assert "big.obj, line 4" in str(err.value) and len(str(err.value)) < 300


def test_a_large_file_packed_with_empty_lists_is_refused_before_parsing(tmp_path):
    """``[],`` repeated needs about 25 × its size in memory as Python lists; a file
    over 1 MiB with more than one array or object per 6 bytes is refused unparsed,
    while the same size of FOLD rows (``[1,2],``: 6 bytes each) reads."""
    from foldcore.io.fold_json import BYTES_PER_CONTAINER, DENSE_FROM_BYTES

    head = ('{"vertices_coords":[[0,0],[1,0],[0,1]],"faces_vertices":[[0,1,2]],'
            '"edges_vertices":[[0,1],[1,2],[2,0]],"edges_assignment":["B","B","B"],"x":[')
    rows = DENSE_FROM_BYTES // 3 + 10
    dense = tmp_path / "dense.fold"
    dense.write_text(head + "[]," * rows + "[]]}")
    with pytest.raises(PatternError, match=r"dense.fold: \d+ JSON arrays and objects"):
        fio.read(dense)
    sparse = tmp_path / "rows.fold"
    sparse.write_text(head + "[1,2]," * (DENSE_FROM_BYTES // BYTES_PER_CONTAINER + 10)
                      + "[1,2]]}")
    assert len(fio.read(sparse).vertices) == 3
