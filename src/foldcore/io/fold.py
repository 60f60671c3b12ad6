"""Read FOLD files (JSON, FOLD spec 1.2) as :class:`CreasePattern`; writing is
:mod:`.fold_write`, the JSON checks :mod:`.fold_json` (both re-exported here).

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
  to mm: ``mm`` ×1, ``cm`` ×10, ``m`` ×1000, ``in`` ×25.4, ``pt`` ×25.4/72,
  ``um`` ×1e-3, ``nm`` ×1e-6; ``unit`` (or absent: no unit of length) scales
  the sheet to 100 mm across unless a size or scale is given
  (:data:`foldcore.limits.UNITLESS_SHEET_MM`).

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
message names the same item (memory and time:
``docs/architecture.md#reading-large-files``).
"""
from __future__ import annotations

import os
from dataclasses import dataclass
from itertools import chain

import numpy as np

from .. import limits
from ..errors import PatternError
from ..files import check_input
from ..hinges import HINGE_MODELS
from ..pattern import DEFAULT_MAX_ANGLE_DEG, CreasePattern
from ..planar import Loops, derive_face_loops, freeze, has_repeats, loop_starts, next_in_loop
from .conventions import (PlaneFit, Reading, assigned_angles, crease_pattern_frame, drive_only,
                          into_plane, note, trust_signs)
from .fold_json import (ARRAY, CELLS_KEY, EDGE_STIFFNESS_KEY,  # noqa: F401  (part of this API)
                        FACE_STIFFNESS_KEY, HINGE_KEY, MAX_ANGLE_KEY, POISSON_KEY, TARGET_KEY,
                        THICKNESS_KEY, UNIT_MM, WIDTH_KEY, check_length, fail, has_class, index,
                        int_table, number, number_table, parse_json, required_list, short)

#: Largest input file read, bytes (256 MiB).
MAX_FILE_BYTES = 256 * 1024 * 1024


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
    drawing : (V, 2) float or None
        Read from an SVG drawing: each vertex as first drawn, mm, before the
        reader merged close points (None for other files). A thin sheet then
        reads the drawing as Origami Simulator does: it leaves out the straight
        degree-2 vertices (as Origami Simulator does with a drawing and not with
        a FOLD file) and cuts each quadrilateral along its shorter diagonal as
        drawn (:func:`foldcore.sheet.build_sheet`'s ``merge_straight``, ``drawn``).
    """

    pattern: CreasePattern
    thickness: float | None
    frame_unit: str
    stiffness: dict | None = None
    hinge: list | None = None
    drawing: np.ndarray | None = None


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
    d = parse_json(data, source)
    del data  # the bytes go now, unless the caller keeps them
    return _fold_file(d, source, reading, owned=True)


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
    return _fold_file(d, source, reading, owned=False)


#: The keys :func:`_fold_file` converts to arrays before it builds the pattern.
_PATTERN_KEYS = ("vertices_coords", "vertices_flatUnfoldCoords", "faces_vertices",
                 "edges_vertices", "edges_assignment", "edges_foldAngle", "edges_foldAngles",
                 TARGET_KEY, WIDTH_KEY, MAX_ANGLE_KEY)


def _fold_file(d, source: str, reading: Reading | None, owned: bool) -> FoldFile:
    """:func:`fold_file_from_dict`; ``owned``: ``d`` was parsed here, so the lists of
    :data:`_PATTERN_KEYS` are dropped from it once converted, before the pattern is
    built (as Python objects they take about 7 × the file's size)."""
    reading = Reading() if reading is None else reading
    if not isinstance(d, dict):
        fail(source, f"the top level must be a JSON object, got {type(d).__name__}")
    d = crease_pattern_frame(d, source)
    unit, scale = _unit_scale(d, source)
    rows, folded = _crease_pattern_coords(d, source)
    faces = _faces(d, len(rows), source)
    vertices = _coords(rows, scale, source, faces, folded)
    del rows
    default_size = reading.unitless_size(unit)
    factor = reading.factor(_extent(vertices), default_size)
    if default_size is not None:
        declared = "absent" if d.get("frame_unit") is None else "'unit'"
        note(source, f"no unit of length (frame_unit {declared}): the sheet read as "
                     f"{default_size:g} mm across (1 unit = {factor:.6g} mm); "
                     "reading.size or reading.scale sets another")
    if factor != 1.0:
        vertices, scale = np.asarray(vertices, dtype=np.float64) * factor, scale * factor
    edges = _edges(d, len(vertices), source)
    n = len(edges)
    assignments = _assignments(d, vertices, edges, source)
    widths = _per_edge(d, WIDTH_KEY, n, source)
    max_angles = _per_edge(d, MAX_ANGLE_KEY, n, source)
    fold_angles = _floats(_fold_angles(d, assignments, source, reading, max_angles))
    widths = None if widths is None else _floats([
        None if w is None else _scaled(w, scale, f"{WIDTH_KEY}[{e}] (edge {e})", source,
                                       vertices=vertices)
        for e, w in enumerate(widths)])
    max_angles = None if max_angles is None else _floats(
        [DEFAULT_MAX_ANGLE_DEG if m is None else m for m in max_angles])
    if owned:
        for key in _PATTERN_KEYS:
            d.pop(key, None)
    freeze(vertices, edges, fold_angles, widths, max_angles, faces)
    args = dict(vertices=vertices, edges=edges, assignments=assignments,
                fold_angles=fold_angles, widths=widths, max_angles=max_angles, faces=faces,
                source=source)
    pattern = drive_only(build_pattern(args), reading.drive, source)
    return FoldFile(pattern, _thickness(d, scale, source, vertices), unit,
                    _stiffness(d, n, args["faces"], source), _hinge_models(d, n, source))


def _floats(values: list | None) -> np.ndarray | None:
    """A checked per-edge list of numbers and None as a float array (None → NaN)."""
    return None if values is None else np.array(values, dtype=np.float64)


def read_bytes(path, limit: int | None = None) -> bytes:
    """The bytes of a regular file (:func:`foldcore.files.check_input`), refusing files
    larger than ``limit`` before reading.

    ``limit`` defaults to :data:`MAX_FILE_BYTES` (read at call time).
    """
    source = os.fspath(path)
    limit = MAX_FILE_BYTES if limit is None else limit
    size = check_input(source, PatternError).st_size  # a named pipe would block the read
    try:
        if size > limit:
            fail(source, f"file is {size} bytes, larger than the {limit}-byte limit")
        with open(source, "rb") as fh:
            data = fh.read(limit + 1)
    except OSError as exc:
        raise PatternError(f"{source}: cannot read the file ({exc.strerror or exc})") from None
    except ValueError as exc:  # e.g. a NUL byte in the path
        raise PatternError(f"{source}: cannot read the file (invalid path: {exc})") from None
    if len(data) > limit:
        fail(source, f"file is larger than the {limit}-byte limit")
    return data


def _unit_scale(d: dict, source: str) -> tuple[str, float]:
    unit = d.get("frame_unit")
    unit = "unit" if unit is None else unit
    if not isinstance(unit, str) or unit not in UNIT_MM:
        fail(source, f"unknown frame_unit {short(unit)} "
                     f"(expected one of {', '.join(UNIT_MM)})")
    return unit, UNIT_MM[unit]


def _crease_pattern_coords(d: dict, source: str) -> tuple[list, bool]:
    """The rows of the crease pattern's coordinates: ``vertices_coords``, or a folded
    form's ``vertices_flatUnfoldCoords`` (said); and whether they are a folded form
    (labelled so, without flat coordinates: unfolded from its faces, :mod:`.unfold`)."""
    classes = d.get("frame_classes")
    folded = has_class(classes, "foldedForm")
    if d.get("vertices_flatUnfoldCoords") is not None and folded:
        rows = required_list(d, "vertices_flatUnfoldCoords", source)
        note(source, "a folded form: its crease pattern read from vertices_flatUnfoldCoords")
        return rows, False
    return required_list(d, "vertices_coords", source), folded


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


def _coords(rows: list, scale: float, source: str, faces=None, folded: bool = False):
    """(V, 2) vertex coordinates in mm (``[]`` for none), checked at once when the rows
    are plain [x, y] or [x, y, z] lists; from the first suspect row on, row by row. A
    sheet in 3D off the z = 0 plane is rotated into it (:func:`.conventions.into_plane`);
    a folded form (3D off any plane, or labelled ``folded``) is unfolded from its faces
    (:func:`.unfold.unfold_faces`)."""
    xy = number_table(rows, (2, 3))
    if xy is None:
        return _coords_by_row(rows, scale, source, 0)
    with np.errstate(over="ignore", invalid="ignore"):
        mm = xy[:, :2] * scale
    bad = ~np.isfinite(xy).all(axis=1) | ~np.isfinite(mm).all(axis=1)
    in_3d = xy.shape[1] == 3 and not bad.any() and (xy[:, 2] != 0).any()
    xyz = xy * scale if in_3d or folded and not bad.any() else None
    fit = PlaneFit.of(xyz) if in_3d else None
    if in_3d and (fit.flat or not faces):
        if folded:  # Origami Simulator labels its flat exports so
            note(source, "labelled a folded form (frame_classes: foldedForm) without "
                         "vertices_flatUnfoldCoords, on one plane: read as the crease pattern")
        return into_plane(xyz, faces, source, fit)
    if xyz is not None and faces:
        return _unfolded(xyz, faces, source)
    if folded:
        note(source, "labelled a folded form (frame_classes: foldedForm) without "
                     "vertices_flatUnfoldCoords or faces to unfold: its coordinates are read "
                     "as the crease pattern, which must be flat and without overlaps")
    if not bad.any():
        return mm
    first = int(np.argmax(bad))
    return np.concatenate([mm[:first], _coords_by_row(rows, scale, source, first)])


def _unfolded(xyz: np.ndarray, faces, source: str) -> np.ndarray:
    """:func:`.unfold.unfold_faces`, said once."""
    from .unfold import unfold_faces

    flat = unfold_faces(xyz, faces, source)
    note(source, "a folded form without vertices_flatUnfoldCoords: its crease pattern "
                 "unfolded from its faces, each laid flat beside the one before it")
    return flat


def _coords_by_row(rows, scale: float, source: str, start: int):
    """Rows ``start``... of vertices_coords checked one by one, as (n, 2) mm."""
    out = []
    for i, row in enumerate(rows[start:], start):
        xyz = [number(x) for x in row] if isinstance(row, ARRAY) else []
        if not 2 <= len(xyz) <= 3 or None in xyz:
            fail(source, f"vertices_coords[{i}] (vertex {i}) must be 2 or 3 finite "
                         f"numbers, got {short(row)}")
        if len(xyz) == 3 and xyz[2] != 0:
            fail(source, f"vertex {i} has z = {xyz[2]:g} where other rows are 2D; "
                         "give every vertex 2 coordinates, or 3 on one plane")
        out.append([_scaled(x, scale, f"vertices_coords[{i}] (vertex {i})", source)
                    for x in xyz[:2]])
    return out if start == 0 else np.array(out, dtype=np.float64).reshape(-1, 2)


def _edges(d: dict, n_vertices: int, source: str):
    """(E, 2) vertex ids (``[]`` for none); at once for plain [u, v] int lists."""
    rows = required_list(d, "edges_vertices", source)
    ids = int_table(rows, 2)
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
            fail(source, f"edges_vertices[{i}] (edge {i}) must be [u, v], got {short(row)}")
        ids = [index(x, n_vertices) for x in row]
        if None in ids:
            fail(source, f"edge {i} refers to vertices {short(row)}, but there are "
                         f"{n_vertices} vertices (ids 0..{n_vertices - 1})")
        out.append(ids)
    return out if start == 0 else np.array(out, dtype=np.int64).reshape(-1, 2)


def _faces(d: dict, n_vertices: int, source: str) -> Loops | list[list[int]] | None:
    """``faces_vertices`` as :class:`Loops` (lists of int ids in range, at once), else
    checked face by face from the first suspect one; None when absent or empty."""
    raw = d.get("faces_vertices")
    if raw is None or isinstance(raw, ARRAY) and not raw:
        return None
    if not isinstance(raw, ARRAY):
        fail(source, f"faces_vertices must be a list, got {type(raw).__name__}")
    first = _face_loops(raw, n_vertices)
    if isinstance(first, Loops):
        return first
    out = [list(row) for row in raw[:first]]
    for i, row in enumerate(raw[first:], first):
        ids = [index(x, n_vertices) for x in row] if isinstance(row, ARRAY) else [None]
        if None in ids:
            fail(source, f"faces_vertices[{i}] (face {i}) must list vertex ids "
                         f"(there are {n_vertices} vertices), got {short(row)}")
        out.append(ids)
    return out


def _face_loops(raw, n_vertices: int) -> Loops | int:
    """The faces as :class:`Loops` if every face is a list of int ids in range, else
    the first face that may not be (0 when the faces are not plain int lists)."""
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
        return Loops(flat, lengths)
    return int(np.searchsorted(np.cumsum(lengths), np.argmax(bad), side="right"))


def _assignments(d: dict, vertices, edges, source: str) -> list[str]:
    raw = d.get("edges_assignment")
    if raw is None:
        return _default_assignments(vertices, edges, source)
    check_length(raw, "edges_assignment", len(edges), source)
    if set(map(type, raw)) <= {str} and set(raw) <= set("MVBFU"):
        return list(raw)  # the usual case, nothing to convert
    for i, a in enumerate(raw):
        if not isinstance(a, str):
            fail(source, f"edges_assignment[{i}] (edge {i}) must be a string, got {short(a)}")
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
    check_length(raw, key, n, source, item)
    if _plain_numbers(raw):
        return list(raw) if int not in set(map(type, raw)) else \
            [None if x is None else float(x) for x in raw]
    out = [None if x is None else number(x) for x in raw]
    for i, (x, value) in enumerate(zip(raw, out)):
        if x is not None and value is None:
            fail(source, f"{key}[{i}] ({item} {i}) must be a finite number or null, "
                         f"got {short(x)}")
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
    check_length(raw, CELLS_KEY, n_faces, source, "face")
    out = {}
    for f, x in enumerate(raw):
        if x is None:
            continue
        counts = list(x) if isinstance(x, ARRAY) else [x]
        rings = len(counts) == 2 and counts[0] == "rings"
        if len(counts) not in (1, 2) or not all(
                isinstance(c, int) and not isinstance(c, bool) and c >= 1
                for c in counts[rings:]):
            fail(source, f"{CELLS_KEY}[{f}] (face {f}) must be null, a cell count ≥ 1, "
                         f"two of them or [\"rings\", count], got {short(x)}")
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
            fail(source, f"{POISSON_KEY}[{e}] (edge {e}) must be a Poisson ratio in "
                         f"[-1, 0.5] or null, got {short(nu)}")
        out[e] = float(nu)
    return out


def _hinge_models(d: dict, n_edges: int, source: str) -> list | None:
    """Hinge model name (or None) per edge from ``foldcore:edges_hinge``."""
    raw = d.get(HINGE_KEY)
    if raw is None:
        return None
    check_length(raw, HINGE_KEY, n_edges, source, "edge")
    for e, name in enumerate(raw):
        if name is not None and name not in HINGE_MODELS:
            fail(source, f"{HINGE_KEY}[{e}] (edge {e}) must be one of "
                         f"{', '.join(map(repr, HINGE_MODELS))} or null, got {short(name)}")
    return list(raw)


def _stiffness(d: dict, n_edges: int, faces, source: str) -> dict | None:
    """Stiffness factors per edge and per face (null → 1); each must be > 0."""
    out = {}
    hinge = _per_edge(d, EDGE_STIFFNESS_KEY, n_edges, source)
    if hinge is not None:
        out["hinge"] = _positive_factors(hinge, EDGE_STIFFNESS_KEY, "edge", source)
    if d.get(FACE_STIFFNESS_KEY) is not None:
        if faces is None:
            fail(source, f"{FACE_STIFFNESS_KEY} needs faces_vertices in the file (it is "
                         "given per face, in that order)")
        panel = _per_item(d, FACE_STIFFNESS_KEY, len(faces), "face", source)
        out["panel"] = _positive_factors(panel, FACE_STIFFNESS_KEY, "face", source)
    return out or None


def _positive_factors(values, key: str, item: str, source: str) -> np.ndarray:
    for i, v in enumerate(values):
        if v is not None and not v > 0:
            fail(source, f"{key}[{i}] ({item} {i}) must be a positive number or null, "
                         f"got {short(v)}")
    return np.array([1.0 if v is None else float(v) for v in values])


def _thickness(d: dict, scale: float, source: str, vertices) -> float | None:
    """``foldcore:thickness`` in mm, None if absent; PatternError unless positive and
    in :mod:`foldcore.limits`' window of the sheet ``vertices`` (mm)."""
    raw = d.get(THICKNESS_KEY)
    if raw is None:
        return None
    value = number(raw)
    if value is None or not value > 0:
        fail(source, f"{THICKNESS_KEY} must be a positive number, got {short(raw)}")
    mm = _scaled(value, scale, THICKNESS_KEY, source)
    limits.check_thickness(mm, vertices, THICKNESS_KEY, source)
    return mm


def _scaled(value: float, scale: float, what: str, source: str, vertices=None) -> float:
    """``value`` × the frame_unit ``scale`` (mm); PatternError if that overflows, or,
    given the sheet's ``vertices`` (mm), if it is not a hinge width of that sheet
    (:data:`foldcore.limits.WIDTH_RATIO`)."""
    mm = value * scale
    if not np.isfinite(mm):
        fail(source, f"{what} = {value:g} overflows when converted to mm "
                     f"(× {scale:g}, frame_unit)")
    if vertices is not None and mm > 0:  # not > 0: the pattern refuses it, naming the edge
        limits.check_width(mm, vertices, what, source)
    return mm


def build_pattern(args: dict) -> CreasePattern:
    try:
        return CreasePattern(**args)
    except PatternError as exc:
        if "contradicts assignment" in str(exc):  # a file writing magnitudes only
            raise PatternError(f"{exc}; reading.trust_assignment=True gives angles their "
                               "assignment's sign") from None
        raise
    except Exception as exc:  # last resort: never a raw traceback for user input
        raise PatternError(f"{args['source']}: unexpected malformed pattern "
                           f"({type(exc).__name__}: {exc})") from exc
