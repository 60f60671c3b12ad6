"""Read SVG crease patterns in Origami Simulator's colour convention.

Origami Simulator (Ghassaei et al. 2018, ``js/pattern.js``) reads a crease
pattern from the strokes of an SVG's lines, polylines, polygons, rects and
paths: the stroke colour is the crease type and the opacity (``opacity`` ×
``stroke-opacity``) the target angle as a share of 180°.

======================  ==========  ===================================
stroke                  type        foldcore
======================  ==========  ===================================
red ``#ff0000``         mountain    ``M``, target −opacity × 180°
blue ``#0000ff``        valley      ``V``, target +opacity × 180°
black ``#000000``       boundary    ``B``
yellow ``#ffff00``      facet       ``F`` (held flat, 0°)
magenta ``#ff00ff``     undriven    ``U`` (passive hinge)
green ``#00ff00``       cut         refused: foldcore does not cut sheets
======================  ==========  ===================================

Colours are matched as Origami Simulator matches them (``#f00``, ``red``,
``rgb(255,0,0)`` alike, after CSS and presentation attributes: svgelements
computes styles, transforms and the viewBox). Strokes of other colours, and
shapes without a stroke, are ignored as Origami Simulator ignores them, said
once with a count. Curved segments are refused (panels are planar): an SVG
path's Bézier or arc segment whose control points are off its chord by more
than 1e-4 of its chord names its element.

Planarisation (shapely): endpoints within ``SNAP_PX`` = 3 px (Origami
Simulator's vertex tolerance; at most 1 % of the sheet) of another segment are
moved onto it (T-joins drawn a little short or long), the segments are noded
— every crossing and overlap becomes a shared vertex — and vertices within
that distance are merged (an overlapped piece is one edge). Each piece takes the type of the segments it
lies on; two different types on one piece are refused, naming both elements.

Lengths: SVG user units are CSS pixels, 1 px = 25.4 / 96 mm; ``Reading.scale``
or ``Reading.size`` rescale. y is flipped (SVG's y points down), so the
pattern seen from +z is the drawing as seen on screen, its top side up.
"""
from __future__ import annotations

import os

import numpy as np

from ..errors import PatternError
from ..pattern import CreasePattern
from .conventions import Reading, note

MM_PER_PX = 25.4 / 96.0  # CSS pixel
#: Merge distance, px: Origami Simulator's ``vertTol`` (its published patterns rely
#: on it: hypar.svg has a T-join drawn 0.83 px short on an 864 px sheet) ...
SNAP_PX = 3.0
#: ... at most this share of the sheet's larger extent (a sheet drawn a few px wide).
SNAP_MAX = 1e-2
#: A Bézier or arc segment is straight if its points are off its chord by at most this
#: share of the chord (Illustrator exports round coordinates to 1e-3 px).
STRAIGHT = 1e-4
#: A piece lies along a segment if the sine of the angle between them is at most this
#: (a piece near a crossing is near both segments but along one).
PARALLEL = 0.1
#: Stroke (r, g, b) → (assignment, sign of the target: -1 mountain, +1 valley, 0 none).
STROKES = {(0, 0, 0): ("B", 0.0), (255, 0, 0): ("M", -1.0), (0, 0, 255): ("V", 1.0),
           (255, 255, 0): ("F", 0.0), (255, 0, 255): ("U", 0.0), (0, 255, 0): ("C", 0.0)}


def read_svg(path, reading: Reading | None = None) -> CreasePattern:
    """Read an SVG crease pattern (module docstring); lengths mm, angles degrees.

    Raises
    ------
    PatternError
        Not an SVG, no creases, a cut, a curved segment, conflicting types on one
        segment, or a malformed pattern (named as :class:`CreasePattern` names it).
    """
    source = os.fspath(path)
    reading = Reading() if reading is None else reading
    segments, kinds, angles, owners = _strokes(source)
    if not len(segments):
        raise PatternError(f"{source}: no stroked lines in Origami Simulator's colours "
                           "(red mountain, blue valley, black boundary, yellow facet, "
                           "magenta undriven)")
    segments[:, :, 1] *= -1.0  # SVG y points down
    extent = float(np.ptp(segments.reshape(-1, 2), axis=0).max())
    tol = min(SNAP_PX, SNAP_MAX * extent)
    vertices, edges, pieces = _planarise(segments, tol)
    assignments, fold_angles = _piece_types(pieces, edges, vertices, segments, kinds,
                                            angles, owners, tol, source)
    factor = reading.factor(extent * MM_PER_PX) * MM_PER_PX
    return CreasePattern(vertices * factor, edges, assignments, fold_angles=fold_angles,
                         source=source)


def _strokes(source: str):
    """(S, 2, 2) straight segments (px), their assignment, target (degrees or NaN) and
    the element each came from (for messages)."""
    try:
        from svgelements import SVG, Close, Line, Move, Path, Shape
    except ImportError as exc:  # pragma: no cover - a dependency
        raise PatternError(f"{source}: reading SVG needs svgelements "
                           "(pip install svgelements)") from exc
    try:
        svg = SVG.parse(source, reify=True)
    except Exception as exc:  # not XML, not SVG: one line naming the file
        raise PatternError(f"{source}: not a readable SVG ({type(exc).__name__}: "
                           f"{' '.join(str(exc).split())[:120]})") from None
    segments, kinds, angles, owners, ignored = [], [], [], [], {}
    for number, element in enumerate(e for e in svg.elements() if isinstance(e, Shape)):
        name = _element_name(element, number)
        kind, sign = _stroke_type(element)
        if kind is None:
            colour = "none" if element.stroke is None or element.stroke.value is None \
                else element.stroke.hex
            ignored[colour] = ignored.get(colour, 0) + 1
            continue
        if kind == "C":
            raise PatternError(f"{source}: {name} is a cut (green stroke); foldcore does "
                               "not cut sheets: draw the cut as boundary (black) around "
                               "separate pieces, or remove it")
        angle = sign * 180.0 * _opacity(element) if sign else (0.0 if kind == "F" else np.nan)
        for seg in Path(element):
            if isinstance(seg, Move) or seg.start is None or seg.end is None:
                continue
            if not isinstance(seg, (Line, Close)):
                _check_straight(seg, name, source)
            a, b = (float(seg.start.x), float(seg.start.y)), (float(seg.end.x),
                                                              float(seg.end.y))
            if a != b:
                segments.append((a, b))
                kinds.append(kind)
                angles.append(angle)
                owners.append(name)
    if ignored:
        counts = ", ".join(f"{n} {c}" for c, n in sorted(ignored.items()))
        note(source, f"{sum(ignored.values())} shapes whose stroke is none of Origami "
                     f"Simulator's colours were ignored ({counts})")
    return (np.array(segments, dtype=np.float64).reshape(-1, 2, 2), np.array(kinds),
            np.array(angles, dtype=np.float64), owners)


def _element_name(element, number: int) -> str:
    tag = type(element).__name__.lower().replace("simpleline", "line")
    ident = element.values.get("id")
    return f"{tag} {number}" + (f" (id {ident!r})" if ident else "")


def _stroke_type(element):
    stroke = element.stroke
    if stroke is None or stroke.value is None:
        return None, 0.0
    return STROKES.get((stroke.red, stroke.green, stroke.blue), (None, 0.0))


def _opacity(element) -> float:
    """``opacity`` × ``stroke-opacity`` of the element (each 1 when absent), in [0, 1]:
    as written (svgelements keeps stroke-opacity as the colour's 8-bit alpha, which
    would turn 0.25 into 45.18°), else the colour's alpha."""
    def number(key, default):
        try:
            return float(element.values.get(key, default))
        except (TypeError, ValueError):
            return default
    stroke = number("stroke-opacity", element.stroke.opacity)
    return float(np.clip(number("opacity", 1.0) * stroke, 0.0, 1.0))


def _check_straight(seg, name: str, source: str) -> None:
    """A Bézier or arc segment is read as its chord only if it is one (its points at
    a few parameters lie on the chord)."""
    a = np.array([seg.start.x, seg.start.y], dtype=float)
    b = np.array([seg.end.x, seg.end.y], dtype=float)
    chord = b - a
    length = float(np.hypot(*chord))
    for t in (0.25, 0.5, 0.75):
        p = seg.point(t)
        off = abs(float(np.cross(chord, np.array([p.x, p.y], dtype=float) - a))) / max(length,
                                                                                      1e-300)
        if off > STRAIGHT * length:
            raise PatternError(f"{source}: {name} has a curved segment "
                               f"({type(seg).__name__} from ({a[0]:g}, {a[1]:g}) to "
                               f"({b[0]:g}, {b[1]:g})); foldcore's panels are planar: "
                               "draw creases as straight lines")


def _planarise(segments: np.ndarray, tol: float):
    """(V, 2) vertices, (E, 2) edges and the (E, 2, 2) noded pieces of the segments:
    endpoints snapped onto nearby segments, near coordinates merged, crossings and
    overlaps noded (shapely's unary union)."""
    import shapely

    segments = _snap_endpoints(segments, tol)
    lines = shapely.linestrings(segments)
    noded = shapely.unary_union(shapely.set_precision(lines, tol))
    pieces = []
    for part in shapely.get_parts(noded):
        xy = shapely.get_coordinates(part)
        pieces.extend(zip(xy[:-1], xy[1:]))
    pieces = np.array(pieces, dtype=np.float64).reshape(-1, 2, 2)
    vertices, ids = _merge_close(pieces.reshape(-1, 2), tol)
    edges = np.sort(ids.reshape(-1, 2), axis=1)
    keep = edges[:, 0] != edges[:, 1]  # a piece shorter than tol: its ends merged
    edges, first = np.unique(edges[keep], axis=0, return_index=True)
    used, edges = np.unique(edges, return_inverse=True)
    return vertices[used], edges.reshape(-1, 2), pieces[keep][first]


def _merge_close(points: np.ndarray, tol: float):
    """(V, 2) points with every cluster closer than ``tol`` (transitively) replaced by
    its mean, and each input point's id (several crossings rounded apart at one
    vertex, a T-join's ends)."""
    from scipy.cluster.hierarchy import DisjointSet
    from scipy.spatial import cKDTree

    unique, ids = np.unique(points, axis=0, return_inverse=True)
    clusters = DisjointSet(range(len(unique)))
    for i, j in cKDTree(unique).query_pairs(tol):
        clusters.merge(i, j)
    roots = np.array([clusters[i] for i in range(len(unique))])
    _, cluster = np.unique(roots, return_inverse=True)
    merged = np.zeros((cluster.max() + 1 if len(cluster) else 0, 2))
    np.add.at(merged, cluster, unique)
    merged /= np.bincount(cluster)[:, None]
    return merged, cluster[ids.ravel()]


def _snap_endpoints(segments: np.ndarray, tol: float) -> np.ndarray:
    """Move each endpoint within ``tol`` of another segment onto that segment (a T-join
    drawn a little short or long), keeping endpoints that already meet one."""
    import shapely

    out = segments.copy()
    lines = shapely.linestrings(segments)
    tree = shapely.STRtree(lines)
    ends = shapely.points(segments.reshape(-1, 2))
    point_ids, line_ids = tree.query(ends, predicate="dwithin", distance=tol)
    own = point_ids // 2 == line_ids
    for p, s in zip(point_ids[~own], line_ids[~own]):
        here = out[p // 2, p % 2]
        a, b = segments[s]
        d = b - a
        t = float(np.clip(np.dot(here - a, d) / float(np.dot(d, d)), 0.0, 1.0))
        target = a + t * d
        if np.hypot(*(target - here)) <= tol:
            out[p // 2, p % 2] = target
    return out


def _piece_types(pieces, edges, vertices, segments, kinds, angles, owners, tol, source):
    """Each piece's assignment and target: those of the segments it lies along — its
    midpoint within ``tol`` and both ends within 2 ``tol`` of the segment, and its
    direction within ``PARALLEL`` (sine) of the segment's; two different ones are
    refused. A piece near a crossing is also near the crossing segment but not along
    it; a short piece whose merged ends turned it by more is typed by the segment
    closest to its direction, one whose ends merged farther by the nearest segment."""
    import shapely

    lines = shapely.linestrings(segments)
    tree = shapely.STRtree(lines)
    ends = vertices[edges]  # (E, 2, 2), after merging
    piece_ids, seg_ids = tree.query(shapely.points(ends.mean(axis=1)), predicate="dwithin",
                                    distance=tol)
    along = np.maximum(shapely.distance(shapely.points(ends[piece_ids, 0]), lines[seg_ids]),
                       shapely.distance(shapely.points(ends[piece_ids, 1]), lines[seg_ids]))
    piece_ids, seg_ids = piece_ids[along <= 2.0 * tol], seg_ids[along <= 2.0 * tol]
    sine = np.abs(_cross(_unit(ends[piece_ids, 1] - ends[piece_ids, 0]),
                         _unit(segments[seg_ids, 1] - segments[seg_ids, 0])))
    assignment = np.full(len(pieces), "", dtype="<U1")
    target = np.full(len(pieces), np.nan)
    owner = [None] * len(pieces)
    for p in np.unique(piece_ids):
        mine = np.flatnonzero(piece_ids == p)
        parallel = mine[sine[mine] <= PARALLEL]
        chosen = parallel if len(parallel) else mine[[int(np.argmin(sine[mine]))]]
        for s in seg_ids[chosen]:
            same = assignment[p] == kinds[s] and (np.isnan(target[p]) and np.isnan(angles[s])
                                                  or target[p] == angles[s])
            if owner[p] is None:
                assignment[p], target[p], owner[p] = kinds[s], angles[s], owners[s]
            elif not same:
                raise PatternError(f"{source}: {owners[s]} and {owner[p]} overlap with "
                                   f"different crease types or angles ({kinds[s]} and "
                                   f"{assignment[p]}) near ({vertices[edges[p, 0]][0]:g}, "
                                   f"{-vertices[edges[p, 0]][1]:g}) px")
    for p in [q for q, o in enumerate(owner) if o is None]:  # its ends merged far off
        s = int(tree.query_nearest(shapely.points(ends[p].mean(axis=0)))[0])
        assignment[p], target[p] = kinds[s], angles[s]
    return assignment.tolist(), [None if np.isnan(t) else float(t) for t in target]


def _unit(d: np.ndarray) -> np.ndarray:
    return d / np.maximum(np.hypot(d[:, 0], d[:, 1]), 1e-300)[:, None]


def _cross(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    return a[:, 0] * b[:, 1] - a[:, 1] * b[:, 0]
