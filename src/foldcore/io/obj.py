"""The paper's input: a 2D polygon mesh (OBJ or STL) plus a hinge file.

Mesh (lengths in mm)
--------------------
* OBJ: ``v x y [z]`` vertices (z must be 0; further numbers are ignored) and
  ``f i j k ...`` polygon faces with 1-based vertex ids (``i/t``, ``i//n`` and
  ``i/t/n`` are tolerated; negative ids count back from the last vertex read).
  Other statements (``vt``, ``vn``, ``o``, ``g``, ``s``, ``usemtl``...) and
  ``#`` comments are ignored.
* STL, ASCII or binary: facets with z = 0. Vertices with exactly equal
  coordinates are merged, numbered in order of first appearance. A binary STL
  must be exactly 84 + 50 × (triangle count) bytes; an ASCII STL's every
  ``outer loop`` needs its ``endloop`` (a truncated file is refused).

Mesh and hinge files above :data:`foldcore.io.MAX_FILE_BYTES` are refused unread;
the others are read a chunk of lines at a time into flat arrays (memory:
``docs/architecture.md#reading-large-files``).

Each face is a panel; clockwise faces are reversed (with a warning).

Edge ids
--------
The edges are the unique undirected sides of the faces, numbered in order of
first appearance while walking the faces in file order, side by side: face 0's
sides (v0, v1), (v1, v2), ..., (v_{n-1}, v0), then face 1's, and so on (for
STL: the facets in file order, over the merged vertices). A side met again
later (the other face of an interior edge) keeps its first id.
:func:`mesh_edges` lists them, so ``mesh_edges(faces)[i]`` is edge ``i``.

Hinge file
----------
One hinge per line: ``edge_id width kind [angle] [max=deg]``, ``#`` comments
and blank lines allowed.

* ``edge_id`` — mesh edge id as above (0-based).
* ``width`` — hinge width in mm, or ``auto`` (chosen from Eq. 7 when the sheet
  is thickened).
* ``kind`` — ``M`` mountain or ``V`` valley (the paper's kinds); foldcore also
  accepts ``F`` (held flat) and ``U`` (unassigned, passive either way).
* ``angle`` — present = actuated: the bend angle in degrees. For ``M``/``V`` it
  is the magnitude (a sign, if written, must agree: valley +, mountain −);
  for ``U`` it is signed, valley positive; for ``F`` only 0 is allowed.
* ``max=deg`` — foldcore extension: largest fold magnitude, degrees (default 180).

Boundary edges (one face) take no hinge line and become ``B``; every interior
edge (two faces) needs exactly one hinge line.
"""
from __future__ import annotations

import math
import os
from array import array
from pathlib import Path

import numpy as np

from .. import files, limits
from ..errors import PatternError
from ..pattern import DEFAULT_MAX_ANGLE_DEG, CreasePattern
from ..planar import Loops, freeze, loop_starts, loops_of, next_in_loop
from .fold import build_pattern, read_bytes
from .fold_json import short

HINGE_SUFFIX = ".hinges"
HINGE_KINDS = ("M", "V", "F", "U")
STL_RECORD = np.dtype([("normal", "<f4", 3), ("v", "<f4", (3, 3)), ("attr", "<u2")])
#: Characters decoded and split into lines at a time: a file's lines are never all held.
CHUNK_CHARS = 1 << 14


def mesh_edges(faces) -> np.ndarray:
    """The mesh's edge list in hinge-file numbering (see the module docstring).

    Parameters
    ----------
    faces : sequence of (n,) int arrays, or :class:`foldcore.planar.Loops`
        Faces as 0-based vertex loops, in file order.

    Returns
    -------
    (E, 2) int64 array
        Edge ``i`` as the vertex pair of the side that first named it.
    """
    return _edge_table(faces)[0]


def _edge_table(faces) -> tuple[np.ndarray, np.ndarray]:
    """(E, 2) edges in hinge-file order and (E,) number of faces on each.

    At once: the sides of all faces in file order, each keyed by its sorted
    vertex pair; an edge is a key's first side, edges ordered by that side.
    """
    loops = loops_of(faces)
    lengths = loops.lengths[loops.lengths > 0]  # an empty face has no sides
    if not len(lengths):
        return np.zeros((0, 2), dtype=np.int64), np.zeros(0, dtype=np.int64)
    a = loops.flat
    b = a[next_in_loop(loop_starts(lengths), lengths)]
    lo, hi = np.minimum(a, b), np.maximum(a, b)
    key = (lo - lo.min()) * (int(hi.max()) - int(lo.min()) + 1) + (hi - lo.min())
    _, first, counts = np.unique(key, return_index=True, return_counts=True)
    order = np.argsort(first)
    return np.stack([a[first[order]], b[first[order]]], axis=1), counts[order]


# ------------------------------------------------------------------- reading
def read_mesh(path, hinges=None) -> CreasePattern:
    """Read an OBJ/STL crease-pattern mesh and its hinge file.

    Parameters
    ----------
    path : str or os.PathLike
        ``.obj`` or ``.stl`` file, coordinates in mm.
    hinges : str or os.PathLike, optional
        Hinge file; default: ``path`` with suffix ``.hinges``.

    Raises
    ------
    PatternError
        Missing or malformed file; the message names the file and line or edge.
    """
    source = os.fspath(path)
    hinge_source = default_hinge_path(source) if hinges is None else os.fspath(hinges)
    vertices, faces = read_polygons(source)
    return mesh_pattern(vertices, faces, read_bytes(hinge_source), source, hinge_source)


def mesh_pattern(vertices, faces, hinge_data: bytes, source: str,
                 hinge_source: str) -> CreasePattern:
    """The pattern of a parsed mesh and the contents of its hinge file.

    Parameters
    ----------
    vertices, faces
        :func:`parse_polygons` output.
    hinge_data : bytes
        The hinge file's bytes (UTF-8; a bad byte reads as U+FFFD).
    source, hinge_source : str
        Names of the mesh and hinge files, used in error messages.
    """
    label = f"{source} (hinges {hinge_source})"
    edges, counts = _edge_table(faces)
    values = _edge_values(vertices, counts,
                          _hinge_rows(hinge_data, hinge_source, len(edges)), label)
    del hinge_data, counts  # the bytes go now, unless the caller keeps them
    freeze(edges, *values.values())
    return build_pattern(dict(vertices=vertices, edges=edges, faces=faces, source=label,
                              **values))


def default_hinge_path(mesh_path) -> str:
    """``mesh_path`` with suffix ``.hinges``; PatternError naming both if missing."""
    mesh = os.fspath(mesh_path)
    hinge = str(Path(mesh).with_suffix(HINGE_SUFFIX))
    if not os.path.exists(hinge):
        raise PatternError(f"{mesh}: no hinge file {hinge} (a mesh needs one hinge line per "
                           "interior edge; pass hinges=PATH to use another file)")
    return hinge


def read_polygons(path) -> tuple[np.ndarray, Loops]:
    """Vertices ((V, 2) float, mm) and 0-based faces of an OBJ or STL file."""
    source = os.fspath(path)
    _mesh_suffix(source)
    return parse_polygons(read_bytes(source), source)


def parse_polygons(data: bytes, source: str) -> tuple[np.ndarray, Loops]:
    """Vertices and faces (a sequence of (n,) int arrays, :class:`foldcore.planar.Loops`)
    of OBJ or STL contents; ``source``'s suffix names the format."""
    vertices, faces = _parse_obj(data, source) if _mesh_suffix(source) == ".obj" \
        else parse_stl(data, source)
    if not faces:
        raise PatternError(f"{source}: the mesh has no faces")
    return vertices, faces


def _mesh_suffix(source: str) -> str:
    suffix = Path(source).suffix.lower()
    if suffix not in (".obj", ".stl"):
        raise PatternError(f"{source}: not an OBJ or STL file")
    return suffix


def parse_obj(text: str, source: str) -> tuple[np.ndarray, Loops]:
    """Vertices ((V, 2), mm) and 0-based faces of OBJ text (see module docstring)."""
    return _parse_obj(text, source)


def _parse_obj(data, source: str) -> tuple[np.ndarray, Loops]:
    """:func:`parse_obj` of OBJ bytes (UTF-8; a bad byte reads as U+FFFD) or text.

    The lines are read a chunk at a time into flat arrays: the coordinates, and
    the faces' 1-based ids (negative ones resolved), lengths and line numbers.
    A line off the plain forms goes to the one-line readers, which name its fault.
    """
    coords, ids, lengths, lines = array("d"), array("q"), array("q"), array("q")
    huge: dict[int, int] = {}  # position in ids → an id beyond int64
    lineno = 0
    for chunk in _line_lists(data):
        for line in chunk:
            lineno += 1
            tokens = (line.split("#", 1)[0] if "#" in line else line).split()
            if not tokens:
                continue
            if tokens[0] == "v":
                try:
                    x, y = float(tokens[1]), float(tokens[2])
                    plain = (len(tokens) < 4 or float(tokens[3]) == 0) \
                        and math.isfinite(x) and math.isfinite(y)
                except (ValueError, IndexError):
                    plain = False
                if not plain:
                    x, y = _obj_vertex(tokens, f"{source}, line {lineno}")
                coords.append(x)
                coords.append(y)
            elif tokens[0] == "f":
                n_read = len(coords) // 2
                try:
                    face = [int(t) for t in tokens[1:]]
                    plain = len(face) >= 3 and 0 not in face
                except ValueError:
                    plain = False
                if not plain:
                    face = [i + 1 for i in _obj_face(tokens, n_read, f"{source}, line {lineno}")]
                elif min(face) < 0:
                    face = [i if i > 0 else n_read + i + 1 for i in face]
                mark = len(ids)
                try:
                    ids.extend(face)
                except OverflowError:  # an id beyond int64 (out of range): 0 in its place
                    del ids[mark:]
                    fits = [-2 ** 63 <= i < 2 ** 63 for i in face]
                    huge.update((mark + k, i) for k, i in enumerate(face) if not fits[k])
                    ids.extend(i if fit else 0 for i, fit in zip(face, fits))
                lengths.append(len(face))
                lines.append(lineno)
    return _obj_arrays(coords, ids, huge, lengths, lines, source)


def _obj_arrays(coords: array, ids: array, huge: dict, lengths: array, lines: array,
                source: str) -> tuple[np.ndarray, Loops]:
    """Vertices ((V, 2)) and 0-based faces from :func:`_parse_obj`'s flat arrays;
    PatternError naming the first face that refers to a vertex the file lacks."""
    n = len(coords) // 2
    flat = np.frombuffer(ids, dtype=np.int64)
    bad = (flat < 1) | (flat > n)
    if bad.any():
        k = int(np.argmax(bad))
        f = int(np.searchsorted(np.cumsum(np.frombuffer(lengths, dtype=np.int64)), k,
                                side="right"))
        raise PatternError(f"{source}, line {lines[f]}: face {f} refers to vertex "
                           f"{huge.get(k, int(flat[k]))}, but the file has {n} vertices "
                           "(ids are 1-based)")
    faces = Loops(flat - 1, np.array(lengths, dtype=np.int64))
    freeze(faces)  # this reader's own: the pattern shares it
    return np.array(coords, dtype=np.float64).reshape(-1, 2), faces


def _obj_vertex(tokens: list[str], where: str) -> tuple[float, float]:
    xyz = [_float(t) for t in tokens[1:4]]
    if len(xyz) < 2 or None in xyz:
        raise PatternError(f"{where}: expected 'v x y [z]' with finite numbers, "
                           f"got {short(' '.join(tokens))}")
    if len(xyz) == 3 and xyz[2] != 0:
        raise PatternError(f"{where}: vertex has z = {xyz[2]:g}; the pattern must lie "
                           "flat in the plane z = 0")
    return xyz[0], xyz[1]


def _obj_face(tokens: list[str], n_read: int, where: str) -> list[int]:
    ids = [_int(t.split("/", 1)[0]) for t in tokens[1:]]
    if len(ids) < 3 or None in ids or 0 in ids:
        raise PatternError(f"{where}: expected 'f i j k ...' with at least 3 non-zero "
                           f"vertex ids (1-based), got {short(' '.join(tokens))}")
    return [i - 1 if i > 0 else n_read + i for i in ids]


def parse_stl(data: bytes, source: str) -> tuple[np.ndarray, Loops]:
    """Vertices ((V, 2), mm; coincident ones merged) and faces of an STL file."""
    count = int.from_bytes(data[80:84], "little")
    if len(data) >= 84 and len(data) == 84 + 50 * count:
        records = np.frombuffer(data, dtype=STL_RECORD, count=count, offset=84)
        return _merge_triangles(records["v"].astype(np.float64), source)
    if b"\0" in data:  # ASCII STL is text: a damaged binary STL
        _bad_binary_stl(data, count, source)
    else:
        polygons = _ascii_stl_loops(data, source)
    return _merge_vertices(polygons)


def _bad_binary_stl(data: bytes, count: int, source: str):
    """Refuse binary data that is not a whole binary STL (truncated, wrong count)."""
    if len(data) < 84:
        raise PatternError(f"{source}: not an ASCII STL (NUL bytes) and only {len(data)} "
                           "bytes, too short for a binary STL (80-byte header + count)")
    raise PatternError(f"{source}: binary STL header says {count} triangles "
                       f"({84 + 50 * count} bytes), but the file has {len(data)} bytes "
                       "(truncated or damaged)")


def _ascii_stl_loops(data, source: str) -> list[tuple[str, list]]:
    """[(where, [[x, y, z], ...]), ...]: the vertex loops of an ASCII STL (bytes or text)."""
    loops, current = [], None
    for lineno, tokens in _lines(data):
        where, word = f"{source}, line {lineno}", tokens[0].lower()
        if word == "outer":
            if current is not None:
                raise PatternError(f"{where}: 'outer loop' before the 'endloop' of the loop "
                                   f"at {current[0].rsplit(', ', 1)[-1]}")
            current = (where, [])
        elif word == "vertex":
            xyz = [_float(t) for t in tokens[1:]]
            if current is None or len(xyz) != 3 or None in xyz:
                raise PatternError(f"{where}: expected 'vertex x y z' inside "
                                   f"'outer loop', got {short(' '.join(tokens))}")
            current[1].append(xyz)
        elif word == "endloop" and current is not None:
            loops.append(current)
            current = None
    if current is not None:
        raise PatternError(f"{current[0]}: this 'outer loop' has no 'endloop' "
                           "(file truncated?)")
    return loops


def _merge_triangles(tris: np.ndarray, source: str) -> tuple[np.ndarray, Loops]:
    """:func:`_merge_vertices` of a binary STL's (F, 3, 3) facets, at once.

    The first vertex that is not finite with z = 0 is named as before;
    vertices with equal (x, y) (0.0 and -0.0 alike, as dict keys) are merged,
    numbered in order of first appearance, keeping the first one's values.
    """
    xyz = tris.reshape(-1, 3)
    bad = ~(np.isfinite(xyz[:, 0]) & np.isfinite(xyz[:, 1]) & (xyz[:, 2] == 0))
    if bad.any():
        k = int(np.argmax(bad))
        x, y, z = xyz[k].tolist()
        raise PatternError(f"{source}, facet {k // 3}: vertex ({x:g}, {y:g}, {z:g}) must be "
                           "finite with z = 0 (the pattern lies flat)")
    xy = xyz[:, :2] + 0.0  # -0.0 → 0.0: equal keys, as in a dict
    order = np.lexsort((xy[:, 1], xy[:, 0]))
    step = np.ones(len(xy), dtype=bool)
    step[1:] = (np.diff(xy[order], axis=0) != 0).any(axis=1)
    group = np.cumsum(step) - 1  # per sorted corner: its (x, y) class
    first = np.full(int(group[-1]) + 1 if len(group) else 0, len(xy), dtype=np.int64)
    np.minimum.at(first, group, order)  # each class's first corner
    rank = np.empty(len(first), dtype=np.int64)
    rank[np.argsort(first)] = np.arange(len(first))
    ids = np.empty(len(xy), dtype=np.int64)
    ids[order] = rank[group]
    vertices = xyz[np.sort(first), :2]
    return np.ascontiguousarray(vertices).reshape(-1, 2), \
        Loops(ids, np.full(len(ids) // 3, 3, dtype=np.int64))


def _merge_vertices(polygons) -> tuple[np.ndarray, Loops]:
    ids: dict[tuple[float, float], int] = {}
    flat, lengths = array("q"), array("q")
    for where, loop in polygons:
        if len(loop) < 3:
            raise PatternError(f"{where}: a facet needs at least 3 vertices, got {len(loop)}")
        for x, y, z in loop:
            if not (math.isfinite(x) and math.isfinite(y) and z == 0):
                raise PatternError(f"{where}: vertex ({x:g}, {y:g}, {z:g}) must be finite "
                                   "with z = 0 (the pattern lies flat)")
        flat.extend([ids.setdefault((x, y), len(ids)) for x, y, _ in loop])
        lengths.append(len(loop))
    return np.array(list(ids), dtype=np.float64).reshape(-1, 2), \
        Loops(np.array(flat, dtype=np.int64), np.array(lengths, dtype=np.int64))


def parse_hinges(text: str, source: str, n_edges: int) -> dict[int, tuple]:
    """Hinge lines by edge id: ``{edge: (width_mm, kind, angle_deg, max_deg, line)}``.

    ``width_mm`` is NaN for ``auto``; ``angle_deg`` is signed (valley positive),
    NaN when passive. Raises PatternError naming the file and 1-based line.
    """
    rows = zip(*(column.tolist() for column in _hinge_rows(text, source, n_edges)))
    return {row[0]: row[1:] for row in rows}


def _hinge_rows(data, source: str, n_edges: int) -> tuple[np.ndarray, ...]:
    """The hinge lines of ``data`` (bytes or text) as arrays in line order: edge ids,
    widths (mm, NaN: auto), kinds, signed angles (degrees, NaN: passive), max angles
    and line numbers; PatternError naming the file and line of the first bad one."""
    edges, lines = array("q"), array("q")
    widths, angles, max_angles = array("d"), array("d"), array("d")
    kinds = []
    seen = array("q", bytes(8 * max(n_edges, 0)))  # the line of each edge's hinge
    for lineno, tokens in _lines(data):
        edge, width, kind, angle, max_angle = _hinge_line(tokens, n_edges, source, lineno)
        if seen[edge]:
            raise PatternError(f"{source}, line {lineno}: edge {edge} already has a hinge "
                               f"(line {seen[edge]})")
        seen[edge] = lineno
        edges.append(edge)
        widths.append(width)
        kinds.append(kind)
        angles.append(angle)
        max_angles.append(max_angle)
        lines.append(lineno)
    return (np.array(edges, dtype=np.int64), np.array(widths, dtype=np.float64),
            np.array(kinds, dtype="<U1"), np.array(angles, dtype=np.float64),
            np.array(max_angles, dtype=np.float64), np.array(lines, dtype=np.int64))


def _hinge_line(tokens: list[str], n_edges: int, source: str, lineno: int) -> tuple:
    if len(tokens) < 3:
        raise PatternError(f"{source}, line {lineno}: expected 'edge_id width M|V "
                           f"[bend_angle_deg]', got {short(' '.join(tokens))}")
    edge = _int(tokens[0])
    if edge is None or not 0 <= edge < n_edges:
        raise PatternError(f"{source}, line {lineno}: edge id {tokens[0]!r} is not an edge of "
                           f"the mesh (ids 0..{n_edges - 1}; see foldcore.io.mesh_edges)")
    width = math.nan if tokens[1].lower() == "auto" else _float(tokens[1])
    if width is None or width <= 0:
        raise PatternError(f"{source}, line {lineno}: width {tokens[1]!r} must be a positive "
                           "number (mm) or 'auto'")
    kind = tokens[2].upper()
    if kind not in HINGE_KINDS:
        raise PatternError(f"{source}, line {lineno}: hinge kind {tokens[2]!r} must be one of "
                           f"{', '.join(HINGE_KINDS)}")
    if len(tokens) == 3:
        return edge, width, kind, math.nan, DEFAULT_MAX_ANGLE_DEG
    return (edge, width, kind, *_hinge_options(tokens[3:], kind, f"{source}, line {lineno}"))


def _hinge_options(tokens: list[str], kind: str, where: str) -> tuple[float, float]:
    """(signed angle or NaN, max angle), both degrees, from the optional tokens."""
    angle, max_angle = math.nan, DEFAULT_MAX_ANGLE_DEG
    for token in tokens:
        if token.lower().startswith("max="):
            max_angle = _float(token[4:])
            if max_angle is None or not 0 < max_angle <= 180:
                raise PatternError(f"{where}: {token!r}: the max angle must be in (0, 180]°")
        elif math.isnan(angle):
            angle = _signed_angle(token, kind, where)
        else:
            raise PatternError(f"{where}: unexpected extra field {token!r}")
    return angle, max_angle


def _signed_angle(token: str, kind: str, where: str) -> float:
    value = _float(token)
    if value is None or abs(value) > 180:
        raise PatternError(f"{where}: bend angle {token!r} must be a number in [-180, 180]°")
    if kind == "V" and value < 0 or kind == "F" and value != 0:
        raise PatternError(f"{where}: bend angle {token}° contradicts kind {kind!r} "
                           "(valley > 0, mountain < 0, flat 0)")
    return -abs(value) if kind == "M" else value


def pattern_from_mesh(vertices, faces, hinges: dict, source: str) -> CreasePattern:
    """Build the pattern: faces are panels, hinge lines give the interior edges.

    Parameters
    ----------
    vertices : (V, 2) float array, mm
    faces : sequence of (n,) int arrays, 0-based
    hinges : dict
        :func:`parse_hinges` output.
    source : str
        Name used in error messages.
    """
    rows = list(zip(*((e, *values) for e, values in hinges.items()))) or [()] * 6
    columns = tuple(np.array(c, dtype=t) for c, t in zip(rows, (np.int64, np.float64, "<U1",
                                                               np.float64, np.float64, np.int64)))
    edges, counts = _edge_table(faces)
    values = _edge_values(vertices, counts, columns, source)
    return build_pattern(dict(vertices=vertices, edges=edges, faces=faces, source=source,
                              **values))


def _edge_values(vertices, counts, hinges: tuple, source: str) -> dict:
    """The per-edge arguments of the pattern (assignments, angles, widths, max angles)
    from the faces on each edge (``counts``, :func:`_edge_table`) and the hinges as
    :func:`_hinge_rows` columns, checked in line order, as the lines were read."""
    n = len(counts)
    for e in np.flatnonzero(counts > 2):
        raise PatternError(f"{source}: edge {e} is shared by {counts[e]} faces (at most 2)")
    edge, width, kind, angle, max_angle, line = hinges
    _check_widths(vertices, edge, width, line, source)
    for k in np.flatnonzero(counts[edge] == 1)[:1]:
        raise PatternError(f"{source}, hinge line {line[k]}: edge {edge[k]} is on the sheet "
                           "boundary (one face); only interior edges take hinges")
    kinds = np.where(counts == 1, "B", "?")
    angles, widths = np.full(n, np.nan), np.full(n, np.nan)
    max_angles = np.full(n, DEFAULT_MAX_ANGLE_DEG)
    kinds[edge], widths[edge], angles[edge], max_angles[edge] = kind, width, angle, max_angle
    missing = np.flatnonzero(kinds == "?")
    if len(missing):
        raise PatternError(f"{source}: interior edge {missing[0]} has no hinge line "
                           f"({len(missing)} missing); every interior edge needs one, since "
                           "the panels are the mesh faces")
    return dict(assignments=kinds, fold_angles=angles, widths=widths, max_angles=max_angles)


def _check_widths(vertices, edge, width, line, source: str) -> None:
    """Each given hinge width (not NaN) within :data:`foldcore.limits.WIDTH_RATIO` of the
    sheet, at once; the first one outside is named by :func:`foldcore.limits.check_width`."""
    given = np.flatnonzero(~np.isnan(width))
    extent = limits.sheet_extent(vertices) if len(given) else 0.0
    if not limits.LENGTH_MM[0] <= extent <= limits.LENGTH_MM[1]:
        return  # check_width skips them: the pattern names the extent
    lo, hi = limits.length_window(limits.WIDTH_RATIO, extent)
    w = width[given]
    for k in given[~(np.isfinite(w) & (lo <= w) & (w <= hi))][:1]:
        limits.check_width(float(width[k]), vertices, f"width of edge {edge[k]}",
                           f"{source}, hinge line {line[k]}")


def _line_lists(data):
    """The lines of ``data`` — bytes (UTF-8, a bad byte read as U+FFFD) or text — as
    ``text.split("\\n")`` gives them, in lists of about :data:`CHUNK_CHARS` characters."""
    newline = "\n" if isinstance(data, str) else b"\n"
    start, size = 0, len(data)
    while start < size:
        cut = data.find(newline, start + CHUNK_CHARS)
        end = size if cut < 0 else cut + 1
        piece = data[start:end]
        text = piece if isinstance(piece, str) else piece.decode("utf-8", errors="replace")
        lines = text.split("\n")
        if text.endswith("\n"):
            lines.pop()  # the end of this piece, not a line
        yield lines
        start = end


def _lines(data):
    """(1-based line number, tokens) of each non-blank line of ``data`` (bytes or text,
    :func:`_line_lists`), ``#`` comments removed."""
    lineno = 0
    for lines in _line_lists(data):
        for line in lines:
            lineno += 1
            tokens = line.split("#", 1)[0].split()
            if tokens:
                yield lineno, tokens


def _float(token: str) -> float | None:
    try:
        value = float(token)
    except ValueError:
        return None
    return value if math.isfinite(value) else None


def _int(token: str) -> int | None:
    try:
        return int(token)
    except ValueError:
        return None


# ------------------------------------------------------------------- writing
def write_obj(path, pattern: CreasePattern) -> None:
    """Write the pattern's vertices (mm, z = 0) and faces as OBJ, atomically.

    Full float precision, so :func:`read_mesh` gives back the same vertices.
    Write the hinges with :func:`write_hinges`.
    """
    with files.atomic_write(path) as fh:
        fh.write("# foldcore crease pattern: 2D polygon mesh, mm (hinges: .hinges file)\n")
        for x, y in pattern.vertices.tolist():
            fh.write(f"v {x!r} {y!r} 0\n")
        for face in pattern.faces:
            fh.write("f " + " ".join(str(v + 1) for v in face.tolist()) + "\n")


def write_hinges(path, pattern: CreasePattern) -> None:
    """Write one hinge line per crease, in :func:`mesh_edges` numbering, atomically."""
    lookup = {(min(a, b), max(a, b)): e for e, (a, b) in enumerate(pattern.edges.tolist())}
    with files.atomic_write(path) as fh:
        fh.write("# foldcore hinge file: edge_id width(mm|auto) M|V|F|U [angle_deg] "
                 "[max=deg]\n# edge ids: unique face sides in order of first appearance\n")
        for i, (a, b) in enumerate(mesh_edges(pattern.face_loops).tolist()):
            e = lookup[(min(a, b), max(a, b))]
            if pattern.assignments[e] != "B":
                fh.write(f"{i} {_hinge_fields(pattern, e)}\n")


def _hinge_fields(pattern: CreasePattern, e: int) -> str:
    width, kind = float(pattern.widths[e]), str(pattern.assignments[e])
    angle, max_angle = float(pattern.fold_angles[e]), float(pattern.max_angles[e])
    fields = ["auto" if math.isnan(width) else repr(width), kind]
    if not math.isnan(angle):
        fields.append(repr(abs(angle) if kind == "M" else angle))
    if max_angle != DEFAULT_MAX_ANGLE_DEG:
        fields.append(f"max={max_angle!r}")
    return " ".join(fields)
