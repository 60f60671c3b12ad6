"""Result files: read a FOLD written by ``foldcore simulate -o`` back as its thick mesh.

The file holds the crease pattern and a ``foldedForm`` frame with the solid's
3D coordinates (mm) and outer faces; :func:`read_result` rebuilds the
ThickMesh it came from, so panels, sub-strips and creases are known again
(the renders, the fabrication files and the viewer page start here).

Every folded frame (a ``simulate --series`` file has one per fold percent) is
checked as it is read, so what reaches a picture, a fabrication file or the
viewer page is known to be in range: coordinates finite and within
±:data:`MAX_FRAME_COORDINATE_MM` mm (after ``frame_unit``), within
``MAX_REACH`` × the sheet of the frame's other vertices, and as many in
every frame; ``frame_title`` a string of at most :data:`MAX_TITLE_CHARS`
characters; achieved angles (``foldcore:pattern_foldAngle``, the file's
``edges_foldAngle``) one per crease-pattern edge, null or degrees in
[−180, 180]. Anything else is refused with a :class:`PatternError` naming the
file, the frame and the item.
"""
from __future__ import annotations

import os
from dataclasses import dataclass

import numpy as np

from . import limits
from .errors import PatternError
from .io.fold import edges_poisson, faces_cells, fold_file_from_dict, read_bytes
from .io.fold_json import (ARRAY, MODEL_KEY, UNIT_MM, check_length, fail, has_class, index, number,
                           number_table, parse_json, short)

#: Largest |coordinate| of a folded frame's vertex, mm (after ``frame_unit``): the
#: largest sheet accepted (1e7 mm across, ``limits.LENGTH_MM``) moved 1e8 × its
#: extent off the origin, where a sheet's faces are already refused as zero-area
#: (docs/architecture.md#accepted-ranges-of-inputs); far inside float32 (3.4e38),
#: in which the viewer page holds positions.
MAX_FRAME_COORDINATE_MM = 1e15
#: Longest ``frame_title`` accepted, characters.
MAX_TITLE_CHARS = 200
#: Largest achieved fold angle magnitude in a frame, degrees (FOLD's range).
MAX_ANGLE_DEG = 180.0

#: Largest RMS misfit (fraction of the thickness) of a panel's rebuilt footprint
#: to its folded shape before :meth:`ResultFile.check_footprint` refuses the flat outlines.
FOOTPRINT_TOLERANCE = 0.05


@dataclass(frozen=True)
class FoldedFrame:
    """One folded frame of a result file, checked (module docstring).

    Attributes
    ----------
    index : int
        Its place in the file's ``file_frames``.
    title : str
        Its ``frame_title`` (at most :data:`MAX_TITLE_CHARS` characters), or
        ``"frame K"`` (K = ``index``) when it has none.
    positions : (N, 3) float
        Vertex positions, mm; finite, within ±:data:`MAX_FRAME_COORDINATE_MM`.
    angles : (E,) float
        Achieved fold angle per edge of the crease pattern, degrees in
        [−:data:`MAX_ANGLE_DEG`, :data:`MAX_ANGLE_DEG`]: the frame's
        ``foldcore:pattern_foldAngle``, else the file's ``edges_foldAngle``;
        NaN where the file gives none (a passive crease, a boundary edge).
    """

    index: int
    title: str
    positions: np.ndarray
    angles: np.ndarray


@dataclass(frozen=True)
class ResultFile:
    """A simulation result read back from FOLD.

    Attributes
    ----------
    pattern : CreasePattern
    mesh : ThickMesh
        Rebuilt with :func:`foldcore.thicken`; its surface equals the file's.
    positions : (N, 3) float
        Folded vertex positions, mm.
    thickness : float
        mm.
    footprint_misfit_mm : float
        Largest RMS distance between a rigid panel's rebuilt flat shape,
        best-fit rotated, and its folded shape (mm); small when the rebuilt
        hinge widths are those simulated (elastic cells, which deform, are
        left out).
    source : str
    frames : tuple of FoldedFrame
        Every folded frame of the file, in order; the last one's positions are
        ``positions``.
    """

    pattern: object
    mesh: object
    positions: np.ndarray
    thickness: float
    footprint_misfit_mm: float
    source: str
    frames: tuple = ()

    def check_footprint(self) -> None:
        """Refuse flat outlines whose hinge widths differ from the simulated ones.

        Raises
        ------
        PatternError
            ``footprint_misfit_mm`` > ``FOOTPRINT_TOLERANCE`` × thickness.
        """
        limit = FOOTPRINT_TOLERANCE * self.thickness
        if self.footprint_misfit_mm > limit:
            raise PatternError(
                f"{self.source}: the panels of the folded frame do not fit the flat sheet "
                f"rebuilt with the file's hinge widths (misfit {self.footprint_misfit_mm:.3g} mm "
                f"> {limit:.3g} mm); pass the thickening.hinge_width used with simulate")


@dataclass(frozen=True)
class SheetResultFile:
    """A thin sheet's result file (``foldcore:model`` "sheet"), checked.

    Attributes
    ----------
    pattern : CreasePattern
    frames : tuple of FoldedFrame, each folded frame (positions: one per pattern
        vertex, mm)
    triangles : (T, 3) int, the last folded frame's triangles (pattern vertex ids)
    source : str
    """

    pattern: object
    frames: tuple
    triangles: np.ndarray
    source: str


def _sheet_result(fold, frames, faces, source: str) -> SheetResultFile:
    """The :class:`SheetResultFile` of a thin sheet's checked frames: one position per
    pattern vertex, faces that are triangles."""
    n = fold.pattern.n_vertices
    if len(frames[-1].positions) != n:
        fail(source, f"file_frames[{frames[-1].index}] has {len(frames[-1].positions)} "
                     f"vertices, the pattern {n}: not a thin sheet's folded form")
    if not faces or any(len(f) != 3 for f in faces):
        fail(source, f"file_frames[{frames[-1].index}]: a thin sheet's folded form is "
                     "triangles (faces_vertices of 3 vertex ids each)")
    return SheetResultFile(fold.pattern, tuple(frames), np.array(faces, dtype=np.int64),
                           source)


def read_result(path, hinge_width=None, subdivisions=None, thin: bool = False):
    """Read a FOLD result (``foldcore simulate -o``) and rebuild its thick mesh.

    The file holds the crease pattern (with ``foldcore:thickness`` and the
    hinge widths) and a ``foldedForm`` frame with the solid's 3D coordinates
    and outer faces. The stored faces alone cannot tell panels from hinges
    nor mountain from valley, so the ThickMesh is rebuilt with
    :func:`foldcore.thicken` from the file's pattern and thickness; thicken is
    deterministic, so the same settings give the same vertex ids, and the
    rebuilt mesh is accepted only if its outer faces equal the stored ones.
    The stored coordinates are then the positions of the rebuilt mesh: panels,
    sub-strips and their creases (M/V) are all known. The mesh is matched to
    the last folded frame; every folded frame is checked (module docstring)
    and kept in ``frames``. With ``thin``, a thin sheet's result (``foldcore:model``
    "sheet") is read as a :class:`SheetResultFile` (its frames, checked, and its
    triangles) instead of refused.

    Parameters
    ----------
    path : str or os.PathLike
    hinge_width : float, optional
        mm; as given to simulate (``--hinge-width``); default: the file's widths.
    subdivisions : int or "auto", optional
        As given to simulate; default: try ``auto`` (with the file's hinge
        models, ``foldcore:edges_hinge``; without them the default model,
        then Eq. 8), then 1 … 16 sub-strips on every crease.

    Raises
    ------
    PatternError
        Unreadable or malformed file, no folded frame, a folded frame out of
        range (module docstring), no thickness, or no rebuilt mesh matching the
        stored faces.
    """
    from .measure import element_rotations

    source = os.fspath(path)
    data = read_bytes(source)
    if not data.lstrip(b"\xef\xbb\xbf \t\r\n").startswith(b"{"):
        raise PatternError(f"{source}: not a result FOLD file (a JSON object); "
                           "`foldcore simulate PATTERN -o RESULT.fold` writes one")
    d = parse_json(data, source)
    fold = fold_file_from_dict(d, source)
    frames, faces = _folded_frames(d, fold.pattern.n_edges, source)
    if fold.thickness is None and d.get(MODEL_KEY) == "sheet":
        if thin:
            return _sheet_result(fold, frames, faces, source)
        raise PatternError(f"{source}: a thin sheet's result (folded with no thickness): "
                           "export reads thick results; render and view show it, and its "
                           "folded form is the file's foldedForm frame, for any FOLD viewer")
    if fold.thickness is None:
        raise PatternError(f"{source}: no foldcore:thickness; not a foldcore result file")
    for frame in frames:
        _check_reach(frame, fold.pattern, fold.thickness, source)
    positions = frames[-1].positions
    if hinge_width is not None:
        limits.check_width(hinge_width, fold.pattern.vertices, "thickening.hinge_width", source)
    recipe = {"elastic": faces_cells(d, len(fold.pattern.faces), source) or None,
              "stretch": edges_poisson(d, fold.pattern.n_edges, source) or None,
              "hinge": fold.hinge}
    mesh = _matching_mesh(fold.pattern, fold.thickness, hinge_width, subdivisions,
                          positions, faces, source, recipe)
    panels = mesh.groups[mesh.panel_group]
    rot = element_rotations(panels, positions)
    misfit = 0.0
    for e in range(len(panels)):
        if int(panels.source[e]) in mesh.elastic:
            continue  # elastic cells deform by design: only rigid panels test the widths
        s = panels.slots(e)
        p = positions[panels.indices[s]]
        diff = p - p.mean(axis=0) - panels.rest[s] @ rot[e].T
        misfit = max(misfit, float(np.sqrt((diff ** 2).sum(axis=1).mean())))
    return ResultFile(fold.pattern, mesh, positions, fold.thickness, misfit, source,
                      tuple(frames))


MAX_REACH = 1e3  # × (sheet extent + thickness): farthest a folded vertex may lie from the rest


def _check_reach(frame: FoldedFrame, pattern, thickness: float, source: str) -> None:
    """Refuse a folded frame with a vertex farther than ``MAX_REACH`` × (the sheet's
    extent + thickness) from the frame's median: no fold of the sheet puts one
    there, and such values overflow the rotation fits (``np.linalg.svd`` does not
    return on a coordinate of 1e308)."""
    extent = float(np.ptp(pattern.vertices, axis=0).max()) + float(thickness)
    positions = frame.positions
    reach = np.abs(positions - np.median(positions, axis=0)).max(axis=1)
    far = np.flatnonzero(~(reach <= MAX_REACH * extent))
    if len(far):
        v = int(far[0])
        fail(source, f"file_frames[{frame.index}], vertex {v}: at {positions[v].tolist()} it "
                     f"lies beyond {MAX_REACH:g} × the sheet's extent ({extent:g} mm) from "
                     "the others; not a fold of this sheet")


def _folded_frames(d: dict, n_edges: int, source: str) -> tuple[list, list]:
    """Every ``foldedForm`` frame of a FOLD dict, checked (:class:`FoldedFrame`, in
    order), and the last one's faces; every frame has the last one's vertex count."""
    raw = d.get("file_frames")
    raw = list(enumerate(raw)) if isinstance(raw, list) else []
    folded = [(i, f) for i, f in raw if isinstance(f, dict) and _is_folded(f, i, source)]
    if not folded:
        fail(source, "no folded frame (file_frames with frame_classes 'foldedForm'); "
                     "write one with foldcore simulate -o")
    key_angles = d.get("edges_foldAngle")
    key_angles = np.full(n_edges, np.nan) if key_angles is None else \
        _angles(key_angles, "edges_foldAngle", n_edges, source)
    frames = [_folded_frame(i, f, d, key_angles, source) for i, f in folded]
    last = frames[-1]
    for frame in frames:
        if len(frame.positions) != len(last.positions):
            fail(source, f"file_frames[{frame.index}] has {len(frame.positions)} vertices, "
                         f"file_frames[{last.index}] (the last folded frame) "
                         f"{len(last.positions)}")
    return frames, _frame_faces(folded[-1][1].get("faces_vertices"), len(last.positions),
                                last.index, source)


def _folded_frame(i: int, frame: dict, d: dict, key_angles: np.ndarray,
                  source: str) -> FoldedFrame:
    """``file_frames[i]`` of the FOLD dict ``d``, checked; its angles are its own
    ``foldcore:pattern_foldAngle`` or else ``key_angles`` (the file's, checked)."""
    from .outputs import SERIES_ANGLE_KEY

    angles = frame.get(SERIES_ANGLE_KEY)
    if angles is not None:
        angles = _angles(angles, f"file_frames[{i}].{SERIES_ANGLE_KEY}", len(key_angles),
                         source)
    return FoldedFrame(i, _frame_title(frame.get("frame_title"), i, source),
                       _frame_positions(frame, d, i, source),
                       key_angles if angles is None else angles)


def _is_folded(frame: dict, i: int, source: str) -> bool:
    """Whether ``frame`` (``file_frames[i]``) is a folded form; its ``frame_classes``
    must be a list."""
    classes = frame.get("frame_classes", [])
    if not isinstance(classes, list):
        fail(source, f"file_frames[{i}].frame_classes must be a list of strings, "
                     f"got {short(classes)}")
    return has_class(classes, "foldedForm")


def _frame_title(title, i: int, source: str) -> str:
    """``file_frames[i]``'s ``frame_title``: a string of at most :data:`MAX_TITLE_CHARS`
    characters, or ``"frame i"`` if absent."""
    if title is None:
        return f"frame {i}"
    if not isinstance(title, str) or len(title) > MAX_TITLE_CHARS:
        fail(source, f"file_frames[{i}]: frame_title must be text of at most "
                     f"{MAX_TITLE_CHARS} characters, got {short(title)}")
    return title


def _frame_positions(frame: dict, d: dict, i: int, source: str) -> np.ndarray:
    """(N, 3) positions, mm, of ``file_frames[i]``: finite and within
    ±:data:`MAX_FRAME_COORDINATE_MM` after its ``frame_unit``."""
    unit = frame.get("frame_unit", d.get("frame_unit", "unit"))
    if not isinstance(unit, str) or unit not in UNIT_MM:
        fail(source, f"file_frames[{i}]: unknown frame_unit {short(unit)}")
    with np.errstate(over="ignore"):  # inf beyond float64: refused below
        x = _frame_coords(frame.get("vertices_coords"), i, source) * UNIT_MM[unit]
    far = np.flatnonzero(~(np.abs(x) <= MAX_FRAME_COORDINATE_MM).all(axis=1))
    if len(far):
        v = int(far[0])
        fail(source, f"file_frames[{i}], vertex {v}: at {x[v].tolist()} mm (frame_unit "
                     f"{unit!r}) it lies beyond ±{MAX_FRAME_COORDINATE_MM:g} mm")
    return x


def _frame_coords(rows, i: int, source: str) -> np.ndarray:
    """(N, 3) float of ``file_frames[i]``'s ``vertices_coords``: finite JSON numbers only."""
    if not isinstance(rows, ARRAY) or not rows:
        fail(source, f"file_frames[{i}]: vertices_coords must be a non-empty list of "
                     f"[x, y, z], got {short(rows)}")
    table = number_table(rows, (3,))
    if table is not None and np.isfinite(table).all():
        return table
    out = []
    for v, row in enumerate(rows):
        xyz = [number(c) for c in row] if isinstance(row, ARRAY) else []
        if len(xyz) != 3 or None in xyz:
            fail(source, f"file_frames[{i}], vertex {v}: vertices_coords[{v}] must be 3 "
                         f"finite numbers [x, y, z], got {short(row)}")
        out.append(xyz)
    return np.array(out, dtype=float)


def _angles(raw, key: str, n_edges: int, source: str) -> np.ndarray:
    """(E,) degrees of a per-edge angle list ``raw`` (``key``): null (NaN) or a number
    in [−:data:`MAX_ANGLE_DEG`, :data:`MAX_ANGLE_DEG`] per edge."""
    check_length(raw, key, n_edges, source, "edge")
    if set(map(type, raw)) <= {int, float, type(None)}:  # at once: None → NaN (not in JSON)
        try:
            out = np.array(raw, dtype=np.float64)
        except OverflowError:  # an int beyond float range: found below
            out = None
        if out is not None and not (np.abs(out) > MAX_ANGLE_DEG).any():
            return out
    out = np.full(n_edges, np.nan)
    for e, a in enumerate(raw):
        value = number(a)
        if a is not None and (value is None or not abs(value) <= MAX_ANGLE_DEG):
            fail(source, f"{key}[{e}] (edge {e}) must be null or degrees in "
                         f"[-{MAX_ANGLE_DEG:g}, {MAX_ANGLE_DEG:g}], got {short(a)}")
        out[e] = np.nan if a is None else value
    return out


def _frame_faces(rows, n: int, i: int, source: str) -> list:
    """``file_frames[i]``'s ``faces_vertices`` as tuples of vertex ids in 0..n-1."""
    if not isinstance(rows, ARRAY):
        fail(source, f"file_frames[{i}]: faces_vertices must be a list of vertex-id lists, "
                     f"got {short(rows)}")
    faces = []
    for f, row in enumerate(rows):
        ids = [index(v, n) for v in row] if isinstance(row, ARRAY) else [None]
        if None in ids:
            fail(source, f"file_frames[{i}], face {f}: faces_vertices[{f}] must be vertex "
                         f"ids in 0..{n - 1}, got {short(row)}")
        faces.append(tuple(ids))
    return faces


def _matching_mesh(pattern, thickness, hinge_width, subdivisions, positions, faces, source,
                   recipe=None):
    """The ThickMesh whose outer faces are ``faces`` (see :func:`read_result`);
    ``recipe``: thicken's ``elastic``/``stretch``/``hinge`` as stored in the file."""
    from .errors import MeshError
    from .mesh import surface_faces
    from .thickening import MAX_SUBDIVISIONS, thicken

    recipe = dict(recipe or {})
    hinge = recipe.pop("hinge", None)
    if subdivisions is not None:
        candidates = [(subdivisions, hinge)]
    else:  # without stored models: the default, then Eq. 8 (whose auto counts differ)
        candidates = [("auto", hinge)] + ([("auto", "eq8")] if hinge is None else []) + \
                     [(k, hinge) for k in range(1, MAX_SUBDIVISIONS + 1)]
    wanted = sorted(tuple(sorted(f)) for f in faces)
    first_error = None
    for k, model in candidates:
        try:
            mesh = thicken(pattern, thickness, hinge_width, k, hinge=model, **recipe)
        except MeshError as exc:
            first_error = first_error or exc
            continue
        if mesh.n_vertices != len(positions):
            continue
        if sorted(tuple(sorted(f.tolist())) for f in surface_faces(mesh)) == wanted:
            return mesh
    if first_error is not None and subdivisions is not None:
        raise first_error
    tried = "subdivisions " + (str(subdivisions) if subdivisions is not None
                               else f"auto and 1..{MAX_SUBDIVISIONS}")
    raise PatternError(f"{source}: the folded frame ({len(positions)} vertices, {len(faces)} "
                       f"faces) matches no thick mesh rebuilt from the file (thickness "
                       f"{thickness:g} mm, {tried}); pass the thickening.subdivisions "
                       "and thickening.hinge_width used with simulate")
