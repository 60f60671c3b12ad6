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
``SVG_STROKE_MAX_MM``, a laser cutter's hairline) and 2 % of it.

Panel and hinge outlines share their common sides (the score lines); which
layer is cut, scored or only drawn is the laser operator's choice. Every
outline is one closed polyline, collinear points removed. SVG is written by
hand (exact mm units through ``viewBox``, deterministic output); DXF through
ezdxf (the ``export`` extra), ``$INSUNITS`` = mm.

Folded solid (3D printing, CAD): binary STL (mm) of the outer surface,
:func:`foldcore.surface.write_stl`.

A thin sheet's result (:class:`foldcore.result_file.SheetResultFile`) has no
strips or panels: its flat sheet is its lines (:func:`crease_lines`), each
edge one open segment — ``CUT`` the boundary edges (both sides of a cut
drawn once), ``HINGE_M`` / ``HINGE_V`` / ``HINGE_F`` / ``HINGE`` the creases
— and its STL the folded triangles, a surface without thickness. Result files
(``foldcore simulate -o``) are read back by :func:`foldcore.result_file.read_result`. Every file is
written atomically (:mod:`foldcore.files`): it appears complete or not at all.
Design notes:
``docs/architecture.md#fabrication-files``.
"""
from __future__ import annotations

import io

import numpy as np

from . import files, limits
from .files import ExportError
from .result_file import ResultFile
from .surface import stl_bytes

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


# ------------------------------------------------------------------- writing
def _write_text(path, text: str) -> None:
    """Write ``text`` to ``path`` atomically, after checking its folder (ExportError)."""
    files.check_folder(path, ExportError)
    files.write_text(path, text)


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
             margin_mm: float | None = None, closed: bool = True) -> str:
    """An SVG document (mm) of :func:`sheet_outlines`: one ``<g>`` per layer, ``<polygon>``s
    (``<polyline>``s of :func:`crease_lines` with ``closed`` False).

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
            lines.append(f'<{"polygon" if closed else "polyline"} points="{points}"/>')
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
def dxf_text(outlines: dict, closed: bool = True) -> str:
    """A DXF (R2010, mm) of :func:`sheet_outlines`: closed LWPOLYLINEs (open ones of
    :func:`crease_lines` with ``closed`` False), one DXF layer per outline layer (CUT,
    PANEL, HINGE_M, HINGE_V, ...)."""
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
            msp.add_lwpolyline([tuple(map(float, q)) for q in p], close=closed,
                               dxfattribs={"layer": layer})
    stream = io.StringIO()
    doc.write(stream)
    return stream.getvalue()


def write_dxf(path, mesh, pattern=None) -> None:
    """Write the flat sheet's outlines as DXF (mm) to ``path`` atomically."""
    _write_text(path, dxf_text(sheet_outlines(mesh, pattern)))


# ------------------------------------------------------------------- thin sheets
def crease_lines(pattern) -> dict:
    """The flat thin sheet's lines, mm, per layer (module docstring): each a (2, 2)
    segment; boundary edges on each other (the two sides of a cut) drawn once."""
    xy = np.asarray(pattern.vertices, dtype=float)
    out = {}
    kinds = np.asarray(pattern.assignments)
    for layer, pick in (("CUT", kinds == "B"), ("HINGE_M", kinds == "M"),
                        ("HINGE_V", kinds == "V"), ("HINGE_F", kinds == "F"),
                        ("HINGE", kinds == "U")):
        segments = xy[pattern.edges[pick]]
        if len(segments):
            out[layer] = list(_once(segments))
    return out


def _once(segments: np.ndarray) -> np.ndarray:
    """``segments`` (S, 2, 2) with each drawn once, whichever way it runs."""
    forward = np.where((segments[:, 0, 0] < segments[:, 1, 0])[:, None, None]
                       | ((segments[:, 0, 0] == segments[:, 1, 0])
                          & (segments[:, 0, 1] <= segments[:, 1, 1]))[:, None, None],
                       segments, segments[:, ::-1])
    _, first = np.unique(forward.reshape(-1, 4), axis=0, return_index=True)
    return segments[np.sort(first)]


def export_sheet(result, svg=None, dxf=None, stl=None, stroke_mm: float | None = None,
                 margin_mm: float | None = None) -> list:
    """:func:`export` of a thin sheet's result (a
    :class:`foldcore.result_file.SheetResultFile`): its lines as SVG/DXF, its folded
    triangles as STL; all written or none."""
    from .surface import triangles_stl_bytes

    _check_destinations((svg, dxf, stl))
    limits.check_svg_sizes(stroke_mm, margin_mm, result.pattern.vertices, result.source)
    lines = crease_lines(result.pattern)
    contents = []
    if svg:
        contents.append((svg, svg_text(lines, f"foldcore thin sheet of {result.source}",
                                       stroke_mm, margin_mm, closed=False)))
    if dxf:
        contents.append((dxf, dxf_text(lines, closed=False)))
    if stl:
        positions = result.frames[-1].positions
        contents.append((stl, triangles_stl_bytes(positions[result.triangles],
                                                  "foldcore thin sheet (no thickness), mm")))
    return _write_all(contents)


# ------------------------------------------------------------------- all at once
def export(result: ResultFile, svg=None, dxf=None, stl=None, stroke_mm: float | None = None,
           margin_mm: float | None = None) -> list:
    """Write the fabrication files asked for; returns the paths written.

    Every file's contents are made first, then all are written or none
    (:func:`foldcore.files.all_or_nothing`), so an error (bad geometry,
    missing ezdxf, a full disk) leaves no file behind.

    Parameters
    ----------
    result : ResultFile
    svg, dxf : path, optional
        Flat sheet outlines (needs :meth:`ResultFile.check_footprint` to pass).
    stl : path, optional
        The folded solid at ``result.positions``.
    stroke_mm, margin_mm : float, optional
        SVG stroke width and margin, mm (default: shares of the sheet's extent);
        1e-6 … 1 and 0 … 10 × the sheet's extent (:data:`foldcore.limits.STROKE_RATIO`,
        :data:`foldcore.limits.MARGIN_RATIO`).
    """
    _check_destinations((svg, dxf, stl))
    limits.check_svg_sizes(stroke_mm, margin_mm, result.pattern.vertices, result.source)
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
        contents.append((stl, stl_bytes(result.mesh, result.positions, source=result.source)))
    return _write_all(contents)


def _check_destinations(paths) -> None:
    """ExportError when no path is given, or a path's folder cannot be written."""
    if not any(paths):
        raise ExportError("nothing to export: give svg, dxf and/or stl paths")
    for path in paths:
        if path:
            files.check_folder(path, ExportError)  # every destination before any write


def _write_all(contents: list) -> list:
    """Write each (path, text or bytes) of ``contents``, all or none; the paths written."""
    with files.all_or_nothing(dict(enumerate(p for p, _ in contents))) as tmp:
        for i, (_, data) in enumerate(contents):
            with open(tmp[i], "xb") as fh:
                fh.write(data if isinstance(data, bytes) else data.encode("utf-8"))
    return [p for p, _ in contents]
