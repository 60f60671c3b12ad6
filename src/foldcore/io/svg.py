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

import io
import os
import re

import numpy as np

from ..errors import PatternError
from ..pattern import CreasePattern
from .conventions import Reading, note
from .svg_screen import screened_svg

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
#: Largest coordinate accepted after transforms, px (264 km: beyond every length
#: foldcore folds, far inside the arithmetic's range).
MAX_COORD_PX = 1e9
#: Most straight segments in one pattern ...
MAX_SEGMENTS = 200_000
#: ... and most pairs of them that meet or cross (each a vertex to node; Origami
#: Simulator's library has at most 16 782, and noding 10⁵ takes about 2 s).
MAX_MEETINGS = 100_000
#: Most pairs of noded points closer than the merge distance (a few per T-join or
#: crossing in a drawing; many lines through one point crowd there by the million).
MAX_CLOSE_PAIRS = 1_000_000
#: An SVG number, and one followed by a unit (a length).
_NUMBER = re.compile(r"([+-]?(?:\d+\.?\d*|\.\d+)(?:[eE][+-]?\d+)?)")
_LENGTH = re.compile(_NUMBER.pattern + r"\s*(?:px|mm|cm|in|pt|pc|em|ex|%)?")
_SEPARATORS = re.compile(r"[\s,]+")
#: Attributes that place a shape's points.
_GEOMETRY = ("x", "y", "x1", "y1", "x2", "y2", "width", "height", "cx", "cy", "r", "rx", "ry")
#: What svgelements raises on values it cannot compute (units it cannot resolve,
#: degenerate transforms, numbers out of range): refused naming the element.
_SVG_FAILURES = (ArithmeticError, ValueError, TypeError, IndexError, AttributeError,
                 KeyError)


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
    _check_meetings(segments, source)
    segments[:, :, 1] *= -1.0  # SVG y points down
    extent = float(np.ptp(segments.reshape(-1, 2), axis=0).max())
    tol = min(SNAP_PX, SNAP_MAX * extent)
    vertices, edges, pieces = _planarise(segments, tol, source)
    assignments, fold_angles = _piece_types(pieces, edges, vertices, segments, kinds,
                                            angles, owners, tol, source)
    factor = reading.factor(extent * MM_PER_PX) * MM_PER_PX
    return CreasePattern(vertices * factor, edges, assignments, fold_angles=fold_angles,
                         source=source)


def _strokes(source: str):
    """(S, 2, 2) straight segments (px), their assignment, target (degrees or NaN) and
    the element each came from (for messages)."""
    segments, kinds, angles, owners, ignored = [], [], [], [], {}
    for number, element in enumerate(_shapes(source)):
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
        angle = sign * 180.0 * _opacity(element, name, source) if sign \
            else (0.0 if kind == "F" else np.nan)
        try:
            found = _element_segments(element, name, source)
        except PatternError:
            raise
        except _SVG_FAILURES as exc:
            raise PatternError(f"{source}: {name} cannot be computed "
                               f"({_failure(exc)})") from None
        segments += found
        kinds += [kind] * len(found)
        angles += [angle] * len(found)
        owners += [name] * len(found)
        if len(segments) > MAX_SEGMENTS:
            raise PatternError(f"{source}: more than {MAX_SEGMENTS} straight segments "
                               f"(at {name})")
    if ignored:
        counts = ", ".join(f"{n} {c}" for c, n in sorted(ignored.items()))
        note(source, f"{sum(ignored.values())} shapes whose stroke is none of Origami "
                     f"Simulator's colours were ignored ({counts})")
    return (np.array(segments, dtype=np.float64).reshape(-1, 2, 2), np.array(kinds),
            np.array(angles, dtype=np.float64), owners)


def _shapes(source: str) -> list:
    """The drawing's shapes (svgelements, transforms and styles applied) from the
    screened file (:func:`~.svg_screen.screened_svg`)."""
    try:
        from svgelements import SVG, Shape
    except ImportError as exc:  # pragma: no cover - a dependency
        raise PatternError(f"{source}: reading SVG needs svgelements "
                           "(pip install svgelements)") from exc
    data = screened_svg(source)
    try:
        svg = SVG.parse(io.BytesIO(data), reify=False)  # transforms checked per shape
        return [e for e in svg.elements() if isinstance(e, Shape)]
    except (*_SVG_FAILURES, RecursionError, SyntaxError) as exc:  # ParseError: SyntaxError
        raise PatternError(f"{source}: not a readable SVG ({_failure(exc)})") from None


def _element_segments(element, name: str, source: str) -> list:
    """[((x0, y0), (x1, y1))] the straight segments (px) of one stroked shape, its
    transform applied; refused naming the element where a geometric attribute is
    not a finite number (svgelements would read it as 0) or the transform is
    singular or not finite (a ``scale(0)`` would make its creases vanish)."""
    from svgelements import Close, Line, Move, Path

    _check_geometry(element, name, source)
    matrix = element.transform
    entries = [matrix.a, matrix.b, matrix.c, matrix.d, matrix.e, matrix.f]
    if not (all(np.isfinite(entries)) and matrix.determinant != 0.0):
        raise PatternError(f"{source}: {name} has a transform that is singular or not "
                           f"finite ({', '.join(f'{v:g}' for v in entries)}); its "
                           "creases would vanish or leave the sheet")
    path = Path(element)
    path.reify()
    out = []
    for seg in path:
        if isinstance(seg, Move) or seg.start is None or seg.end is None:
            continue
        a = _point(seg.start, name, source)
        b = _point(seg.end, name, source)
        if not isinstance(seg, (Line, Close)):
            _check_straight(seg, np.array(a), np.array(b), name, source)
        if a != b:
            out.append((a, b))
    return out


def _check_geometry(element, name: str, source: str) -> None:
    """Each geometric attribute as written (``x1``, ``width``, ``points`` …) is finite
    numbers (with a unit where one may stand): svgelements reads what is not as 0,
    which would move the crease."""
    for key in _GEOMETRY:
        raw = element.values.get(key)
        if raw is not None and not _finite_length(str(raw)):
            raise PatternError(f"{source}: {name} has {key}={str(raw)[:40]!r}, not a "
                               "finite number")
    points = element.values.get("points")
    if points is not None:
        tokens = _SEPARATORS.split(str(points).strip())
        bad = [t for t in tokens if t and not _finite_length(t, unit=False)]
        if bad:
            raise PatternError(f"{source}: {name} has points with {bad[0][:40]!r}, not a "
                               "finite number")


def _finite_length(text: str, unit: bool = True) -> bool:
    """Whether ``text`` is one finite SVG number (followed by a unit where ``unit``)."""
    match = (_LENGTH if unit else _NUMBER).fullmatch(text.strip())
    return bool(match) and np.isfinite(float(match.group(1)))


def _point(p, name: str, source: str) -> tuple:
    """(x, y) px of a segment's end, refused naming the element unless finite and
    within :data:`MAX_COORD_PX`."""
    x, y = float(p.x), float(p.y)
    if not (abs(x) <= MAX_COORD_PX and abs(y) <= MAX_COORD_PX):  # False for NaN too
        raise PatternError(f"{source}: {name} has a point at ({x:g}, {y:g}) px after its "
                           f"transforms, outside the accepted ±{MAX_COORD_PX:g} px")
    return x, y


def _failure(exc: BaseException) -> str:
    """An exception as a short one-line text."""
    return f"{type(exc).__name__}: {' '.join(str(exc).split())[:120]}"


def _check_meetings(segments: np.ndarray, source: str) -> None:
    """Refuse a drawing whose segments meet or cross more than :data:`MAX_MEETINGS`
    times (each meeting a vertex the noding creates; counted in chunks so that the
    count stops once past the bound)."""
    import shapely

    lines = shapely.linestrings(segments)
    tree = shapely.STRtree(lines)
    chunk = max(64, 2_000_000 // max(len(lines), 1))
    total = 0
    for start in range(0, len(lines), chunk):
        first, second = tree.query(lines[start:start + chunk], predicate="intersects")
        total += int(np.count_nonzero(first + start < second))
        if total > MAX_MEETINGS:
            raise PatternError(f"{source}: its {len(lines)} segments meet or cross more "
                               f"than {MAX_MEETINGS} times; foldcore reads crease "
                               "patterns, not hatchings")


def _element_name(element, number: int) -> str:
    tag = type(element).__name__.lower().replace("simpleline", "line")
    ident = element.values.get("id")
    return f"{tag} {number}" + (f" (id {ident!r})" if ident else "")


def _stroke_type(element):
    stroke = element.stroke
    if stroke is None or stroke.value is None:
        return None, 0.0
    return STROKES.get((stroke.red, stroke.green, stroke.blue), (None, 0.0))


def _opacity(element, name: str, source: str) -> float:
    """``opacity`` × ``stroke-opacity`` of the element (each 1 when absent), in [0, 1]:
    as written (svgelements keeps stroke-opacity as the colour's 8-bit alpha, which
    would turn 0.25 into 45.18°), else the colour's alpha. Values outside [0, 1] are
    clamped (CSS); a value that is not a number is ignored (CSS), one that is not
    finite refused naming the element (it would drop the crease's target)."""
    def number(key, default):
        try:
            value = float(element.values.get(key, default))
        except (TypeError, ValueError):
            return default
        if not np.isfinite(value):
            raise PatternError(f"{source}: {name} has {key}={value}, not a finite number "
                               "(the opacity is the crease's target angle / 180°)")
        return value
    stroke = number("stroke-opacity", element.stroke.opacity)
    return float(np.clip(number("opacity", 1.0) * stroke, 0.0, 1.0))


def _check_straight(seg, a: np.ndarray, b: np.ndarray, name: str, source: str) -> None:
    """A Bézier or arc segment from ``a`` to ``b`` (px, its checked ends) is read as
    its chord only if it is one (its points at a few parameters lie on the chord)."""
    chord = b - a
    length = float(np.hypot(*chord))
    for t in (0.25, 0.5, 0.75):
        d = np.array(_point(seg.point(t), name, source)) - a
        off = abs(float(chord[0] * d[1] - chord[1] * d[0])) / max(length, 1e-300)
        if off > STRAIGHT * length:
            raise PatternError(f"{source}: {name} has a curved segment "
                               f"({type(seg).__name__} from ({a[0]:g}, {a[1]:g}) to "
                               f"({b[0]:g}, {b[1]:g})); foldcore's panels are planar: "
                               "draw creases as straight lines")


def _planarise(segments: np.ndarray, tol: float, source: str = "<segments>"):
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
    vertices, ids = _merge_close(pieces.reshape(-1, 2), tol, source)
    edges = np.sort(ids.reshape(-1, 2), axis=1)
    keep = edges[:, 0] != edges[:, 1]  # a piece shorter than tol: its ends merged
    edges, first = np.unique(edges[keep], axis=0, return_index=True)
    used, edges = np.unique(edges, return_inverse=True)
    return vertices[used], edges.reshape(-1, 2), pieces[keep][first]


def _merge_close(points: np.ndarray, tol: float, source: str):
    """(V, 2) points with every cluster closer than ``tol`` (transitively) replaced by
    its mean, and each input point's id (several crossings rounded apart at one
    vertex, a T-join's ends); refused where more than :data:`MAX_CLOSE_PAIRS` pairs
    are that close (counted before they are listed)."""
    import scipy.sparse as sp
    from scipy.sparse.csgraph import connected_components
    from scipy.spatial import cKDTree

    unique, ids = np.unique(points, axis=0, return_inverse=True)
    tree = cKDTree(unique)
    close = (int(tree.count_neighbors(tree, tol)) - len(unique)) // 2
    if close > MAX_CLOSE_PAIRS:
        raise PatternError(f"{source}: {close} pairs of its crossings lie within the "
                           f"merge distance {tol:g} px of each other (more than "
                           f"{MAX_CLOSE_PAIRS}): too many lines through one place")
    pairs = tree.query_pairs(tol, output_type="ndarray")
    graph = sp.coo_matrix((np.ones(len(pairs)), (pairs[:, 0], pairs[:, 1])),
                          shape=(len(unique), len(unique)))
    _, cluster = connected_components(graph, directed=False)
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
