"""Result files: read a FOLD written by ``foldcore simulate -o`` back as its thick mesh.

The file holds the crease pattern and a ``foldedForm`` frame with the solid's
3D coordinates (mm) and outer faces; :func:`read_result` rebuilds the
ThickMesh it came from, so panels, sub-strips and creases are known again
(the renders, the fabrication files and the viewer page start here).
"""
from __future__ import annotations

import os
from dataclasses import dataclass

import numpy as np

from . import limits
from .errors import PatternError
from .io.fold import edges_poisson, faces_cells, fold_file_from_dict, read_bytes
from .io.fold_json import ARRAY, UNIT_MM, index, number, parse_json, short

#: Largest RMS misfit (fraction of the thickness) of a panel's rebuilt footprint
#: to its folded shape before :meth:`ResultFile.check_footprint` refuses the flat outlines.
FOOTPRINT_TOLERANCE = 0.05


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
    """

    pattern: object
    mesh: object
    positions: np.ndarray
    thickness: float
    footprint_misfit_mm: float
    source: str

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


def read_result(path, hinge_width=None, subdivisions=None) -> ResultFile:
    """Read a FOLD result (``foldcore simulate -o``) and rebuild its thick mesh.

    The file holds the crease pattern (with ``foldcore:thickness`` and the
    hinge widths) and a ``foldedForm`` frame with the solid's 3D coordinates
    and outer faces. The stored faces alone cannot tell panels from hinges
    nor mountain from valley, so the ThickMesh is rebuilt with
    :func:`foldcore.thicken` from the file's pattern and thickness; thicken is
    deterministic, so the same settings give the same vertex ids, and the
    rebuilt mesh is accepted only if its outer faces equal the stored ones.
    The stored coordinates are then the positions of the rebuilt mesh: panels,
    sub-strips and their creases (M/V) are all known.

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
        Unreadable or malformed file, no folded frame, no thickness, or no
        rebuilt mesh matching the stored faces.
    """
    from .measure import element_rotations

    source = os.fspath(path)
    d = parse_json(read_bytes(source), source)
    fold = fold_file_from_dict(d, source)
    positions, faces = _folded_frame(d, source)
    if fold.thickness is None:
        raise PatternError(f"{source}: no foldcore:thickness; not a foldcore result file")
    _check_reach(positions, fold.pattern, fold.thickness, source)
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
    return ResultFile(fold.pattern, mesh, positions, fold.thickness, misfit, source)


MAX_REACH = 1e3  # × (sheet extent + thickness): farthest a folded vertex may lie from the rest


def _check_reach(positions, pattern, thickness: float, source: str) -> None:
    """Refuse a folded frame with a vertex farther than ``MAX_REACH`` × (the sheet's
    extent + thickness) from the frame's median: no fold of the sheet puts one
    there, and such values overflow the rotation fits (``np.linalg.svd`` does not
    return on a coordinate of 1e308)."""
    extent = float(np.ptp(pattern.vertices, axis=0).max()) + float(thickness)
    reach = np.abs(positions - np.median(positions, axis=0)).max(axis=1)
    far = np.flatnonzero(~(reach <= MAX_REACH * extent))
    if len(far):
        v = int(far[0])
        raise PatternError(f"{source}: folded frame: vertex {v} at {positions[v].tolist()} lies "
                           f"beyond {MAX_REACH:g} × the sheet's extent ({extent:g} mm) from "
                           "the others; not a fold of this sheet")


def _folded_frame(d: dict, source: str):
    """(N, 3) positions (mm) and faces of the last ``foldedForm`` frame of a FOLD dict."""
    frames = d.get("file_frames")
    frames = [f for f in frames if isinstance(f, dict)] if isinstance(frames, list) else []
    for i, f in enumerate(frames):
        if not isinstance(f.get("frame_classes", []), list):
            raise PatternError(f"{source}: file_frames[{i}].frame_classes must be a list of "
                               f"strings, got {f['frame_classes']!r}")
    folded = [f for f in frames if "foldedForm" in (f.get("frame_classes") or [])]
    if not folded:
        raise PatternError(f"{source}: no folded frame (file_frames with frame_classes "
                           "'foldedForm'); write one with foldcore simulate -o")
    frame = folded[-1]
    unit = frame.get("frame_unit", d.get("frame_unit", "unit"))
    if not isinstance(unit, str) or unit not in UNIT_MM:
        raise PatternError(f"{source}: folded frame: unknown frame_unit {unit!r}")
    x = _frame_coords(frame.get("vertices_coords"), source) * UNIT_MM[unit]
    if not np.isfinite(x).all():
        v = int(np.flatnonzero(~np.isfinite(x).all(axis=1))[0])
        raise PatternError(f"{source}: folded frame: vertex {v} overflows when converted "
                           f"to mm (frame_unit {unit!r})")
    return x, _frame_faces(frame.get("faces_vertices"), len(x), source)


def _frame_coords(rows, source: str) -> np.ndarray:
    """(N, 3) float of a folded frame's ``vertices_coords``: finite JSON numbers only."""
    if not isinstance(rows, ARRAY) or not rows:
        raise PatternError(f"{source}: folded frame: vertices_coords must be a non-empty "
                           f"list of [x, y, z], got {short(rows)}")
    out = []
    for i, row in enumerate(rows):
        xyz = [number(c) for c in row] if isinstance(row, ARRAY) else []
        if len(xyz) != 3 or None in xyz:
            raise PatternError(f"{source}: folded frame: vertices_coords[{i}] must be 3 "
                               f"finite numbers [x, y, z], got {short(row)}")
        out.append(xyz)
    return np.array(out, dtype=float)


def _frame_faces(rows, n: int, source: str) -> list:
    """A folded frame's ``faces_vertices`` as tuples of vertex ids in 0..n-1."""
    if not isinstance(rows, ARRAY):
        raise PatternError(f"{source}: folded frame: faces_vertices must be a list of "
                           f"vertex-id lists, got {short(rows)}")
    faces = []
    for i, row in enumerate(rows):
        ids = [index(v, n) for v in row] if isinstance(row, ARRAY) else [None]
        if None in ids:
            raise PatternError(f"{source}: folded frame: faces_vertices[{i}] must be vertex "
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
