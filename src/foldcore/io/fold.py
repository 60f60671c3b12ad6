"""Read and write FOLD files (JSON, FOLD spec 1.2) as :class:`CreasePattern`.

Reading: frame 0 (the key frame) is the crease pattern; ``file_frames`` and
unknown keys are ignored.

* ``vertices_coords`` — 2D, or 3D on one plane (rotated into z = 0); a folded
  form's ``vertices_flatUnfoldCoords`` instead (:mod:`.conventions`).
* ``edges_vertices`` — vertex ids per edge (required).
* ``edges_assignment`` — ``M V B F U`` (lower case accepted). When absent,
  edges with a face on both sides become ``U`` and the others ``B``.
* ``faces_vertices`` — optional; derived from the planar graph when absent,
  ``null`` or empty.
* ``edges_foldAngle`` — degrees, valley positive: a number is an actuated
  target, ``null`` a passive crease. A file without the key folds its M/V
  creases to ∓180° (Origami Simulator's convention; ``Reading(mv_without_angle=
  "passive")`` keeps them passive; :mod:`.conventions`).
* ``frame_unit`` — every length (coordinates, widths, thickness) is converted
  to mm: ``unit`` (or absent) and ``mm`` ×1, ``cm`` ×10, ``m`` ×1000,
  ``in`` ×25.4, ``pt`` ×25.4/72, ``um`` ×1e-3, ``nm`` ×1e-6.

foldcore's own keys (lengths in the file's ``frame_unit``; foldcore writes mm):

* ``foldcore:edges_width`` — hinge width per edge, ``null`` = automatic (Eq. 7).
* ``foldcore:edges_maxAngle`` — largest fold magnitude per edge, degrees,
  ``null`` = 180.
* ``foldcore:thickness`` — sheet thickness (file level).
* ``foldcore:edges_targetAngle`` — written next to *achieved* angles in
  ``edges_foldAngle`` (a simulation result); the target angles, degrees,
  valley positive, ``null`` = passive. When present it is read instead of
  ``edges_foldAngle``, so a result file reads back as the pattern simulated.
* ``foldcore:faces_cells`` — in a result of a mesh with elastic panels: per
  face ``null`` (rigid), a cell count (a bar), two (a plate) or
  ``["rings", n]`` (a facet in n rings), as given to ``thicken(elastic=...)``,
  so the mesh can be rebuilt.
* ``foldcore:edges_poisson`` — in a result of a mesh with stretch hinges: per
  edge ``null`` (a bending hinge or boundary) or the stretch hinge's Poisson
  ratio ν, as given to ``thicken(stretch=...)``.
* ``foldcore:edges_hinge`` — hinge model per edge, ``"axis"``, ``"arc"``,
  ``"eq8"`` or ``null`` (the default, ``axis``; :mod:`foldcore.hinges`), as
  given to ``thicken(hinge=...)``; results carry the models used.

Every malformed input raises :class:`PatternError` naming the file and the
offending item; files above :data:`MAX_FILE_BYTES` are refused unread.

Large files: arrays of plain numbers, ids and letters are checked with NumPy;
from the first item that may be bad on, the row-by-row checks run, so the
message names the same item. A 10⁶-vertex triangulated grid (154 MB) reads
in about 19 s with a 2.6 GB peak, mostly the parsed JSON's Python objects
(``bench/reading.py``); a file at the size limit would need about 4.5 GB.
"""
from __future__ import annotations

import errno
import gc
import json
import os
import secrets
from contextlib import contextmanager, suppress
from dataclasses import dataclass
from functools import partial
from itertools import chain

import numpy as np

from .. import limits
from ..errors import PatternError
from ..hinges import HINGE_MODELS
from ..pattern import DEFAULT_MAX_ANGLE_DEG, CreasePattern
from ..planar import derive_face_loops, has_repeats, loop_starts, next_in_loop
from .conventions import Reading, assigned_angles, into_plane, note, trust_signs

#: Largest input file read, bytes (256 MiB).
MAX_FILE_BYTES = 256 * 1024 * 1024

#: Millimetres per ``frame_unit``.
UNIT_MM = {"unit": 1.0, "mm": 1.0, "cm": 10.0, "m": 1000.0, "in": 25.4,
           "pt": 25.4 / 72.0, "um": 1e-3, "nm": 1e-6}

WIDTH_KEY = "foldcore:edges_width"
MAX_ANGLE_KEY = "foldcore:edges_maxAngle"
THICKNESS_KEY = "foldcore:thickness"
TARGET_KEY = "foldcore:edges_targetAngle"
EDGE_STIFFNESS_KEY = "foldcore:edges_stiffness"
FACE_STIFFNESS_KEY = "foldcore:faces_stiffness"
CELLS_KEY = "foldcore:faces_cells"
POISSON_KEY = "foldcore:edges_poisson"
HINGE_KEY = "foldcore:edges_hinge"
#: What a JSON array may be in a FOLD dict: a list, or a tuple from a Python caller.
ARRAY = (list, tuple)
#: Digits to "0" and "E" to "e", for :func:`_may_overflow`'s plain substring search.
_DIGITS_TO_ZERO = bytes.maketrans(b"123456789E", b"000000000e")


@dataclass(frozen=True)
class FoldFile:
    """A FOLD file's crease pattern plus the file-level values foldcore uses.

    Attributes
    ----------
    pattern : CreasePattern
        The key frame, lengths in mm.
    thickness : float or None
        Sheet thickness in mm (``foldcore:thickness``); None when absent.
    frame_unit : str
        The unit the file declared (``"unit"`` when absent); already applied.
    stiffness : dict or None
        ``{"hinge": (E,) float, "panel": (F,) float}`` stiffness factors from
        ``foldcore:edges_stiffness`` / ``foldcore:faces_stiffness``
        (dimensionless, null → 1; see :func:`foldcore.thicken`), ready for
        ``thicken(..., stiffness=...)``; None when the file has neither.
    hinge : list of str or None, or None
        Hinge model per edge from ``foldcore:edges_hinge`` (None entries:
        the default), ready for ``thicken(..., hinge=...)``; None when absent.
    """

    pattern: CreasePattern
    thickness: float | None
    frame_unit: str
    stiffness: dict | None = None
    hinge: list | None = None


# ------------------------------------------------------------------- reading
def read_fold(path, reading: Reading | None = None) -> CreasePattern:
    """Read the crease pattern of a FOLD file (lengths in mm, angles in degrees;
    ``reading``: the conventions, :class:`foldcore.io.conventions.Reading`).

    Raises
    ------
    PatternError
        Unreadable, too large, not JSON, or not a valid crease pattern.
    """
    return read_fold_file(path, reading).pattern


def read_fold_file(path, reading: Reading | None = None) -> FoldFile:
    """Read a FOLD file: its crease pattern and ``foldcore:thickness`` (mm)."""
    source = os.fspath(path)
    return parse_fold(read_bytes(source), source, reading)


def parse_fold(data: bytes, source: str = "<fold>",
               reading: Reading | None = None) -> FoldFile:
    """A FOLD file's contents (UTF-8 JSON bytes) as a :class:`FoldFile`.

    Parameters
    ----------
    data : bytes
        The file's bytes.
    source : str
        Name used in error messages (the file name).
    reading : Reading, optional
        Conventions and scaling (default: Origami Simulator's, :mod:`.conventions`).
    """
    return fold_file_from_dict(_parse_json(data, source), source, reading)


def pattern_from_fold_dict(d, source: str = "<fold>") -> CreasePattern:
    """Build a :class:`CreasePattern` from a parsed FOLD object (a dict).

    Parameters
    ----------
    d : dict
        The top-level JSON object of a FOLD file.
    source : str
        Name used in error messages (the file name).
    """
    return fold_file_from_dict(d, source).pattern


def fold_file_from_dict(d, source: str = "<fold>", reading: Reading | None = None) -> FoldFile:
    """Like :func:`pattern_from_fold_dict`, also returning thickness and unit."""
    reading = Reading() if reading is None else reading
    if not isinstance(d, dict):
        _fail(source, f"the top level must be a JSON object, got {type(d).__name__}")
    unit, scale = _unit_scale(d, source)
    rows = _crease_pattern_coords(d, source)
    faces = _faces(d, len(rows), source)
    vertices = _coords(rows, scale, source, faces)
    factor = reading.factor(_extent(vertices))
    if factor != 1.0:
        vertices, scale = np.asarray(vertices, dtype=np.float64) * factor, scale * factor
    edges = _edges(d, len(vertices), source)
    n = len(edges)
    assignments = _assignments(d, vertices, edges, source)
    widths = _per_edge(d, WIDTH_KEY, n, source)
    max_angles = _per_edge(d, MAX_ANGLE_KEY, n, source)
    args = dict(
        vertices=vertices, edges=edges, assignments=assignments,
        fold_angles=_fold_angles(d, assignments, source, reading, max_angles),
        widths=None if widths is None else [
            None if w is None else _scaled(w, scale, f"{WIDTH_KEY}[{e}] (edge {e})", source,
                                           vertices=vertices)
            for e, w in enumerate(widths)],
        max_angles=None if max_angles is None else
        [DEFAULT_MAX_ANGLE_DEG if m is None else m for m in max_angles],
        faces=faces, source=source)
    pattern = _build(args)
    return FoldFile(pattern, _thickness(d, scale, source, vertices), unit,
                    _stiffness(d, n, args["faces"], source), _hinge_models(d, n, source))


def read_bytes(path, limit: int | None = None) -> bytes:
    """The bytes of a file, refusing files larger than ``limit`` before reading.

    ``limit`` defaults to :data:`MAX_FILE_BYTES` (read at call time).
    """
    source = os.fspath(path)
    limit = MAX_FILE_BYTES if limit is None else limit
    try:
        size = os.stat(source).st_size
        if size > limit:
            _fail(source, f"file is {size} bytes, larger than the {limit}-byte limit")
        with open(source, "rb") as fh:
            data = fh.read(limit + 1)
    except OSError as exc:
        raise PatternError(f"{source}: cannot read the file ({exc.strerror or exc})") from None
    except ValueError as exc:  # e.g. a NUL byte in the path
        raise PatternError(f"{source}: cannot read the file (invalid path: {exc})") from None
    if len(data) > limit:
        _fail(source, f"file is larger than the {limit}-byte limit")
    return data


def _parse_json(data: bytes, source: str):
    try:
        text = data.decode("utf-8-sig")
    except UnicodeDecodeError as exc:
        _fail(source, f"not UTF-8 text (bad byte at offset {exc.start})")
    # every float is checked by a Python hook only when one could overflow; the
    # parser's many lists are freed by reference counting, so the cyclic GC's
    # passes over them (half of a 10⁶-vertex file's parse) are paused meanwhile
    hook = {"parse_float": partial(_finite_float, source)} if _may_overflow(data) else {}
    try:
        with _gc_paused():
            return json.loads(text, parse_constant=partial(_bad_constant, source), **hook)
    except PatternError:
        raise
    except json.JSONDecodeError as exc:
        _fail(source, f"not valid JSON: {exc.msg} at line {exc.lineno}, column {exc.colno}")
    except (ValueError, RecursionError) as exc:
        _fail(source, f"not valid JSON ({type(exc).__name__}: {exc})")


def _may_overflow(data: bytes) -> bool:
    """False only if no JSON number in ``data`` can overflow a float64.

    A float overflows only beyond 1.8e308, so it needs an exponent of three
    or more digits or a hundred digits in a row (≤ 99 digits × 10⁹⁹ is finite).
    """
    t = data.translate(_DIGITS_TO_ZERO)
    return any(p in t for p in (b"0" * 100, b"e000", b"e+000"))


@contextmanager
def _gc_paused():
    """Pause the cyclic garbage collector (if on) for the block."""
    enabled = gc.isenabled()
    gc.disable()
    try:
        yield
    finally:
        if enabled:
            gc.enable()


def _bad_constant(source: str, name: str):
    _fail(source, f"not valid JSON: literal {name} (NaN/Infinity are not JSON; use null)")


def _finite_float(source: str, text: str) -> float:
    value = float(text)
    if not np.isfinite(value):
        _fail(source, f"number {text} is out of range of a 64-bit float")
    return value


def _unit_scale(d: dict, source: str) -> tuple[str, float]:
    unit = d.get("frame_unit")
    unit = "unit" if unit is None else unit
    if not isinstance(unit, str) or unit not in UNIT_MM:
        _fail(source, f"unknown frame_unit {_short(unit)} "
                      f"(expected one of {', '.join(UNIT_MM)})")
    return unit, UNIT_MM[unit]


def _crease_pattern_coords(d: dict, source: str) -> list:
    """The rows of the crease pattern's coordinates: ``vertices_coords``, or a folded
    form's ``vertices_flatUnfoldCoords`` (said)."""
    classes = d.get("frame_classes")
    folded = isinstance(classes, ARRAY) and "foldedForm" in classes
    if d.get("vertices_flatUnfoldCoords") is not None and folded:
        rows = _required_list(d, "vertices_flatUnfoldCoords", source)
        note(source, "a folded form: its crease pattern read from vertices_flatUnfoldCoords")
        return rows
    if folded:  # Origami Simulator labels its flat exports so: flat is read as the pattern
        note(source, "labelled a folded form (frame_classes: foldedForm) without "
                     "vertices_flatUnfoldCoords: its coordinates are read as the crease "
                     "pattern, which must be flat and without overlaps")
    return _required_list(d, "vertices_coords", source)


def _extent(vertices) -> float:
    v = np.asarray(vertices, dtype=np.float64).reshape(-1, 2)
    return float(np.ptp(v, axis=0).max()) if len(v) else 0.0


def _fold_angles(d: dict, assignments, source: str, reading: Reading,
                 max_angles=None) -> list | None:
    """Target angles per edge (degrees, None = passive): ``foldcore:edges_targetAngle``
    (a result file), else ``edges_foldAngle`` (or FOLD 1.0's ``edges_foldAngles``),
    else from the assignments (:func:`.conventions.assigned_angles`)."""
    for key in (TARGET_KEY, "edges_foldAngle", "edges_foldAngles"):
        if d.get(key) is not None:
            angles = _per_edge(d, key, len(assignments), source)
            return trust_signs(angles, assignments, source) if reading.trust_assignment \
                else angles
    return assigned_angles(assignments, source, reading, max_angles)


def _coords(rows: list, scale: float, source: str, faces=None):
    """(V, 2) vertex coordinates in mm (``[]`` for none), checked at once when the rows
    are plain [x, y] or [x, y, z] lists; from the first suspect row on, row by row. A
    sheet in 3D off the z = 0 plane is rotated into it (:func:`.conventions.into_plane`)."""
    xy = _number_table(rows, (2, 3))
    if xy is None:
        return _coords_by_row(rows, scale, source, 0)
    with np.errstate(over="ignore", invalid="ignore"):
        mm = xy[:, :2] * scale
    bad = ~np.isfinite(xy).all(axis=1) | ~np.isfinite(mm).all(axis=1)
    if xy.shape[1] == 3 and not bad.any() and (xy[:, 2] != 0).any():
        return into_plane(xy * scale, faces, source)
    if not bad.any():
        return mm
    first = int(np.argmax(bad))
    return np.concatenate([mm[:first], _coords_by_row(rows, scale, source, first)])


def _coords_by_row(rows, scale: float, source: str, start: int):
    """Rows ``start``... of vertices_coords checked one by one, as (n, 2) mm."""
    out = []
    for i, row in enumerate(rows[start:], start):
        xyz = [_number(x) for x in row] if isinstance(row, ARRAY) else []
        if not 2 <= len(xyz) <= 3 or None in xyz:
            _fail(source, f"vertices_coords[{i}] (vertex {i}) must be 2 or 3 finite "
                          f"numbers, got {_short(row)}")
        if len(xyz) == 3 and xyz[2] != 0:
            _fail(source, f"vertex {i} has z = {xyz[2]:g} where other rows are 2D; "
                          "give every vertex 2 coordinates, or 3 on one plane")
        out.append([_scaled(x, scale, f"vertices_coords[{i}] (vertex {i})", source)
                    for x in xyz[:2]])
    return out if start == 0 else np.array(out, dtype=np.float64).reshape(-1, 2)


def _edges(d: dict, n_vertices: int, source: str):
    """(E, 2) vertex ids (``[]`` for none); at once for plain [u, v] int lists."""
    rows = _required_list(d, "edges_vertices", source)
    ids = _int_table(rows, 2)
    if ids is None:
        return _edges_by_row(rows, n_vertices, source, 0)
    bad = ((ids < 0) | (ids >= n_vertices)).any(axis=1)
    if not bad.any():
        return ids
    first = int(np.argmax(bad))
    return np.concatenate([ids[:first], _edges_by_row(rows, n_vertices, source, first)])


def _edges_by_row(rows, n_vertices: int, source: str, start: int):
    """Rows ``start``... of edges_vertices checked one by one."""
    out = []
    for i, row in enumerate(rows[start:], start):
        if not isinstance(row, ARRAY) or len(row) != 2:
            _fail(source, f"edges_vertices[{i}] (edge {i}) must be [u, v], got {_short(row)}")
        ids = [_index(x, n_vertices) for x in row]
        if None in ids:
            _fail(source, f"edge {i} refers to vertices {_short(row)}, but there are "
                          f"{n_vertices} vertices (ids 0..{n_vertices - 1})")
        out.append(ids)
    return out if start == 0 else np.array(out, dtype=np.int64).reshape(-1, 2)


def _faces(d: dict, n_vertices: int, source: str) -> list[list[int]] | None:
    raw = d.get("faces_vertices")
    if raw is None or isinstance(raw, ARRAY) and not raw:
        return None
    if not isinstance(raw, ARRAY):
        _fail(source, f"faces_vertices must be a list, got {type(raw).__name__}")
    first = _first_bad_face(raw, n_vertices)
    if first is None:
        return list(raw)
    out = [list(row) for row in raw[:first]]
    for i, row in enumerate(raw[first:], first):
        ids = [_index(x, n_vertices) for x in row] if isinstance(row, ARRAY) else [None]
        if None in ids:
            _fail(source, f"faces_vertices[{i}] (face {i}) must list vertex ids "
                          f"(there are {n_vertices} vertices), got {_short(row)}")
        out.append(ids)
    return out


def _first_bad_face(raw, n_vertices: int) -> int | None:
    """None if every face is a list of int ids in range, else the first face that may
    not be (0 when the faces are not plain int lists)."""
    if not set(map(type, raw)) <= {list, tuple} \
            or not set(map(type, chain.from_iterable(raw))) <= {int}:
        return 0
    lengths = np.fromiter(map(len, raw), dtype=np.int64, count=len(raw))
    try:
        flat = np.fromiter(chain.from_iterable(raw), dtype=np.int64, count=int(lengths.sum()))
    except OverflowError:
        return 0
    bad = (flat < 0) | (flat >= n_vertices)
    if not bad.any():
        return None
    return int(np.searchsorted(np.cumsum(lengths), np.argmax(bad), side="right"))


def _number_table(rows, widths: tuple) -> np.ndarray | None:
    """``rows`` as an (n, k) float array if they are lists/tuples of one length k in
    ``widths`` holding only int/float (not bool); None otherwise (check row by row)."""
    if not rows or not set(map(type, rows)) <= {list, tuple}:
        return None
    lengths = set(map(len, rows))
    if len(lengths) != 1 or not lengths <= set(widths) \
            or not set(map(type, chain.from_iterable(rows))) <= {int, float}:
        return None
    try:
        return np.array(rows, dtype=np.float64)
    except (OverflowError, ValueError, TypeError):  # e.g. an int beyond float range
        return None


def _int_table(rows, width: int) -> np.ndarray | None:
    """``rows`` as an (n, width) int64 array if they are lists/tuples of ``width`` ints
    (not bool); None otherwise (check row by row)."""
    if not rows or not set(map(type, rows)) <= {list, tuple} or set(map(len, rows)) != {width} \
            or not set(map(type, chain.from_iterable(rows))) <= {int}:
        return None
    try:
        return np.array(rows, dtype=np.int64)
    except OverflowError:
        return None


def _assignments(d: dict, vertices, edges, source: str) -> list[str]:
    raw = d.get("edges_assignment")
    if raw is None:
        return _default_assignments(vertices, edges, source)
    _check_length(raw, "edges_assignment", len(edges), source)
    if set(map(type, raw)) <= {str} and set(raw) <= set("MVBFU"):
        return list(raw)  # the usual case, nothing to convert
    for i, a in enumerate(raw):
        if not isinstance(a, str):
            _fail(source, f"edges_assignment[{i}] (edge {i}) must be a string, got {_short(a)}")
    return [a.upper() if len(a) == 1 else a for a in raw]


def _default_assignments(vertices, edges, source: str) -> list[str]:
    """``U`` for edges with faces on both sides, ``B`` for the others.

    A graph with an edge from a vertex to itself or an edge twice has no
    faces to derive: all ``U``, and CreasePattern names the edge.
    """
    v = np.asarray(vertices, dtype=np.float64).reshape(-1, 2)
    e = np.asarray(edges, dtype=np.int64).reshape(-1, 2)
    if not len(e) or has_repeats(e):
        return ["U"] * len(e)
    try:
        with np.errstate(all="ignore"):  # huge coordinates: CreasePattern refuses them
            flat, lengths = derive_face_loops(v, e, np.zeros(len(e), dtype=bool), source)
    except PatternError:
        raise
    except Exception:  # malformed graph: let CreasePattern name the problem
        return ["U"] * len(e)
    u, w = flat, flat[next_in_loop(loop_starts(lengths), lengths)]
    n = len(v)
    sides, counts = np.unique(np.minimum(u, w) * n + np.maximum(u, w), return_counts=True)
    key = e.min(axis=1) * n + e.max(axis=1)
    at = np.minimum(np.searchsorted(sides, key), max(len(sides) - 1, 0))
    two = (sides[at] == key) & (counts[at] >= 2) if len(sides) else np.zeros(len(e), bool)
    return np.where(two, "U", "B").tolist()


def _per_edge(d: dict, key: str, n_edges: int, source: str) -> list | None:
    return _per_item(d, key, n_edges, "edge", source)


def _per_item(d: dict, key: str, n: int, item: str, source: str) -> list | None:
    """A per-edge or per-face list of finite numbers or nulls (None when absent)."""
    raw = d.get(key)
    if raw is None:
        return None
    _check_length(raw, key, n, source, item)
    if _plain_numbers(raw):
        return list(raw) if int not in set(map(type, raw)) else \
            [None if x is None else float(x) for x in raw]
    out = [None if x is None else _number(x) for x in raw]
    for i, (x, value) in enumerate(zip(raw, out)):
        if x is not None and value is None:
            _fail(source, f"{key}[{i}] ({item} {i}) must be a finite number or null, "
                          f"got {_short(x)}")
    return out


def _plain_numbers(raw) -> bool:
    """True if ``raw`` holds only None and finite int/float (not bool), checked at once."""
    if not raw or not set(map(type, raw)) <= {int, float, type(None)}:
        return False
    try:
        values = np.array(raw, dtype=np.float64)  # None → NaN
    except (OverflowError, ValueError, TypeError):
        return False
    return not np.isinf(values).any() and np.isnan(values).sum() == raw.count(None)


def faces_cells(d: dict, n_faces: int, source: str) -> dict:
    """``{face: n, (n1, n2) or ("rings", n)}`` from ``foldcore:faces_cells`` ({} when
    absent)."""
    raw = d.get(CELLS_KEY)
    if raw is None:
        return {}
    _check_length(raw, CELLS_KEY, n_faces, source, "face")
    out = {}
    for f, x in enumerate(raw):
        if x is None:
            continue
        counts = list(x) if isinstance(x, ARRAY) else [x]
        rings = len(counts) == 2 and counts[0] == "rings"
        if len(counts) not in (1, 2) or not all(
                isinstance(c, int) and not isinstance(c, bool) and c >= 1
                for c in counts[rings:]):
            _fail(source, f"{CELLS_KEY}[{f}] (face {f}) must be null, a cell count ≥ 1, "
                          f"two of them or [\"rings\", count], got {_short(x)}")
        out[f] = tuple(counts) if len(counts) == 2 else counts[0]
    return out


def edges_poisson(d: dict, n_edges: int, source: str) -> dict:
    """``{edge: ν}`` of the stretch hinges from ``foldcore:edges_poisson`` ({} when
    absent); ν in [−1, 0.5]."""
    values = _per_edge(d, POISSON_KEY, n_edges, source)
    out = {}
    for e, nu in enumerate(values or []):
        if nu is None:
            continue
        if not -1.0 <= nu <= 0.5:
            _fail(source, f"{POISSON_KEY}[{e}] (edge {e}) must be a Poisson ratio in "
                          f"[-1, 0.5] or null, got {_short(nu)}")
        out[e] = float(nu)
    return out


def _hinge_models(d: dict, n_edges: int, source: str) -> list | None:
    """Hinge model name (or None) per edge from ``foldcore:edges_hinge``."""
    raw = d.get(HINGE_KEY)
    if raw is None:
        return None
    _check_length(raw, HINGE_KEY, n_edges, source, "edge")
    for e, name in enumerate(raw):
        if name is not None and name not in HINGE_MODELS:
            _fail(source, f"{HINGE_KEY}[{e}] (edge {e}) must be one of "
                          f"{', '.join(map(repr, HINGE_MODELS))} or null, got {_short(name)}")
    return list(raw)


def _stiffness(d: dict, n_edges: int, faces, source: str) -> dict | None:
    """Stiffness factors per edge and per face (null → 1); each must be > 0."""
    out = {}
    hinge = _per_edge(d, EDGE_STIFFNESS_KEY, n_edges, source)
    if hinge is not None:
        out["hinge"] = _positive_factors(hinge, EDGE_STIFFNESS_KEY, "edge", source)
    if d.get(FACE_STIFFNESS_KEY) is not None:
        if faces is None:
            _fail(source, f"{FACE_STIFFNESS_KEY} needs faces_vertices in the file (it is "
                          "given per face, in that order)")
        panel = _per_item(d, FACE_STIFFNESS_KEY, len(faces), "face", source)
        out["panel"] = _positive_factors(panel, FACE_STIFFNESS_KEY, "face", source)
    return out or None


def _positive_factors(values, key: str, item: str, source: str) -> np.ndarray:
    for i, v in enumerate(values):
        if v is not None and not v > 0:
            _fail(source, f"{key}[{i}] ({item} {i}) must be a positive number or null, "
                          f"got {_short(v)}")
    return np.array([1.0 if v is None else float(v) for v in values])


def _thickness(d: dict, scale: float, source: str, vertices) -> float | None:
    """``foldcore:thickness`` in mm, None if absent; PatternError unless positive and
    in :mod:`foldcore.limits`' window of the sheet ``vertices`` (mm)."""
    raw = d.get(THICKNESS_KEY)
    if raw is None:
        return None
    value = _number(raw)
    if value is None or not value > 0:
        _fail(source, f"{THICKNESS_KEY} must be a positive number, got {_short(raw)}")
    mm = _scaled(value, scale, THICKNESS_KEY, source)
    limits.check_thickness(mm, vertices, THICKNESS_KEY, source)
    return mm


def _scaled(value: float, scale: float, what: str, source: str, vertices=None) -> float:
    """``value`` × the frame_unit ``scale`` (mm); PatternError if that overflows, or,
    given the sheet's ``vertices`` (mm), if it is not a hinge width of that sheet
    (:data:`foldcore.limits.WIDTH_RATIO`)."""
    mm = value * scale
    if not np.isfinite(mm):
        _fail(source, f"{what} = {value:g} overflows when converted to mm "
                      f"(× {scale:g}, frame_unit)")
    if vertices is not None and mm > 0:  # not > 0: the pattern refuses it, naming the edge
        limits.check_width(mm, vertices, what, source)
    return mm


def _build(args: dict) -> CreasePattern:
    try:
        return CreasePattern(**args)
    except PatternError as exc:
        if "contradicts assignment" in str(exc):  # a file writing magnitudes only
            raise PatternError(f"{exc}; --trust-assignment (Reading(trust_assignment="
                               "True)) gives angles their assignment's sign") from None
        raise
    except Exception as exc:  # last resort: never a raw traceback for user input
        raise PatternError(f"{args['source']}: unexpected malformed pattern "
                           f"({type(exc).__name__}: {exc})") from exc


# ------------------------------------------------------------ value checks
def _fail(source: str, message: str):
    raise PatternError(f"{source}: {message}")


def _short(value, limit: int = 60) -> str:
    """``value`` for an error message: JSON-like, at most ``limit`` characters."""
    try:
        text = json.dumps(value) if isinstance(value, (*ARRAY, dict, str, type(None))) \
            else repr(value)
    except (TypeError, ValueError, RecursionError):  # not JSON (a Python caller's object)
        try:
            text = repr(value)
        except RecursionError:
            text = f"<nested {type(value).__name__}>"
    return text if len(text) <= limit else text[:limit - 3] + "..."


def _required_list(d: dict, key: str, source: str) -> list:
    if key not in d:
        _fail(source, f"missing required key {key!r}")
    if not isinstance(d[key], ARRAY):
        _fail(source, f"{key} must be a list, got {type(d[key]).__name__}")
    return d[key]


def _check_length(raw, key: str, n: int, source: str, item: str = "edge"):
    if not isinstance(raw, ARRAY):
        _fail(source, f"{key} must be a list, got {type(raw).__name__}")
    if len(raw) != n:
        _fail(source, f"{key} has {len(raw)} entries for {n} {item}s "
                      f"({item}s_vertices); entry {min(len(raw), n)} is the first mismatch")


def _number(x) -> float | None:
    """``x`` as a finite float, or None if it is not a finite JSON number."""
    if isinstance(x, bool) or not isinstance(x, (int, float)):
        return None
    try:
        value = float(x)
    except OverflowError:
        return None
    return value if np.isfinite(value) else None


def _index(x, n: int) -> int | None:
    """``x`` as a vertex id in 0..n-1, or None."""
    value = _number(x)
    if value is None or value != int(value) or not 0 <= value < n:
        return None
    return int(value)


# ------------------------------------------------------------------- writing
def fold_dict(pattern: CreasePattern, achieved_angles=None, frames=None,
              thickness: float | None = None, extra: dict | None = None) -> dict:
    """The FOLD object (a dict ready for JSON) of a crease pattern or result.

    Parameters
    ----------
    pattern : CreasePattern
    achieved_angles : (E,) array_like of float, optional
        Fold angles reached, degrees, valley positive; NaN → null. When given
        they fill ``edges_foldAngle`` and the targets go to
        ``foldcore:edges_targetAngle``.
    frames : sequence of dict, optional
        Extra frames (e.g. the folded thick solid), written as ``file_frames``
        unchanged (NumPy arrays are converted when written).
    thickness : float, optional
        Sheet thickness, mm (``foldcore:thickness``).
    extra : dict, optional
        More top-level keys (use a ``foldcore:`` prefix); they win on clashes.
    """
    d = {"file_spec": 1.2, "file_creator": "foldcore", "file_classes": ["singleModel"],
         "frame_classes": ["creasePattern"], "frame_attributes": ["2D"], "frame_unit": "mm",
         "vertices_coords": pattern.vertices.tolist(),
         "edges_vertices": pattern.edges.tolist(),
         "edges_assignment": pattern.assignments.tolist(),
         "faces_vertices": [f.tolist() for f in pattern.faces],
         "edges_foldAngle": _nullable(pattern.fold_angles),
         WIDTH_KEY: _nullable(pattern.widths), MAX_ANGLE_KEY: pattern.max_angles.tolist()}
    if achieved_angles is not None:
        achieved = np.asarray(achieved_angles, dtype=np.float64)
        if achieved.shape != (pattern.n_edges,):
            raise ValueError(f"achieved_angles has shape {achieved.shape}, "
                             f"expected ({pattern.n_edges},)")
        d[TARGET_KEY], d["edges_foldAngle"] = d["edges_foldAngle"], _nullable(achieved)
    if thickness is not None:
        d[THICKNESS_KEY] = float(thickness)
    if frames is not None:
        d["file_frames"] = list(frames)
    d.update(extra or {})
    return d


def write_fold(path, pattern: CreasePattern, achieved_angles=None, frames=None,
               thickness: float | None = None, extra: dict | None = None) -> None:
    """Write :func:`fold_dict` to ``path`` atomically (no partial file on error).

    Floats keep full precision (shortest round-trip repr), so reading the file
    back gives the same pattern bit for bit. One top-level key per line.
    """
    d = fold_dict(pattern, achieved_angles, frames, thickness, extra)
    dumps = partial(json.dumps, allow_nan=False, default=_jsonable)
    with atomic_write(path) as fh:
        fh.write("{\n")
        for i, (key, value) in enumerate(d.items()):
            fh.write(f"  {json.dumps(key)}: {dumps(value)}{',' if i < len(d) - 1 else ''}\n")
        fh.write("}\n")


@contextmanager
def atomic_path(path, suffix: str = ""):
    """A temporary path (same folder) that is renamed to ``path`` if the block succeeds.

    For writers that take a file name (pyvista, imageio) or are given an open
    file (:func:`atomic_write`). The temporary name is a prefix of the target's
    (it must fit NAME_MAX too) and ends in ``.tmp`` + ``suffix``, so writers
    that choose a format from the name still do. On any exception the
    temporary file is removed and ``path`` is left as it was.
    """
    target = os.fspath(path)
    folder, name = os.path.split(os.path.abspath(target))
    tmp = os.path.join(folder, f".{name[:50]}.{os.getpid()}.{secrets.token_hex(4)}.tmp{suffix}")
    try:
        yield tmp
        if not os.path.exists(tmp):
            raise OSError(errno.ENOENT, "the writer produced no file", target)
        os.replace(tmp, target)
    except OSError as exc:
        with suppress(OSError):
            os.unlink(tmp)
        if exc.filename != tmp:
            raise
        raise OSError(exc.errno, exc.strerror, target) from None  # the user's name, not ours
    except BaseException:
        with suppress(OSError):
            os.unlink(tmp)
        raise


@contextmanager
def atomic_write(path, binary: bool = False):
    """Open a file for writing (text UTF-8, or bytes) that appears at ``path`` only when
    complete: written to a temporary file, fsynced, renamed over ``path``
    (:func:`atomic_path`)."""
    with atomic_path(path) as tmp:
        mode = {"mode": "xb"} if binary else {"mode": "x", "encoding": "utf-8", "newline": "\n"}
        with open(tmp, **mode) as fh:
            yield fh
            fh.flush()
            os.fsync(fh.fileno())


def _nullable(values: np.ndarray) -> list:
    return [float(x) if np.isfinite(x) else None for x in values]


def _jsonable(obj):
    if isinstance(obj, np.ndarray):
        return obj.tolist()
    if isinstance(obj, np.generic):
        return obj.item()
    raise TypeError(f"{type(obj).__name__} is not JSON serialisable")
