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

Mesh and hinge files above :data:`foldcore.io.MAX_FILE_BYTES` are refused unread.

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
from pathlib import Path

import numpy as np

from .. import files, limits
from ..errors import PatternError
from ..pattern import DEFAULT_MAX_ANGLE_DEG, CreasePattern
from ..planar import loop_starts, next_in_loop
from .fold import build_pattern, read_bytes
from .fold_json import short

HINGE_SUFFIX = ".hinges"
HINGE_KINDS = ("M", "V", "F", "U")
STL_RECORD = np.dtype([("normal", "<f4", 3), ("v", "<f4", (3, 3)), ("attr", "<u2")])


def mesh_edges(faces) -> np.ndarray:
    """The mesh's edge list in hinge-file numbering (see the module docstring).

    Parameters
    ----------
    faces : sequence of (n,) int arrays
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
    faces = [f for f in faces if len(f)]  # an empty face has no sides
    lengths = np.fromiter(map(len, faces), dtype=np.int64, count=len(faces))
    if not faces:
        return np.zeros((0, 2), dtype=np.int64), np.zeros(0, dtype=np.int64)
    flat = np.concatenate([np.asarray(f, dtype=np.int64).ravel() for f in faces])
    a, b = flat, flat[next_in_loop(loop_starts(lengths), lengths)]
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
        The hinge file's bytes.
    source, hinge_source : str
        Names of the mesh and hinge files, used in error messages.
    """
    table = parse_hinges(_text(hinge_data), hinge_source, len(mesh_edges(faces)))
    return pattern_from_mesh(vertices, faces, table, f"{source} (hinges {hinge_source})")


def default_hinge_path(mesh_path) -> str:
    """``mesh_path`` with suffix ``.hinges``; PatternError naming both if missing."""
    mesh = os.fspath(mesh_path)
    hinge = str(Path(mesh).with_suffix(HINGE_SUFFIX))
    if not os.path.exists(hinge):
        raise PatternError(f"{mesh}: no hinge file {hinge} (a mesh needs one hinge line per "
                           "interior edge; pass hinges=PATH to use another file)")
    return hinge


def read_polygons(path) -> tuple[np.ndarray, list[np.ndarray]]:
    """Vertices ((V, 2) float, mm) and 0-based faces of an OBJ or STL file."""
    source = os.fspath(path)
    _mesh_suffix(source)
    return parse_polygons(read_bytes(source), source)


def parse_polygons(data: bytes, source: str) -> tuple[np.ndarray, list[np.ndarray]]:
    """Vertices and faces of OBJ or STL contents; ``source``'s suffix names the format."""
    vertices, faces = parse_obj(_text(data), source) if _mesh_suffix(source) == ".obj" \
        else parse_stl(data, source)
    if not faces:
        raise PatternError(f"{source}: the mesh has no faces")
    return vertices, faces


def _mesh_suffix(source: str) -> str:
    suffix = Path(source).suffix.lower()
    if suffix not in (".obj", ".stl"):
        raise PatternError(f"{source}: not an OBJ or STL file")
    return suffix


def parse_obj(text: str, source: str) -> tuple[np.ndarray, list[np.ndarray]]:
    """Vertices ((V, 2), mm) and 0-based faces of OBJ text (see module docstring)."""
    vertices, faces, lines = [], [], []
    for lineno, tokens in _lines(text):
        if tokens[0] == "v":
            vertices.append(_obj_vertex(tokens, f"{source}, line {lineno}"))
        elif tokens[0] == "f":
            faces.append(_obj_face(tokens, len(vertices), f"{source}, line {lineno}"))
            lines.append(lineno)
    n = len(vertices)
    for f, (face, lineno) in enumerate(zip(faces, lines)):
        bad = [v for v in face if not 0 <= v < n]
        if bad:
            raise PatternError(f"{source}, line {lineno}: face {f} refers to vertex "
                               f"{bad[0] + 1}, but the file has {n} vertices (ids are 1-based)")
    return np.array(vertices, dtype=np.float64).reshape(-1, 2), \
        [np.array(face, dtype=np.int64) for face in faces]


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


def parse_stl(data: bytes, source: str) -> tuple[np.ndarray, list[np.ndarray]]:
    """Vertices ((V, 2), mm; coincident ones merged) and faces of an STL file."""
    count = int.from_bytes(data[80:84], "little")
    if len(data) >= 84 and len(data) == 84 + 50 * count:
        records = np.frombuffer(data, dtype=STL_RECORD, count=count, offset=84)
        return _merge_triangles(records["v"].astype(np.float64), source)
    if b"\0" in data:  # ASCII STL is text: a damaged binary STL
        _bad_binary_stl(data, count, source)
    else:
        polygons = _ascii_stl_loops(_text(data), source)
    return _merge_vertices(polygons)


def _bad_binary_stl(data: bytes, count: int, source: str):
    """Refuse binary data that is not a whole binary STL (truncated, wrong count)."""
    if len(data) < 84:
        raise PatternError(f"{source}: not an ASCII STL (NUL bytes) and only {len(data)} "
                           "bytes, too short for a binary STL (80-byte header + count)")
    raise PatternError(f"{source}: binary STL header says {count} triangles "
                       f"({84 + 50 * count} bytes), but the file has {len(data)} bytes "
                       "(truncated or damaged)")


def _ascii_stl_loops(text: str, source: str) -> list[tuple[str, list]]:
    """[(where, [[x, y, z], ...]), ...]: the vertex loops of an ASCII STL."""
    loops, current = [], None
    for lineno, tokens in _lines(text):
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


def _merge_triangles(tris: np.ndarray, source: str) -> tuple[np.ndarray, list[np.ndarray]]:
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
    return np.ascontiguousarray(vertices).reshape(-1, 2), list(ids.reshape(-1, 3))


def _merge_vertices(polygons) -> tuple[np.ndarray, list[np.ndarray]]:
    ids: dict[tuple[float, float], int] = {}
    faces = []
    for where, loop in polygons:
        if len(loop) < 3:
            raise PatternError(f"{where}: a facet needs at least 3 vertices, got {len(loop)}")
        for x, y, z in loop:
            if not (math.isfinite(x) and math.isfinite(y) and z == 0):
                raise PatternError(f"{where}: vertex ({x:g}, {y:g}, {z:g}) must be finite "
                                   "with z = 0 (the pattern lies flat)")
        faces.append(np.array([ids.setdefault((x, y), len(ids)) for x, y, _ in loop],
                              dtype=np.int64))
    return np.array(list(ids), dtype=np.float64).reshape(-1, 2), faces


def parse_hinges(text: str, source: str, n_edges: int) -> dict[int, tuple]:
    """Hinge lines by edge id: ``{edge: (width_mm, kind, angle_deg, max_deg, line)}``.

    ``width_mm`` is NaN for ``auto``; ``angle_deg`` is signed (valley positive),
    NaN when passive. Raises PatternError naming the file and 1-based line.
    """
    table: dict[int, tuple] = {}
    for lineno, tokens in _lines(text):
        where = f"{source}, line {lineno}"
        edge, *values = _hinge_line(tokens, n_edges, where)
        if edge in table:
            raise PatternError(f"{where}: edge {edge} already has a hinge "
                               f"(line {table[edge][-1]})")
        table[edge] = (*values, lineno)
    return table


def _hinge_line(tokens: list[str], n_edges: int, where: str) -> tuple:
    if len(tokens) < 3:
        raise PatternError(f"{where}: expected 'edge_id width M|V [bend_angle_deg]', "
                           f"got {short(' '.join(tokens))}")
    edge = _int(tokens[0])
    if edge is None or not 0 <= edge < n_edges:
        raise PatternError(f"{where}: edge id {tokens[0]!r} is not an edge of the mesh "
                           f"(ids 0..{n_edges - 1}; see foldcore.io.mesh_edges)")
    width = math.nan if tokens[1].lower() == "auto" else _float(tokens[1])
    if width is None or width <= 0:
        raise PatternError(f"{where}: width {tokens[1]!r} must be a positive number "
                           "(mm) or 'auto'")
    kind = tokens[2].upper()
    if kind not in HINGE_KINDS:
        raise PatternError(f"{where}: hinge kind {tokens[2]!r} must be one of "
                           f"{', '.join(HINGE_KINDS)}")
    return (edge, width, kind, *_hinge_options(tokens[3:], kind, where))


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
    edges, counts = _edge_table(faces)
    n = len(edges)
    for e in np.flatnonzero(counts > 2):
        raise PatternError(f"{source}: edge {e} is shared by {counts[e]} faces (at most 2)")
    _check_widths(vertices, hinges, source)
    kinds = np.where(counts == 1, "B", "?")
    angles, widths = np.full(n, np.nan), np.full(n, np.nan)
    max_angles = np.full(n, DEFAULT_MAX_ANGLE_DEG)
    for e, (width, kind, angle, max_angle, lineno) in hinges.items():
        if counts[e] == 1:
            raise PatternError(f"{source}, hinge line {lineno}: edge {e} is on the sheet "
                               "boundary (one face); only interior edges take hinges")
        kinds[e], widths[e], angles[e], max_angles[e] = kind, width, angle, max_angle
    missing = np.flatnonzero(kinds == "?")
    if len(missing):
        raise PatternError(f"{source}: interior edge {missing[0]} has no hinge line "
                           f"({len(missing)} missing); every interior edge needs one, since "
                           "the panels are the mesh faces")
    return build_pattern(dict(vertices=vertices, edges=edges, assignments=kinds,
                              fold_angles=angles, widths=widths, max_angles=max_angles,
                              faces=faces, source=source))


def _check_widths(vertices, hinges: dict, source: str) -> None:
    """Each given hinge width within :data:`foldcore.limits.WIDTH_RATIO` of the sheet."""
    for e, (width, *_, lineno) in hinges.items():
        if not math.isnan(width):
            limits.check_width(width, vertices, f"width of edge {e}",
                                f"{source}, hinge line {lineno}")


def _lines(text: str):
    """(1-based line number, tokens) of each non-blank line, ``#`` comments removed."""
    for lineno, line in enumerate(text.split("\n"), 1):
        tokens = line.split("#", 1)[0].split()
        if tokens:
            yield lineno, tokens


def _text(data: bytes) -> str:
    return data.decode("utf-8", errors="replace")


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
        for i, (a, b) in enumerate(mesh_edges(pattern.faces).tolist()):
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
