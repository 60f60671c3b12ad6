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
green ``#00ff00``       cut         ``C``: the sheet is split along it
======================  ==========  ===================================

Colours are matched as Origami Simulator matches them (``#f00``, ``red``,
``rgb(255,0,0)`` alike, after CSS and presentation attributes: svgelements
computes styles, transforms and the viewBox). Strokes of other colours, and
shapes without a stroke, are ignored as Origami Simulator ignores them, said
once with a count. A path's Bézier or arc segment off its chord by more than
1e-4 of it is a curved crease: read as a polyline within ``CURVE_SAG_PX`` of
the curve (its pieces at least ``SNAP_PX`` long, at most 64 per segment), said
once with a count; a thin sheet folds it with bending facets, as Origami
Simulator folds its curved patterns.

Planarisation (:mod:`.lines`, shapely) at ``SNAP_PX`` = 3 px (Origami
Simulator's vertex tolerance; at most 1 % of the sheet): endpoints that near
another segment are moved onto it (T-joins drawn a little short or long), the
segments are noded — every crossing and overlap becomes a shared vertex —
and vertices that near are merged (an overlapped piece is one edge). Each
piece takes the type of the segments it lies on; two different types on one
piece are refused, naming both elements. A line whose type contradicts its
sides is read as Origami Simulator reads it, said once with a count: a crease
with the sheet on one side only is boundary, a boundary line with the sheet on
both sides a free hinge (``U``).

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
from .conventions import Reading, drive_only, note
from .lines import check_meetings, pattern_from_lines
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
#: A curved segment is read as a polyline within this distance of the curve, px (a
#: third of the merge distance SNAP_PX) ...
CURVE_SAG_PX = 1.0
#: ... halving its parameter range at most this many times (2⁶ = 64 pieces).
CURVE_DEPTH = 6
#: Stroke (r, g, b) → (assignment, sign of the target: -1 mountain, +1 valley, 0 none).
STROKES = {(0, 0, 0): ("B", 0.0), (255, 0, 0): ("M", -1.0), (0, 0, 255): ("V", 1.0),
           (255, 255, 0): ("F", 0.0), (255, 0, 255): ("U", 0.0), (0, 255, 0): ("C", 0.0)}
#: Largest coordinate accepted after transforms, px (264 km: beyond every length
#: foldcore folds, far inside the arithmetic's range).
MAX_COORD_PX = 1e9
#: Most straight segments in one pattern ...
MAX_SEGMENTS = 200_000
#: The order in which Origami Simulator's ``loadSVG`` reads the crease types (its
#: ``findType`` calls), and within one type the element kinds (``findType``'s parse
#: calls); its vertices are numbered as they come, which decides the diagonal of a
#: square face (:func:`foldcore.sheet.build.face_triangles`).
READ_ORDER = ("B", "M", "V", "C", "F", "U")
TAG_ORDER = {"path": 0, "line": 1, "rect": 2, "polygon": 3, "polyline": 4}
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


def read_svg(path, reading: Reading | None = None, with_drawn: bool = False):
    """Read an SVG crease pattern (module docstring); lengths mm, angles degrees; with
    ``with_drawn``, (pattern, its vertices as drawn, (V, 2) mm:
    :func:`.lines.pattern_from_lines`).

    Raises
    ------
    PatternError
        Not an SVG, no creases, conflicting types on one segment, or a
        malformed pattern (named as :class:`foldcore.pattern.CreasePattern` names it).
    """
    source = os.fspath(path)
    reading = Reading() if reading is None else reading
    segments, kinds, angles, owners, numbering = _strokes(source)
    if not len(segments):
        raise PatternError(f"{source}: no stroked lines in Origami Simulator's colours "
                           "(red mountain, blue valley, black boundary, yellow facet, "
                           "magenta undriven)")
    check_meetings(segments, source)
    segments[:, :, 1] *= -1.0  # SVG y points down
    extent = float(np.ptp(segments.reshape(-1, 2), axis=0).max())
    pattern, drawn = pattern_from_lines(segments, kinds, angles, owners, source,
                                        tol=min(SNAP_PX, SNAP_MAX * extent),
                                        factor=reading.factor(extent * MM_PER_PX) * MM_PER_PX,
                                        where=lambda x, y: f"({x:g}, {-y:g}) px",
                                        sides_as_origami_simulator=True, numbering=numbering,
                                        with_drawn=True)
    pattern = drive_only(pattern, reading.drive, source)
    return (pattern, drawn) if with_drawn else pattern


def _strokes(source: str):
    """(S, 2, 2) straight segments (px), their assignment, target (degrees or NaN), the
    element each came from (for messages), and the segments in the order Origami
    Simulator reads them (:data:`READ_ORDER`, then :data:`TAG_ORDER`, then the file's),
    which numbers the vertices."""
    segments, kinds, angles, owners, ignored, curves = [], [], [], [], {}, []
    ranks = []
    for number, element in enumerate(_shapes(source)):
        name = _element_name(element, number)
        kind, sign = _stroke_type(element)
        if kind is None:
            colour = "none" if element.stroke is None or element.stroke.value is None \
                else element.stroke.hex
            ignored[colour] = ignored.get(colour, 0) + 1
            continue
        angle = sign * 180.0 * _opacity(element, name, source) if sign \
            else (0.0 if kind == "F" else np.nan)
        try:
            found = _element_segments(element, name, source, curves)
        except PatternError:
            raise
        except _SVG_FAILURES as exc:
            raise PatternError(f"{source}: {name} cannot be computed "
                               f"({_failure(exc)})") from None
        segments += found
        rank = (READ_ORDER.index(kind), TAG_ORDER.get(_tag(element), len(TAG_ORDER)), number)
        ranks += [rank] * len(found)
        kinds += [kind] * len(found)
        angles += [angle] * len(found)
        owners += [name] * len(found)
        if len(segments) > MAX_SEGMENTS:
            raise PatternError(f"{source}: more than {MAX_SEGMENTS} straight segments "
                               f"(at {name})")
    if curves:
        note(source, f"{len(curves)} curved segments read as {sum(curves)} straight "
                     f"pieces, within {CURVE_SAG_PX:g} px of the curves")
    if ignored:
        counts = ", ".join(f"{n} {c}" for c, n in sorted(ignored.items()))
        note(source, f"{sum(ignored.values())} shapes whose stroke is none of Origami "
                     f"Simulator's colours were ignored ({counts})")
    ranks = np.array(ranks, dtype=np.int64).reshape(-1, 3)
    return (np.array(segments, dtype=np.float64).reshape(-1, 2, 2), np.array(kinds),
            np.array(angles, dtype=np.float64), owners, np.lexsort(ranks.T[::-1]))


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


def _element_segments(element, name: str, source: str, curves: list) -> list:
    """[((x0, y0), (x1, y1))] the straight segments (px) of one stroked shape, its
    transform applied, a curved segment as a polyline (:func:`_polyline`; its piece
    count appended to ``curves``); refused naming the element where a geometric
    attribute is not a finite number (svgelements would read it as 0) or the
    transform is singular or not finite (a ``scale(0)`` would make its creases
    vanish)."""
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
        if isinstance(seg, (Line, Close)) or _straight(seg, np.array(a), np.array(b),
                                                       name, source):
            if a != b:
                out.append((a, b))
            continue
        points = _polyline(seg, name, source)
        out += [(p, q) for p, q in zip(points[:-1], points[1:]) if p != q]
        curves.append(len(points) - 1)
        if len(out) > MAX_SEGMENTS:
            raise PatternError(f"{source}: more than {MAX_SEGMENTS} straight segments "
                               f"(at {name}, its curves read as polylines)")
    return out


def _polyline(seg, name: str, source: str) -> list:
    """A curved segment as a polyline: its parameter range halved until each piece's
    curve lies within :data:`CURVE_SAG_PX` of its chord (checked at its quarter
    points), or the piece is shorter than :data:`SNAP_PX` (it would be merged),
    at most :data:`CURVE_DEPTH` halvings; [(x, y)] px from start to end."""
    def at(t):
        return np.array(_point(seg.point(t), name, source))

    def pieces(t0, t1, p0, p1, depth):
        ts = [t0 + (t1 - t0) * f for f in (0.25, 0.5, 0.75)]
        mids = [at(t) for t in ts]
        chord = p1 - p0
        length = float(np.hypot(*chord))
        sag = max(abs(float(chord[0] * (m - p0)[1] - chord[1] * (m - p0)[0]))
                  / max(length, 1e-300) if length else float(np.hypot(*(m - p0)))
                  for m in mids)
        if depth >= CURVE_DEPTH or sag <= CURVE_SAG_PX or length <= SNAP_PX:
            return [p1]
        return (pieces(t0, ts[1], p0, mids[1], depth + 1)
                + pieces(ts[1], t1, mids[1], p1, depth + 1))

    start = at(0.0)
    return [tuple(map(float, p)) for p in [start] + pieces(0.0, 1.0, start, at(1.0), 0)]


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


def _tag(element) -> str:
    """The SVG element kind of an svgelements shape (``line``, ``path``, ``rect``...)."""
    return type(element).__name__.lower().replace("simpleline", "line")


def _element_name(element, number: int) -> str:
    ident = element.values.get("id")
    return f"{_tag(element)} {number}" + (f" (id {ident!r})" if ident else "")


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


def _straight(seg, a: np.ndarray, b: np.ndarray, name: str, source: str) -> bool:
    """Whether a Bézier or arc segment from ``a`` to ``b`` (px, its checked ends) is
    its chord (its points at a few parameters lie on it within :data:`STRAIGHT`)."""
    chord = b - a
    length = float(np.hypot(*chord))
    for t in (0.25, 0.5, 0.75):
        d = np.array(_point(seg.point(t), name, source)) - a
        off = abs(float(chord[0] * d[1] - chord[1] * d[0])) / max(length, 1e-300)
        if off > STRAIGHT * length or not length and np.hypot(*d) > 0.0:
            return False
    return True


