"""Fabrication files: the flat thick sheet as SVG/DXF outlines, the folded solid as STL.

Flat sheet (laser cutting), from the ThickMesh footprint ``mesh.points`` (mm):

* layer ``CUT``: the outline of the whole sheet and the holes left at the
  vertices (the union of every panel and hinge strip), cut through;
* layer ``PANEL``: the outline of every panel;
* layers ``HINGE_M`` / ``HINGE_V`` / ``HINGE_F``: the outline of every
  mountain / valley / facet hinge strip (all its sub-strips), and ``HINGE``
  the others (undriven ``U``, or every strip when no pattern is given).

Colours follow Origami Simulator's crease colours, so a file from one tool
does not contradict the other: cut outline black (its boundary), mountain red,
valley blue, facet yellow, other hinges magenta (its undriven), panels grey
(SVG stroke colours; DXF ACI 7, 1, 5, 2, 6, 8). Stroke width and margin are mm
options; by default a thousandth of the sheet's larger extent (at most
``SVG_STROKE_MAX_MM``, a laser cutter's hairline) and 2 % of it, so a
unit-square sheet is not drawn with strokes 5 % of its width.

Panel and hinge outlines share their common sides (the score lines); which
layer is cut, scored or only drawn is the laser operator's choice. Every
outline is one closed polyline, collinear points removed. SVG is written by
hand (three element types, exact mm units through ``viewBox``, deterministic
output, no dependency); DXF through ezdxf (the ``export`` extra), the
reference DXF writer for Python, ``$INSUNITS`` = mm.

Folded solid (3D printing, CAD): binary STL of the outer surface of the prism
mesh at given positions, written with NumPy (a 50-byte record per triangle is
all the format is; meshio would add a dependency and write to a path we
could not make atomic). Caps (top/bottom faces) are ear-clipped on the flat
footprint, where every panel is a simple polygon, so non-convex panels are
triangulated correctly; side faces are quads split in two. Each triangle is
wound counter-clockwise seen from outside: the surface is closed, every edge
is shared by exactly two triangles, and its signed volume is the solid's.

Every file is written atomically (:func:`atomic_path`): it appears complete
or not at all.

Result files: :func:`read_result` reads a FOLD written by ``foldcore simulate
-o`` (crease pattern + folded-form frame with the solid's 3D coordinates) and
rebuilds the ThickMesh it came from (see its docstring for why).
"""
from __future__ import annotations

import io
import os
from contextlib import contextmanager
from dataclasses import dataclass

import numpy as np

from . import limits
from .errors import FoldcoreError, PatternError
from .io.fold import atomic_path as io_atomic_path
from .io.fold import atomic_write
from .mesh import SurfaceFaces, surface_polygons  # noqa: F401  (part of this API)

LAYERS = {"CUT": {"dxf_colour": 7, "svg": "#000000"},      # black: the boundary
          "PANEL": {"dxf_colour": 8, "svg": "#808080"},    # grey
          "HINGE_M": {"dxf_colour": 1, "svg": "#ff0000"},  # red: mountain
          "HINGE_V": {"dxf_colour": 5, "svg": "#0000ff"},  # blue: valley
          "HINGE_F": {"dxf_colour": 2, "svg": "#ffff00"},  # yellow: facet
          "HINGE": {"dxf_colour": 6, "svg": "#ff00ff"}}    # magenta: undriven / all
#: Default SVG margin and stroke width, as shares of the sheet's larger extent, and
#: the widest default stroke (mm).
SVG_MARGIN_SHARE = 0.02
SVG_STROKE_SHARE = 1e-3
SVG_STROKE_MAX_MM = 0.1
#: Largest RMS misfit (fraction of the thickness) of a panel's rebuilt footprint
#: to its folded shape before :func:`read_result` refuses the flat outlines.
FOOTPRINT_TOLERANCE = 0.05
_STL_RECORD = np.dtype([("normal", "<f4", (3,)), ("vertices", "<f4", (3, 3)),
                        ("attribute", "<u2")])


class ExportError(FoldcoreError, ValueError):
    """A fabrication file cannot be made (bad geometry, missing package, no output)."""


# ------------------------------------------------------------------- writing
@contextmanager
def atomic_path(path, suffix: str | None = None):
    """:func:`foldcore.io.fold.atomic_path` after checking the folder exists
    (:class:`ExportError` naming it); the temporary name ends with ``suffix``
    (default: ``path``'s own suffix), so format-by-name writers still work."""
    target = os.fspath(path)
    _, name = _check_folder(target)
    suffix = os.path.splitext(name)[1] if suffix is None else suffix
    with io_atomic_path(target, suffix) as tmp:
        yield tmp


def _check_folder(target: str) -> tuple[str, str]:
    """(folder, name) of an output path; ExportError naming it if the folder is missing."""
    folder, name = os.path.split(os.path.abspath(target))
    if not name or not os.path.isdir(folder):
        raise ExportError(f"{target}: cannot write there (no such folder: {folder})")
    return folder, name


def write_bytes(path, data: bytes) -> None:
    """Write ``data`` to ``path`` atomically (temporary file, fsync, rename)."""
    _check_folder(os.fspath(path))
    with atomic_write(path, binary=True) as fh:
        fh.write(data)


# ------------------------------------------------------------------- surface


def triangulate_polygon(xy) -> np.ndarray:
    """Ear-clipping triangulation of a simple polygon, (n−2, 3) local indices.

    Parameters
    ----------
    xy : (n, 2) float
        Vertices in order (either orientation; collinear points allowed).

    Returns
    -------
    (n−2, 3) int64, each triangle in the polygon's own orientation.
    """
    xy = np.asarray(xy, dtype=float)
    n = len(xy)
    area2 = float(np.sum(xy[:, 0] * np.roll(xy[:, 1], -1) - np.roll(xy[:, 0], -1) * xy[:, 1]))
    order = list(range(n)) if area2 >= 0 else list(range(n))[::-1]
    eps = 1e-12 * max(float(np.ptp(xy, axis=0).max()), 1e-300) ** 2
    tris = []
    while len(order) > 3:
        for t in range(len(order)):
            a, b, c = order[t - 1], order[t], order[(t + 1) % len(order)]
            if _cross2(xy[a], xy[b], xy[c]) > eps and not _any_inside(xy, order, a, b, c, eps):
                tris.append((a, b, c))
                del order[t]
                break
        else:
            raise ExportError("cannot triangulate a face: its polygon is not simple")
    tris.append(tuple(order))
    out = np.array(tris, dtype=np.int64)
    return out if area2 >= 0 else out[:, ::-1]


def _cross2(a, b, c) -> float:
    return float((b[0] - a[0]) * (c[1] - b[1]) - (b[1] - a[1]) * (c[0] - b[0]))


def _any_inside(xy, order, a, b, c, eps) -> bool:
    """Is any polygon vertex other than a, b, c inside or on triangle abc (CCW)?"""
    others = [i for i in order if i not in (a, b, c)]
    if not others:
        return False
    p = xy[others]
    inside = np.ones(len(others), dtype=bool)
    for u, v in ((a, b), (b, c), (c, a)):
        e = xy[v] - xy[u]
        inside &= e[0] * (p[:, 1] - xy[u][1]) - e[1] * (p[:, 0] - xy[u][0]) >= -eps
    return bool(inside.any())


def surface_triangles(mesh, surface: SurfaceFaces | None = None, return_faces: bool = False):
    """(T, 3) int64 vertex ids of the outer surface, outward (counter-clockwise) winding.

    Caps are triangulated on the flat footprint ``mesh.points`` (valid for any
    simple panel); side quads are split along a diagonal. With
    ``return_faces`` also the (T,) index of each triangle's face in ``surface``.
    """
    surface = surface or surface_polygons(mesh)
    n_top = len(mesh.points)
    tris, owner = [], []
    for f, (loop, cap) in enumerate(zip(surface.loops, surface.is_cap)):
        if cap:
            local = triangulate_polygon(mesh.points[loop % n_top])
            # a bottom loop is reversed, so its footprint is clockwise: the
            # triangles keep that orientation, outward (−z) at rest
            tris.append(loop[local])
        else:
            tris.append(loop[[[0, 1, 2], [0, 2, 3]]])
        owner.append(np.full(len(tris[-1]), f, dtype=np.int64))
    out = np.vstack(tris) if tris else np.zeros((0, 3), dtype=np.int64)
    if return_faces:
        return out, (np.concatenate(owner) if owner else np.zeros(0, dtype=np.int64))
    return out


def surface_edges(surface: SurfaceFaces) -> np.ndarray:
    """(K, 2) int64 distinct polygon edges of the outer surface (vertex ids, sorted pairs)."""
    pairs = [np.column_stack([loop, np.roll(loop, -1)]) for loop in surface.loops]
    if not pairs:
        return np.zeros((0, 2), dtype=np.int64)
    return np.unique(np.sort(np.vstack(pairs), axis=1), axis=0)


def enclosed_volume(positions, triangles) -> float:
    """Signed volume (mm³) enclosed by a closed triangle surface (divergence theorem)."""
    v = np.asarray(positions, dtype=float)[np.asarray(triangles)]
    return float(np.einsum("ij,ij->i", v[:, 0], np.cross(v[:, 1], v[:, 2])).sum() / 6.0)


# ------------------------------------------------------------------- STL
def stl_bytes(mesh, positions=None, header: str = "foldcore thick solid, mm") -> bytes:
    """Binary STL of the mesh's outer surface at ``positions`` (N, 3) mm (default: rest)."""
    x = mesh.rest_positions if positions is None else np.asarray(positions, dtype=float)
    if x.shape != (mesh.n_vertices, 3) or not np.isfinite(x).all():
        raise ExportError(f"positions must be a finite ({mesh.n_vertices}, 3) array of mm, "
                          f"got shape {x.shape}")
    tris = surface_triangles(mesh)
    v = x[tris]
    normal = np.cross(v[:, 1] - v[:, 0], v[:, 2] - v[:, 0])
    length = np.linalg.norm(normal, axis=1)
    normal = np.divide(normal, length[:, None], out=np.zeros_like(normal),
                       where=length[:, None] > 0)
    records = np.zeros(len(tris), dtype=_STL_RECORD)
    records["normal"], records["vertices"] = normal, v
    head = header.encode("ascii", "replace")[:80].ljust(80, b" ")
    if head.lower().startswith(b"solid"):   # binary STL must not look like ASCII STL
        head = b"foldcore " + head[:71]
    return head + np.uint32(len(tris)).tobytes() + records.tobytes()


def write_stl(path, mesh, positions=None) -> None:
    """Write :func:`stl_bytes` to ``path`` atomically."""
    write_bytes(path, stl_bytes(mesh, positions))


# ------------------------------------------------------------------- outlines
def sheet_outlines(mesh, pattern=None) -> dict:
    """Closed outlines of the flat thick sheet, mm, per layer.

    Parameters
    ----------
    mesh : ThickMesh
    pattern : CreasePattern, optional
        Splits the hinge strips by their crease's assignment (``HINGE_M``,
        ``HINGE_V``, ``HINGE_F``; the rest stay ``HINGE``).

    Returns
    -------
    dict {"CUT", "PANEL", "HINGE", ...: list of (n, 2) float}
        Each outline once (not repeating its first point), counter-clockwise
        except holes (clockwise), collinear points removed. ``CUT``: the
        sheet's outer boundary and its holes; ``PANEL``: one per panel;
        ``HINGE*``: one per crease strip (layers without an outline left out).
    """
    import shapely

    pts = mesh.points
    panels = mesh.groups[mesh.panel_group]
    panel_loops = [pts[_top(panels, i)] for i in range(len(panels))]
    creases = sorted(mesh.strips_of_crease)
    hinge_loops = [pts[_strip_outline(mesh, e)] for e in creases]
    stretch = mesh.groups.get("stretch_hinge")
    if stretch is not None:  # one strip per crease, its top loop is its outline
        hinge_loops += [pts[_top(stretch, i)] for i in range(len(stretch))]
        creases += [int(e) for e in stretch.source]
    polygons = [shapely.Polygon(p) for p in panel_loops + hinge_loops]
    union = shapely.union_all(polygons)
    cut = []
    for poly in getattr(union, "geoms", [union]):
        poly = shapely.orient_polygons(poly) if hasattr(shapely, "orient_polygons") \
            else shapely.geometry.polygon.orient(poly)
        cut.append(np.asarray(poly.exterior.coords)[:-1])
        cut += [np.asarray(ring.coords)[:-1] for ring in poly.interiors]
    scale = float(np.ptp(pts, axis=0).max())
    clean = lambda loops: [_drop_collinear(p, scale) for p in loops]  # noqa: E731
    out = {"CUT": clean(cut), "PANEL": clean(panel_loops)}
    layer = [_hinge_layer(pattern, e) for e in creases]
    for name in ("HINGE_M", "HINGE_V", "HINGE_F", "HINGE"):
        loops = [p for p, at in zip(hinge_loops, layer) if at == name]
        if loops or name == "HINGE" and pattern is None:
            out[name] = clean(loops)
    return out


def _hinge_layer(pattern, edge: int) -> str:
    kind = "" if pattern is None else str(pattern.assignments[edge])
    return f"HINGE_{kind}" if kind in ("M", "V", "F") else "HINGE"


def _top(group, i) -> np.ndarray:
    ids = group.indices[group.slots(i)]
    return ids[:len(ids) // 2]


def _strip_outline(mesh, e) -> np.ndarray:
    """Footprint ids of the whole strip of crease ``e``: its four corners (the outer
    sub-strips of its first and last segments along the crease)."""
    hinges = mesh.groups["bending_hinge"]
    strips, k = mesh.strips_of_crease[e], int(mesh.subdivisions[e])
    # sub-strip top: a_j, a_j+1, b_j+1, b_j; segment-major, k strips per segment
    corners = [(strips[0], 0), (strips[k - 1], 1), (strips[-1], 2), (strips[-k], 3)]
    return np.array([_top(hinges, s)[i] for s, i in corners])


def _drop_collinear(xy, scale: float) -> np.ndarray:
    xy = np.asarray(xy, dtype=float)
    keep = np.ones(len(xy), dtype=bool)
    for _ in range(len(xy)):
        idx = np.flatnonzero(keep)
        if len(idx) <= 3:
            break
        p, q, r = xy[np.roll(idx, 1)], xy[idx], xy[np.roll(idx, -1)]
        d1, d2 = q - p, r - q
        cross = d1[:, 0] * d2[:, 1] - d1[:, 1] * d2[:, 0]
        flat = np.abs(cross) <= 1e-9 * scale * (np.linalg.norm(d1, axis=1) +
                                               np.linalg.norm(d2, axis=1))
        if not flat.any():
            break
        keep[idx[np.flatnonzero(flat)[0]]] = False
    return xy[keep]


# ------------------------------------------------------------------- SVG
def svg_text(outlines: dict, title: str = "foldcore flat sheet", stroke_mm: float | None = None,
             margin_mm: float | None = None) -> str:
    """An SVG document (mm) of :func:`sheet_outlines`: one ``<g>`` per layer, ``<polygon>``s.

    SVG's y axis points down, so y is written negated (the sheet is not mirrored).
    ``stroke_mm``/``margin_mm``: stroke width and margin around the sheet, mm
    (default: shares of the sheet's extent, module docstring).
    """
    every = np.vstack([p for loops in outlines.values() for p in loops])
    extent = float(np.ptp(every, axis=0).max())
    stroke = min(SVG_STROKE_MAX_MM, SVG_STROKE_SHARE * extent) if stroke_mm is None \
        else stroke_mm
    margin = SVG_MARGIN_SHARE * extent if margin_mm is None else margin_mm
    lo, hi = every.min(axis=0) - margin, every.max(axis=0) + margin
    w, h = hi - lo
    lines = ['<?xml version="1.0" encoding="UTF-8"?>',
             f'<svg xmlns="http://www.w3.org/2000/svg" version="1.1" width="{_num(w)}mm" '
             f'height="{_num(h)}mm" viewBox="{_num(lo[0])} {_num(-hi[1])} {_num(w)} {_num(h)}">',
             f"<title>{_xml(title)}</title>"]
    for layer, loops in outlines.items():
        colour = LAYERS.get(layer, {}).get("svg", "#000000")
        lines.append(f'<g id="{layer.lower()}" fill="none" stroke="{colour}" '
                     f'stroke-width="{_num(stroke)}">')
        for p in loops:
            points = " ".join(f"{_num(x)},{_num(-y)}" for x, y in p)
            lines.append(f'<polygon points="{points}"/>')
        lines.append("</g>")
    lines.append("</svg>")
    return "\n".join(lines) + "\n"


def _num(v) -> str:
    text = f"{float(v):.6f}".rstrip("0").rstrip(".")
    return "0" if text in ("-0", "") else text


def _xml(text: str) -> str:
    return str(text).replace("&", "&amp;").replace("<", "&lt;").replace(">", "&gt;")


def write_svg(path, mesh, pattern=None, stroke_mm: float | None = None,
              margin_mm: float | None = None) -> None:
    """Write the flat sheet's outlines as SVG (mm) to ``path`` atomically."""
    _write_text(path, svg_text(sheet_outlines(mesh, pattern), stroke_mm=stroke_mm,
                               margin_mm=margin_mm))


# ------------------------------------------------------------------- DXF
def dxf_text(outlines: dict) -> str:
    """A DXF (R2010, mm) of :func:`sheet_outlines`: closed LWPOLYLINEs, one DXF layer per
    outline layer (CUT, PANEL, HINGE_M, HINGE_V, ...)."""
    try:
        import ezdxf
        from ezdxf import units
    except ImportError:
        raise ExportError("DXF export needs the package 'ezdxf': "
                          "pip install 'foldcore[export]'") from None
    doc = ezdxf.new("R2010", setup=False, units=units.MM)
    doc.header["$MEASUREMENT"] = 1   # metric
    msp = doc.modelspace()
    for layer, loops in outlines.items():
        doc.layers.add(layer, color=LAYERS.get(layer, {}).get("dxf_colour", 7))
        for p in loops:
            msp.add_lwpolyline([tuple(map(float, q)) for q in p], close=True,
                               dxfattribs={"layer": layer})
    stream = io.StringIO()
    doc.write(stream)
    return stream.getvalue()


def write_dxf(path, mesh, pattern=None) -> None:
    """Write the flat sheet's outlines as DXF (mm) to ``path`` atomically."""
    _write_text(path, dxf_text(sheet_outlines(mesh, pattern)))


def _write_text(path, text: str) -> None:
    _check_folder(os.fspath(path))
    with atomic_write(path) as fh:
        fh.write(text)


# ------------------------------------------------------------------- results
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
                f"> {limit:.3g} mm); pass the --hinge-width used with simulate")


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
    from .io.fold import (_parse_json, edges_poisson, faces_cells, fold_file_from_dict,
                          read_bytes)
    from .measure import element_rotations

    source = os.fspath(path)
    d = _parse_json(read_bytes(source), source)
    fold = fold_file_from_dict(d, source)
    positions, faces = _folded_frame(d, source)
    if fold.thickness is None:
        raise PatternError(f"{source}: no foldcore:thickness; not a foldcore result file")
    _check_reach(positions, fold.pattern, fold.thickness, source)
    if hinge_width is not None:
        limits.check_width(hinge_width, fold.pattern.vertices, "--hinge-width", source)
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
    there, and such values overflow the rotation fits (a coordinate of 1e308
    made ``np.linalg.svd`` run without end, issue 18)."""
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
    from .io.fold import UNIT_MM

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
    from .io.fold import ARRAY, _number, _short

    if not isinstance(rows, ARRAY) or not rows:
        raise PatternError(f"{source}: folded frame: vertices_coords must be a non-empty "
                           f"list of [x, y, z], got {_short(rows)}")
    out = []
    for i, row in enumerate(rows):
        xyz = [_number(c) for c in row] if isinstance(row, ARRAY) else []
        if len(xyz) != 3 or None in xyz:
            raise PatternError(f"{source}: folded frame: vertices_coords[{i}] must be 3 "
                               f"finite numbers [x, y, z], got {_short(row)}")
        out.append(xyz)
    return np.array(out, dtype=float)


def _frame_faces(rows, n: int, source: str) -> list:
    """A folded frame's ``faces_vertices`` as tuples of vertex ids in 0..n-1."""
    from .io.fold import ARRAY, _index, _short

    if not isinstance(rows, ARRAY):
        raise PatternError(f"{source}: folded frame: faces_vertices must be a list of "
                           f"vertex-id lists, got {_short(rows)}")
    faces = []
    for i, row in enumerate(rows):
        ids = [_index(v, n) for v in row] if isinstance(row, ARRAY) else [None]
        if None in ids:
            raise PatternError(f"{source}: folded frame: faces_vertices[{i}] must be vertex "
                               f"ids in 0..{n - 1}, got {_short(row)}")
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
                       f"{thickness:g} mm, {tried}); pass the --subdivisions and "
                       "--hinge-width used with simulate")


# ------------------------------------------------------------------- all at once
def export(result: ResultFile, svg=None, dxf=None, stl=None, stroke_mm: float | None = None,
           margin_mm: float | None = None) -> list:
    """Write the fabrication files asked for; returns the paths written.

    Every file's contents are made first, then each is written atomically,
    so an error (bad geometry, missing ezdxf) leaves no file behind.

    Parameters
    ----------
    result : ResultFile
    svg, dxf : path, optional
        Flat sheet outlines (needs :meth:`ResultFile.check_footprint` to pass).
    stl : path, optional
        The folded solid at ``result.positions``.
    stroke_mm, margin_mm : float, optional
        SVG stroke width and margin, mm (default: shares of the sheet's extent).
    """
    if not (svg or dxf or stl):
        raise ExportError("nothing to export: give --svg, --dxf and/or --stl")
    for path in (svg, dxf, stl):
        if path:
            _check_folder(os.fspath(path))  # every destination before any write
    contents = []
    if svg or dxf:
        result.check_footprint()
        outlines = sheet_outlines(result.mesh, result.pattern)
        if svg:
            contents.append((svg, svg_text(outlines, f"foldcore flat sheet of {result.source}",
                                           stroke_mm, margin_mm)))
        if dxf:
            contents.append((dxf, dxf_text(outlines)))
    if stl:
        contents.append((stl, stl_bytes(result.mesh, result.positions)))
    for path, data in contents:
        if isinstance(data, bytes):
            write_bytes(path, data)
        else:
            _write_text(path, data)
    return [p for p, _ in contents]
