"""thicken(): crease pattern → ThickMesh (paper §2.2).

Each crease is widened into a strip of its hinge width; the panels are the
faces offset inward by half the width of each crease side (a mitered offset,
so each panel corner is the intersection X of two offset lines — Eq. 1 read
with its arctan); each strip is cut square where the farther of its two
neighbouring panel corners lies, which decouples strips at vertices and leaves
holes there. Strips are split across their width into ``k`` sub-strips and
everything is extruded to thickness ``H`` (mid-plane at z = 0).

Panel outlines get the strip corners inserted (collinear points), so panels and
strips share vertices on every common face: the mesh is conforming.
Units: mm, angles in degrees at this API.
"""
from __future__ import annotations

import math

import numpy as np

from elements.bending_hinge import HINGE_PARAMS
from .errors import MeshError
from .hinges import DEFAULT_HINGE, HINGE_MODELS
from .mesh import ElementGroup, ThickMesh
from .pattern import CreasePattern

MAX_SUBDIVISIONS = 16


# ----------------------------------------------------------------- parameters
def minimum_hinge_width(thickness: float, max_angle_deg, bend_radius: float = 0.0):
    """Eq. 7: hinge width W = (r + H/2)·θmax in mm (θmax given in degrees)."""
    return (bend_radius + 0.5 * thickness) * np.radians(max_angle_deg)


def auto_subdivisions(width, thickness: float, max_angle_deg, hinge=DEFAULT_HINGE) -> np.ndarray:
    """Sub-strips per hinge chosen from its largest fold angle.

    Rule: k = max(2, ceil(θmax / 45°)) (smoothness, paper §6.1). With Eq. 8
    targets (``hinge="eq8"``, per hinge or for all) k is then raised (up to
    16) while one sub-strip of width W/k cannot reach θmax/k: its limit is
    2·atan(W/(k·H)) (top face shrinks to zero length). Arc and axis targets
    have no per-strip limit (an arc's inner face shrinks to zero at 2W/H
    whatever k; the axis hinge pivots about its inner surface past
    2·atan(W/H)), so only the smoothness rule applies. With Eq. 7's minimum
    width (r = 0) the Eq. 8 rule can never be met (θ/k > 2·atan(θ/2k) for
    all k) and stops at 16.
    """
    width = np.atleast_1d(np.asarray(width, dtype=float))
    theta = np.radians(np.broadcast_to(max_angle_deg, width.shape))
    eq8 = np.broadcast_to(np.asarray(hinge) == "eq8", width.shape)
    k = np.maximum(2, np.ceil(np.degrees(theta) / 45.0 - 1e-9)).astype(np.int64)
    for _ in range(MAX_SUBDIVISIONS):
        short = (theta / k > 2 * np.arctan(width / (k * thickness))) & (k < MAX_SUBDIVISIONS) & eq8
        if not short.any():
            break
        k[short] += 1
    return k


def _resolve_widths(pattern, thickness, hinge_width, bend_radius) -> np.ndarray:
    widths = np.array(pattern.widths, dtype=float)
    if hinge_width is not None:
        widths = np.broadcast_to(np.asarray(hinge_width, dtype=float), widths.shape).copy()
    auto = np.isnan(widths)
    widths[auto] = minimum_hinge_width(thickness, pattern.max_angles[auto], bend_radius)
    widths[pattern.assignments == "B"] = np.nan
    bad = np.flatnonzero(~(widths > 0) & (pattern.assignments != "B"))
    if len(bad):
        raise MeshError(f"{pattern.source}: edge {bad[0]}: hinge width must be > 0 mm")
    return widths


def _resolve_hinges(pattern, hinge) -> np.ndarray:
    """(E,) hinge model name per edge ("" for boundary edges), validated."""
    names = np.broadcast_to(np.asarray(DEFAULT_HINGE if hinge is None else hinge, dtype=object),
                            (pattern.n_edges,)).copy()
    names[[n is None for n in names]] = DEFAULT_HINGE
    bad = [e for e, n in enumerate(names) if n not in HINGE_MODELS]
    if bad:
        raise MeshError(f"{pattern.source}: edge {bad[0]}: unknown hinge model "
                        f"{names[bad[0]]!r} (available: {', '.join(HINGE_MODELS)})")
    names[pattern.assignments == "B"] = ""
    return names.astype(str)


def _resolve_subdivisions(pattern, widths, thickness, subdivisions, hinges) -> np.ndarray:
    crease = pattern.assignments != "B"
    if subdivisions is None or (isinstance(subdivisions, str) and subdivisions == "auto"):
        k = np.zeros(pattern.n_edges, dtype=np.int64)
        k[crease] = auto_subdivisions(widths[crease], thickness, pattern.max_angles[crease],
                                      hinges[crease])
        return k
    k = np.broadcast_to(np.asarray(subdivisions), (pattern.n_edges,))
    if not np.issubdtype(k.dtype, np.integer) or (k[crease] < 1).any():
        raise MeshError(f"{pattern.source}: subdivisions must be a positive integer or "
                        f"'auto', got {subdivisions!r}")
    return np.where(crease, k, 0).astype(np.int64)


# ------------------------------------------------------------------- geometry
def _length(v) -> float:
    """Euclidean length of one vector (mm): ``np.linalg.norm``'s own arithmetic for a
    1-D array (the square root of v·v), without its dispatch (≈ 2 µs a call, 6 000
    calls for a Miura 20 × 20's coarse twin)."""
    return math.sqrt(v.dot(v))


def _cross(a, b):
    return a[..., 0] * b[..., 1] - a[..., 1] * b[..., 0]


def _left_normal(d):
    return np.array([-d[1], d[0]])


def _inset_corners(p, offsets):
    """Mitered inward offsets of faces of one vertex count: one corner per face vertex.

    Parameters
    ----------
    p : (n, m, 2) float
        The faces' vertices, mm, counter-clockwise.
    offsets : (n, m) float
        Inward offset (mm) of the side leaving each vertex.

    Returns
    -------
    corners : (n, m, 2) float
        mm.
    mismatched : (n, m) bool
        Where the two sides meeting at a vertex are collinear but offset by
        different amounts (no corner; ``corners`` holds the side's point there).
    """
    d = np.roll(p, -1, axis=1) - p
    u = d / np.linalg.norm(d, axis=2)[..., None]
    n = np.stack([-u[..., 1], u[..., 0]], axis=-1)
    u_in, n_in, off_in = np.roll(u, 1, axis=1), np.roll(n, 1, axis=1), np.roll(offsets, 1, axis=1)
    denom = _cross(u_in, u)
    rhs = offsets[..., None] * n - off_in[..., None] * n_in
    straight = np.abs(denom) < 1e-9
    mismatched = straight & (np.abs(offsets - off_in) > 1e-9 * (1 + offsets))
    t = np.where(straight, 0.0, _cross(rhs, u) / np.where(straight, 1.0, denom))
    return p + off_in[..., None] * n_in + t[..., None] * u_in, mismatched


def _face_offsets(pattern, widths) -> list[np.ndarray]:
    """Inward offset (mm) of each side of each face: half its hinge width, 0 on B."""
    key = {}
    for e, (a, b) in enumerate(pattern.edges):
        key[(int(a), int(b))] = key[(int(b), int(a))] = e
    half = np.nan_to_num(0.5 * widths)
    return [np.array([half[key[(int(a), int(b))]] for a, b in zip(f, np.roll(f, -1))])
            for f in pattern.faces]


def _inset_fails(p, corners) -> np.ndarray:
    """(n,) bool: faces (vertices ``p``, (n, m, 2) mm) whose inset ``corners`` turned a
    side around or make an invalid polygon (the panel vanished or turned inside out)."""
    import shapely

    side_old = np.roll(p, -1, axis=1) - p
    side_new = np.roll(corners, -1, axis=1) - corners
    flipped = (np.einsum("fij,fij->fi", side_old, side_new) <= 0).any(axis=1)
    return flipped | ~shapely.is_valid(shapely.polygons(corners))


class _PointTable:
    """2D points of the thick sheet; ids are allocated as points are added."""

    def __init__(self):
        self.coords: list[np.ndarray] = []

    def add(self, xy) -> int:
        self.coords.append(np.asarray(xy, dtype=float))
        return len(self.coords) - 1

    def extend(self, xy) -> list[int]:
        """Ids of the points of ``xy`` (k, 2), added in order."""
        start = len(self.coords)
        self.coords.extend(np.asarray(xy, dtype=float))
        return list(range(start, len(self.coords)))

    def between(self, a: int, b: int, fractions) -> list[int]:
        """Ids [a, new points at the given fractions of the way a → b, b]."""
        p, q = self.coords[a], self.coords[b]
        return [a] + [self.add(p + t * (q - p)) for t in fractions] + [b]


def _corner_ids(pattern, widths, table):
    """Each face's inset corners ((m, 2) mm) and their point ids (added to ``table``
    face by face), the faces of one vertex count computed together (a loop of
    small array operations per face took 31 ms of the 113 ms a Miura 20 × 20's
    coarse twin took to build). Raises on the first face (by id) whose inset
    fails."""
    offsets = _face_offsets(pattern, widths)
    corners = [None] * len(pattern.faces)
    by_size: dict[int, list[int]] = {}
    for f, face in enumerate(pattern.faces):
        by_size.setdefault(len(face), []).append(f)
    failed = {}  # face → message
    for group in by_size.values():
        p = pattern.vertices[np.array([pattern.faces[f] for f in group])]
        inset, mismatched = _inset_corners(p, np.array([offsets[f] for f in group]))
        fails = _inset_fails(p, inset)
        for row, f in enumerate(group):
            corners[f] = inset[row]
            if mismatched[row].any():
                vertex = pattern.faces[f][int(np.flatnonzero(mismatched[row])[0])]
                failed[f] = (f"{pattern.source}: face {f}: two collinear sides at vertex "
                             f"{vertex} have different hinge widths")
            elif fails[row]:
                failed[f] = (f"{pattern.source}: face {f}: hinge widths are too large for "
                             "this face (its panel would vanish or turn inside out); use "
                             "narrower hinges or a larger pattern")
    if failed:
        raise MeshError(failed[min(failed)])
    return corners, [table.extend(c) for c in corners]


def _corner_lookup(pattern) -> dict:
    """{(face, vertex): the vertex's place in the face's loop} (its first)."""
    lookup = {}
    for f, face in enumerate(pattern.faces):
        for i, v in enumerate(face):
            lookup.setdefault((f, int(v)), i)
    return lookup


def _strip_cuts(pattern, e, corners, place) -> tuple[float, float]:
    """Distances (mm) from each crease end to where its strip starts (≥ 0); ``place``:
    :func:`_corner_lookup`."""
    a, b = pattern.edges[e]
    pa, pb = pattern.vertices[a], pattern.vertices[b]
    u = (pb - pa) / _length(pb - pa)
    cuts = []
    for end, point, direction in ((a, pa, u), (b, pb, -u)):
        along = [float((corners[f][place[(int(f), int(end))]] - point) @ direction)
                 for f in pattern.edge_faces[e]]
        cuts.append(max(along + [0.0]))
    return cuts[0], cuts[1]


def _strip_lines(pattern, e, width, k, cuts, segments: int = 1):
    """(k+1, m+1, 2) array: for each line across the strip, its m+1 points from end a
    to end b (m = ``segments``, equal lengths; 1: just the two ends).

    Line 0 is the left side (left face), line k the right side.
    """
    a, b = pattern.edges[e]
    pa, pb = pattern.vertices[a], pattern.vertices[b]
    length = _length(pb - pa)
    if cuts[0] + cuts[1] >= length * (1 - 1e-9):
        raise MeshError(f"{pattern.source}: edge {e} ({length:.6g} mm) is too short for the "
                        "hinge widths around it; use narrower hinges")
    u = (pb - pa) / length
    n = _left_normal(u)
    start, stop = pa + cuts[0] * u, pb - cuts[1] * u
    t_along = np.arange(segments + 1)[:, None] / segments
    ends = start + t_along * (stop - start)
    ends[-1] = stop  # exactly the end (the path is compared across units to 1e-9)
    t = 0.5 * width * (1 - 2 * np.arange(k + 1) / k)
    return ends[None, :, :] + t[:, None, None] * n[None, None, :]


# ---------------------------------------------------------------- assembling
def _close(p, q, scale) -> bool:
    return _length(p - q) <= 1e-9 * scale


def _attach_strip_sides(pattern, e, lines, corners, corner_ids, place, table, inserts, scale):
    """Ids of the strip's side points (a → b), shared with (or inserted into) its panels
    (``place``: :func:`_corner_lookup`).

    A side's end points are the panel's corners where they coincide, else new
    points inserted into the panel's loop; its intermediate points (a strip
    split into segments along the crease) are always inserted, in loop order.
    """
    a, b = pattern.edges[e]
    f_left, f_right = pattern.edge_faces[e]
    side_ids = {}
    for side, face, first in ((0, f_left, a), (len(lines) - 1, f_right, b)):
        i = place[(int(face), int(first))]
        j = (i + 1) % len(pattern.faces[face])
        pts = lines[side] if side == 0 else lines[side][::-1]  # in the face's loop order
        got = []
        for n, point in enumerate(pts):
            corner = i if n == 0 else (j if n == len(pts) - 1 else None)
            if corner is not None and _close(point, corners[face][corner], scale):
                got.append(corner_ids[face][corner])
            else:
                got.append(table.add(point))
                inserts[face].setdefault(i, []).append(got[-1])
        side_ids[side] = got if side == 0 else got[::-1]
    return side_ids


def thicken(pattern: CreasePattern, thickness: float, hinge_width=None,
            subdivisions="auto", bend_radius: float = 0.0, hinge=None,
            stiffness=None, stretch=None, elastic=None,
            cell_size: float | None = None) -> ThickMesh:
    """Build the thick prism mesh of a crease pattern (paper §2.2).

    Parameters
    ----------
    pattern : CreasePattern
    thickness : float
        Sheet thickness H, mm (> 0).
    hinge_width : float or (E,) array, optional
        Hinge width W per edge, mm; overrides the pattern's widths when given.
        NaN entries (and the default for patterns without widths) use Eq. 7,
        W = (r + H/2)·θmax, with r = ``bend_radius`` and θmax the edge's max angle.
    subdivisions : int, (E,) ints or "auto"
        Sub-strips per hinge; "auto" uses :func:`auto_subdivisions`.
    bend_radius : float
        Inner bend radius r for automatic widths, mm.
    hinge : {"axis", "arc", "eq8"} or (E,) of them (None entries: default), optional
        Hinge kinematics: ``"axis"`` (default,
        :data:`foldcore.hinges.DEFAULT_HINGE`) — the panels turn about the
        crease's mid-line (rigid-origami kinematics at any thickness) until
        their inner edges touch, then about their inner edges; ``"arc"`` — the paper's
        strip bent as a circular arc of constant length (Eq. 7 thickness
        accommodation; the axis drifts off the crease); ``"eq8"`` — the
        paper's Eq. 8 trapezoids. Why and what each costs:
        :mod:`foldcore.hinges`. FOLD files carry it per crease as
        ``foldcore:edges_hinge``.
    stiffness : dict, optional
        ``{"panel": (F,) or float, "hinge": (E,) or float}`` stiffness factors
        multiplying the volume weights (dimensionless, > 0, default 1). Each
        element's energy is weight × ‖its deviation from its target‖², so a
        factor s makes an element s times as costly to strain as the same
        volume of the base material — a material s times stiffer (linear
        elastic energy ½Eε² per volume). Factors change nothing where every
        target can be met; where targets conflict (closed loops, incompatible
        actuation, position targets) they decide the compromise.
        FOLD files carry them as ``foldcore:edges_stiffness`` /
        ``foldcore:faces_stiffness`` (:class:`foldcore.io.FoldFile`).
    stretch : dict {edge id: Poisson ratio ν}, optional
        Creases made *stretch* hinges (§6.3, :mod:`elements.stretch_hinge`,
        one strip each, group ``stretch_hinge``) instead of bending hinges;
        ν in [−1, 0.5]. They start passive (free to stretch); actuate them
        with :meth:`foldcore.Simulation.set_stretch_ratios`.
    elastic : dict {face id: n, "auto" or (n1, n2)}, optional
        Elastic panels (§5.5): the face becomes prisms ("cells"), each a panel
        element whose target is its own rest shape, so the panel deforms
        where its cells meet (its stiffness factor scales every cell).
        ``n`` (a bar, as in the paper): n cells side by side away from its one
        crease side; the face must be a quadrilateral with exactly one crease
        side and no hinge ends inside its sides; ``panel_of_face`` names the
        cell next to the crease. ``(n1, n2)`` (a plate, beyond the paper): an
        n1 × n2 grid of quads, n1 along the face's sides 0 and 2 and n2 along
        sides 1 and 3 (side i runs from ``pattern.faces[f][i]`` to the next
        vertex); any number of its sides may be creases, whose strips are then
        split into as many segments along the crease (``ThickMesh.segments``)
        so strips and cells share their points (two plates on one crease must
        agree on the count); where a strip stops short of a corner (Eq. 1 cuts
        at acute/obtuse corners) the gap adds a column of cells, or a triangle
        where the opposite side has no gap.
        ``panel_of_face`` names the cell at the middle of its first crease
        side. ``("rings", n)`` (a facet, any face; a plain count on a face that
        is not a quadrilateral means the same): n rings, scaled copies of the
        panel's outline toward its centroid, quads between them and a fan of
        triangles at the centre; the outline is the panel's own, so the strips
        stay whole; the face must be star-shaped from its centroid.
        ``"auto"`` (for n or either of n1, n2): ⌈length / ``cell_size``⌉
        (a plate: the longer of the two sides; a facet: the farthest outline
        point from the centroid). ``elastic="plates"``: every quadrilateral
        face a plate with "auto" counts (other faces stay rigid);
        ``elastic="facets"``: every face a facet with "auto" rings. Each
        crease's fold angle is measured by the cells beside it
        (``ThickMesh.crease_panels``).
    cell_size : float, optional
        Target cell length (mm) for ``"auto"`` counts.

    Returns
    -------
    ThickMesh
    """
    if not (np.isfinite(thickness) and thickness > 0):
        raise MeshError(f"{pattern.source}: thickness must be a positive number of mm, "
                        f"got {thickness}")
    _check_stiffness(pattern, stiffness)
    widths = _resolve_widths(pattern, thickness, hinge_width, bend_radius)
    hinges = _resolve_hinges(pattern, hinge)
    ks = _resolve_subdivisions(pattern, widths, thickness, subdivisions, hinges)
    stretch = _resolve_stretch(pattern, stretch)
    ks[list(stretch)] = 1
    table = _PointTable()
    corners, corner_ids = _corner_ids(pattern, widths, table)
    place = _corner_lookup(pattern)
    bars, plates, facets = _split_elastic(pattern, elastic)
    plates = _plate_counts(pattern, plates, corners, cell_size)
    segments = _segments(pattern, plates, stretch, bars)
    inserts: list[dict] = [dict() for _ in pattern.faces]
    scale = float(np.ptp(pattern.vertices, axis=0).max())
    strip_points = {}
    for e in pattern.creases:
        lines = _strip_lines(pattern, e, widths[e], ks[e], _strip_cuts(pattern, e, corners, place),
                             int(segments[e]))
        sides = _attach_strip_sides(pattern, e, lines, corners, corner_ids, place, table, inserts,
                                    scale)
        inner = [[table.add(p) for p in lines[j]] for j in range(1, ks[e])]
        strip_points[int(e)] = [sides[0]] + inner + [sides[ks[e]]]
    loops = _panel_loops(corner_ids, inserts)
    cells = _elastic_cells(pattern, loops, bars, table, cell_size)
    pieces = {frozenset(pair) for lines in strip_points.values() for side in (lines[0], lines[-1])
              for pair in zip(side, side[1:])}
    cells.update(_plate_cells(pattern, loops, corner_ids, plates, table, pieces))
    facet_cells, rings = _facet_cells(pattern, loops, facets, table, cell_size)
    cells.update(facet_cells)
    points = np.array(table.coords)
    stiff = stiffness or {}
    panels, panel_of_face = _panel_group(pattern, points, loops, cells, thickness,
                                         stiff.get("panel", 1.0))
    bending = {e: lines for e, lines in strip_points.items() if e not in stretch}
    strips, strips_of = _hinge_group(pattern, points, bending, widths, ks, thickness,
                                     hinges, stiff.get("hinge", 1.0))
    groups = {"rigid_panel": panels, "bending_hinge": strips}
    if stretch:
        groups["stretch_hinge"] = _stretch_group(pattern, points, strip_points, stretch,
                                                 widths, thickness, stiff.get("hinge", 1.0))
    built = {**{f: len(c) for f, c in cells.items() if f in bars}, **plates, **rings}
    measuring = _crease_panels(pattern, points, cells, panels, panel_of_face)
    return ThickMesh(points=points, thickness=float(thickness), groups=groups,
                     panel_of_face=panel_of_face,
                     strips_of_crease=strips_of, hinge_width=widths, subdivisions=ks,
                     segments=segments, elastic=built, hinge_model=hinges,
                     crease_panels=measuring)


def _prism(ids2d, points, thickness):
    """Footprint point ids (m,) and rest coordinates (2m, 3) of one prism: top loop,
    then bottom loop, centred, world frame."""
    ids2d = np.asarray(ids2d, dtype=np.int64)
    return ids2d, _prisms(ids2d[None], points, thickness)[0]


def _prisms(footprints, points, thickness):
    """Rest coordinates (n, 2m, 3) of the prisms on ``footprints`` (n, m) point ids:
    each its top loop (z = +H/2) then its bottom loop, centred, world frame."""
    xy = points[footprints]
    h = np.full(footprints.shape + (1,), 0.5 * thickness)
    xyz = np.concatenate([np.concatenate([xy, h], axis=2), np.concatenate([xy, -h], axis=2)],
                         axis=1)
    return xyz - xyz.mean(axis=1, keepdims=True)


def _panel_loops(corner_ids, inserts) -> list:
    """Footprint point ids of each panel: its corners with the strip ends inserted."""
    loops = []
    for f, ids in enumerate(corner_ids):
        loop = []
        for i, cid in enumerate(ids):
            loop.append(cid)
            loop += inserts[f].get(i, [])
        loops.append(loop)
    return loops


def _elastic_cells(pattern, loops, elastic, table, cell_size) -> dict:
    """{face: [cell loops]}: each elastic face cut into n quads parallel to its crease side."""
    cells = {}
    for f, n in elastic.items():
        loop = loops[f]
        side = _single_crease_side(pattern, f, len(loop))
        a, b, c, d = (loop[(side + k) % 4] for k in range(4))
        pa, pb, pc, pd = (table.coords[i] for i in (a, b, c, d))
        length = 0.5 * (np.linalg.norm(pd - pa) + np.linalg.norm(pc - pb))
        n = _cell_count(n, length, cell_size, f"{pattern.source}: elastic panel on face {f}",
                        f"the number of cells must be a positive integer or 'auto', got {n!r}")
        side_a = table.between(a, d, np.arange(1, n) / n)
        side_b = table.between(b, c, np.arange(1, n) / n)
        cells[f] = [[side_a[j], side_b[j], side_b[j + 1], side_a[j + 1]] for j in range(int(n))]
    return cells


def _facet_cells(pattern, loops, facets, table, cell_size) -> tuple[dict, dict]:
    """({face: [cell loops]}, {face: ("rings", n)}): each facet (any face given rings)
    cut into n rings, scaled copies of its outline toward its
    centroid: quads between rings, a fan of triangles at the centre. The outline
    is the panel's own (strip ends and segment points included), so cells and
    strips conform; the face must be star-shaped from its centroid. The cell
    nearest the middle of its first crease side comes first (it measures the face)."""
    cells, counts = {}, {}
    for f, n in facets.items():
        loop = loops[f]
        xy = np.array([table.coords[i] for i in loop])
        centre = _area_centroid(xy)
        where = f"{pattern.source}: elastic facet on face {f}"
        if np.any(_cross(xy - centre, np.roll(xy, -1, axis=0) - centre) <= 0):
            raise MeshError(f"{where}: its outline is not star-shaped from its centroid, "
                            "so it cannot be cut into rings; keep it rigid")
        reach = float(np.linalg.norm(xy - centre, axis=1).max())
        n = _cell_count(n, reach, cell_size, where,
                        f"the number of rings must be a positive integer or 'auto', got {n!r}")
        rings = [list(loop)] + [[table.add(centre + (1.0 - r / n) * (p - centre)) for p in xy]
                                for r in range(1, n)]
        middle = table.add(centre)
        m = len(loop)
        quads = [[rings[r][i], rings[r][(i + 1) % m], rings[r + 1][(i + 1) % m], rings[r + 1][i]]
                 for r in range(n - 1) for i in range(m)]
        fan = [[rings[-1][i], rings[-1][(i + 1) % m], middle] for i in range(m)]
        found = quads + fan
        first = _nearest_cell(pattern, f, found, table)
        cells[f] = [found[first]] + found[:first] + found[first + 1:]
        counts[f] = ("rings", n)
    return cells, counts


def _area_centroid(xy) -> np.ndarray:
    """(2,) area centroid of a simple polygon (n, 2), mm."""
    cross = _cross(xy, np.roll(xy, -1, axis=0))
    return (xy + np.roll(xy, -1, axis=0)).T @ cross / (3.0 * cross.sum())


def _nearest_cell(pattern, f: int, cells: list, table) -> int:
    """Index of the cell whose centroid is nearest the middle of face ``f``'s first
    crease side (its first side if it has none)."""
    face = pattern.faces[f]
    sides = [(face[i], face[(i + 1) % len(face)]) for i in range(len(face))]
    creased = [s for s in sides if pattern.assignments[_edge_of(pattern, *s)] != "B"]
    u, v = (creased or sides)[0]
    return _nearest(cells, table.coords, 0.5 * (pattern.vertices[u] + pattern.vertices[v]))


def _nearest(cells: list, coords, point) -> int:
    """Index of the cell (a loop of point ids into ``coords``) whose footprint centroid
    is nearest ``point`` (2,), mm."""
    centres = np.array([np.mean([coords[i] for i in c], axis=0) for c in cells])
    return int(np.argmin(np.linalg.norm(centres - point, axis=1)))


def _split_elastic(pattern, elastic) -> tuple[dict, dict, dict]:
    """Elastic faces as ({face: n or "auto"} bars, {face: (n1, n2)} plates,
    {face: n or "auto"} facets cut into rings — ``("rings", n)``, or a count on a
    face that is not a quadrilateral); ``"plates"``: every quadrilateral face a
    plate with "auto" counts; ``"facets"``: every face rings with "auto" counts."""
    if isinstance(elastic, str):
        if elastic == "plates":
            return {}, {f: ("auto", "auto") for f, face in enumerate(pattern.faces)
                        if len(face) == 4}, {}
        if elastic == "facets":
            return {}, {}, {f: "auto" for f in range(len(pattern.faces))}
        raise MeshError(f"{pattern.source}: elastic must be a dict {{face: cells}}, "
                        f"'plates' or 'facets', got {elastic!r}")
    bars, plates, facets = {}, {}, {}
    for f, n in dict(elastic or {}).items():
        f = int(f)
        if not 0 <= f < len(pattern.faces):
            raise MeshError(f"{pattern.source}: elastic panel: face {f} does not exist")
        if isinstance(n, (tuple, list)) and len(n) == 2 and n[0] == "rings":
            facets[f] = n[1]
        elif isinstance(n, (tuple, list)):
            if len(n) != 2:
                raise MeshError(f"{pattern.source}: elastic plate on face {f}: give two cell "
                                f"counts (n1, n2) or ('rings', n), got {n!r}")
            plates[f] = tuple(n)
        elif len(pattern.faces[f]) != 4:
            facets[f] = n
        else:
            bars[f] = n
    return bars, plates, facets


def _plate_counts(pattern, plates, corners, cell_size) -> dict:
    """{face: (n1, n2)} validated, "auto" entries from ``cell_size`` (mm): n1 cells
    along the face's sides 0 and 2 (its first and third, in pattern order), n2
    along sides 1 and 3."""
    out = {}
    for f, counts in plates.items():
        if len(pattern.faces[f]) != 4:
            raise MeshError(f"{pattern.source}: elastic plate on face {f}: only "
                            f"quadrilateral faces can be gridded, got {len(pattern.faces[f])} "
                            "sides")
        c = np.asarray(corners[f])
        side = np.linalg.norm(np.roll(c, -1, axis=0) - c, axis=1)
        where = f"{pattern.source}: elastic plate on face {f}"
        out[f] = tuple(
            _cell_count(n, length, cell_size, where,
                        f"cell counts must be positive integers or 'auto', got {counts!r}")
            for n, length in zip(counts, (max(side[0], side[2]), max(side[1], side[3]))))
    return out


def _cell_count(n, length: float, cell_size, where: str, bad: str) -> int:
    """A cell count: ``n`` checked, or for ``"auto"`` ⌈length / cell_size⌉ (mm / mm);
    ``where`` and ``bad`` make the refusal's message."""
    if isinstance(n, str) and n == "auto":
        if not (cell_size is not None and np.isfinite(cell_size) and cell_size > 0):
            raise MeshError(f"{where}: 'auto' needs a positive cell_size in mm, "
                            f"got {cell_size!r}")
        n = max(1, int(np.ceil(length / cell_size - 1e-9)))
    if isinstance(n, str) or int(n) != n or n < 1:
        raise MeshError(f"{where}: {bad}")
    return int(n)


def _segments(pattern, plates, stretch, bars) -> np.ndarray:
    """(E,) int: prisms along each crease's strip (1; a plate's cell count along its
    crease sides, so the strip conforms with the cells; 0 for boundary edges).
    A bar (1D cells) cannot share a split crease: refused, naming both faces."""
    segments = np.where(pattern.assignments == "B", 0, 1).astype(np.int64)
    owner = {}
    for f, counts in plates.items():
        face = pattern.faces[f]
        for side in range(4):
            e = _edge_of(pattern, face[side], face[(side + 1) % 4])
            if pattern.assignments[e] == "B":
                continue
            if e in stretch:
                raise MeshError(f"{pattern.source}: elastic plate on face {f}: its side edge "
                                f"{e} is a stretch hinge (one strip, cannot follow the cells)")
            n = counts[side % 2]
            if e in owner and segments[e] != n:
                raise MeshError(f"{pattern.source}: elastic plates on faces {owner[e]} and {f} "
                                f"put {segments[e]} and {n} cells along their shared edge {e}")
            segments[e], owner[e] = n, f
            other = [g for g in pattern.edge_faces[e] if g != f]
            if n > 1 and other and int(other[0]) in bars:
                raise MeshError(f"{pattern.source}: elastic bar on face {int(other[0])} shares "
                                f"edge {e} with the plate on face {f}, whose {n} cells split "
                                "the strip; make both plates")
    return segments


def _plate_cells(pattern, loops, corner_ids, plates, table, strip_pieces) -> dict:
    """{face: [cell loops]}: each plate a grid of quads conforming with its outline.

    The outline's four geometric corners split it into sides; a side's points
    (its corners, the ends and segment points of the strip along it) become
    grid points. Opposite sides get equal counts: a boundary side takes the
    positions of the one opposite; a crease side whose strip stops short of a
    corner (Eq. 1 cuts at acute/obtuse corners) has a gap there, split as
    needed. Interior points: Coons patch of the four sides. The cell at the
    middle of the first crease side comes first (it measures the face).
    """
    cells = {}
    for f, counts in plates.items():
        sides = _plate_sides(pattern, f, loops[f], corner_ids[f], table, strip_pieces, counts)
        grid = _coons_grid(sides, table)
        n1, n2 = grid.shape[0] - 1, grid.shape[1] - 1
        quads = {(i, j): _distinct([grid[i, j], grid[i + 1, j], grid[i + 1, j + 1],
                                    grid[i, j + 1]])
                 for i in range(n1) for j in range(n2)}
        for key, quad in quads.items():
            if _polygon_area(np.array([table.coords[k] for k in quad])) <= 0:
                raise MeshError(f"{pattern.source}: elastic plate on face {f}: cell {key} of "
                                "its grid is folded over (outline too far from a "
                                "quadrilateral); use fewer cells")
        first = _measuring_cell(pattern, f, n1, n2)
        cells[f] = [quads[first]] + [q for key, q in quads.items() if key != first]
    return cells


def _distinct(loop: list) -> list:
    """A cell loop without repeated points (a corner where two grid lines meet makes
    a quad a triangle)."""
    return [p for k, p in enumerate(loop) if p != loop[k - 1]]


def _plate_sides(pattern, f, loop, corners, table, strip_pieces, counts) -> list:
    """Point ids along the four sides of a plate's outline, geometric corner to
    corner, opposite sides with equal counts (see :func:`_plate_cells`); two
    opposite sides without strip points are cut into their count (n1 or n2)
    of equal pieces."""
    xy = np.array([table.coords[i] for i in loop])
    turn = _cross(xy - np.roll(xy, 1, axis=0), np.roll(xy, -1, axis=0) - xy)
    scale = float(np.ptp(xy, axis=0).max())
    bends = np.flatnonzero(np.abs(turn) > 1e-9 * scale ** 2)
    if len(bends) != 4:
        raise MeshError(f"{pattern.source}: elastic plate on face {f}: its inset outline has "
                        f"{len(bends)} corners, a grid needs 4")
    inset = np.array([table.coords[c] for c in corners])
    order = [int(bends[np.argmin(np.linalg.norm(xy[bends] - c, axis=1))]) for c in inset]
    if len(set(order)) != 4:
        raise MeshError(f"{pattern.source}: elastic plate on face {f}: cannot match its "
                        "outline's corners to the face's")
    sides = []
    for s in range(4):
        a, b = order[s], order[(s + 1) % 4]
        sides.append([loop[(a + k) % len(loop)] for k in range((b - a) % len(loop) + 1)])
    bare = [len(side) == 2 for side in sides]
    for s in range(4):  # two opposite sides without strip points: equal pieces
        n = counts[s % 2]
        if bare[s] and bare[(s + 2) % 4] and n > 1:
            sides[s] = table.between(sides[s][0], sides[s][1], np.arange(1, n) / n)
    for s in (0, 1):
        sides[s], sides[s + 2] = _equal_counts(pattern, f, s, sides[s], sides[s + 2], table,
                                               strip_pieces)
    return sides


def _equal_counts(pattern, f, s, near, far, table, strip_pieces) -> tuple[list, list]:
    """Opposite sides (``far`` runs the other way) with as many points each: a side
    without a strip copies the other's positions; otherwise the gaps between a
    corner and a strip end are split (the longest first); a side without gaps
    repeats the corner facing the other's gap (its cells there are triangles)."""
    face = pattern.faces[f]
    strip = [pattern.assignments[_edge_of(pattern, face[k], face[(k + 1) % 4])] != "B"
             for k in (s, s + 2)]
    far_fwd = far[::-1]
    for _ in range(4 * (len(near) + len(far))):
        if len(near) == len(far_fwd):
            return near, far_fwd[::-1]
        short_is_near = len(near) < len(far_fwd)
        short, long_, short_strip = ((near, far_fwd, strip[0]) if short_is_near
                                     else (far_fwd, near, strip[1]))
        refined = _refined(short, long_, short_strip, table, strip_pieces)
        if refined is None:  # no gap to split: the long side's extra piece meets a corner
            gap_first = frozenset((long_[0], long_[1])) not in strip_pieces
            refined = [short[0]] + short if gap_first else short + [short[-1]]
        short = refined
        near, far_fwd = (short, far_fwd) if short_is_near else (near, short)
    raise MeshError(f"{pattern.source}: elastic plate on face {f}: cannot even sides {s} "
                    f"and {s + 2}")


def _refined(side, other, has_strip, table, strip_pieces):
    """``side`` with one more point: at the other side's next relative position if it
    has no strip, else splitting its longest end gap; None if it cannot."""
    if not has_strip:
        return table.between(side[0], side[-1],
                             _chord_params(np.array([table.coords[i] for i in other]))[1:-1])
    pts = np.array([table.coords[i] for i in side])
    ends = [(float(np.linalg.norm(pts[1] - pts[0])), 0),
            (float(np.linalg.norm(pts[-1] - pts[-2])), len(side) - 2)]
    ends = [(length, k) for length, k in ends if len(side) > 2 and length > 0]
    gaps = [(length, k) for length, k in ends
            if frozenset((side[k], side[k + 1])) not in strip_pieces]
    if not gaps:
        return None
    _, k = max(gaps)
    middle = table.add(0.5 * (pts[k] + pts[k + 1]))
    return side[:k + 1] + [middle] + side[k + 1:]


def _chord_params(points: np.ndarray) -> np.ndarray:
    """(n,) chord-length parameters 0 … 1 of a polyline's points (n, 2)."""
    t = np.r_[0.0, np.cumsum(np.linalg.norm(np.diff(points, axis=0), axis=1))]
    return t / t[-1]


def _coons_grid(sides, table) -> np.ndarray:
    """(n1 + 1, n2 + 1) point ids: the four sides on the border, interior points by a
    Coons patch of the sides over their chord-length parameters."""
    b0 = np.array([table.coords[i] for i in sides[0]])
    b1 = np.array([table.coords[i] for i in sides[1]])
    b2 = np.array([table.coords[i] for i in sides[2][::-1]])
    b3 = np.array([table.coords[i] for i in sides[3][::-1]])
    n1, n2 = len(b0) - 1, len(b1) - 1
    u = 0.5 * (_chord_params(b0) + _chord_params(b2))
    v = 0.5 * (_chord_params(b3) + _chord_params(b1))
    c0, c1, c2, c3 = b0[0], b0[-1], b2[-1], b2[0]
    grid = np.empty((n1 + 1, n2 + 1), dtype=np.int64)
    grid[:, 0], grid[n1, :] = sides[0], sides[1]
    grid[:, n2], grid[0, :] = sides[2][::-1], sides[3][::-1]
    for i in range(1, n1):
        for j in range(1, n2):
            p = ((1 - v[j]) * b0[i] + v[j] * b2[i] + (1 - u[i]) * b3[j] + u[i] * b1[j]
                 - ((1 - u[i]) * (1 - v[j]) * c0 + u[i] * (1 - v[j]) * c1
                    + u[i] * v[j] * c2 + (1 - u[i]) * v[j] * c3))
            grid[i, j] = table.add(p)
    return grid


def _measuring_cell(pattern, f: int, n1: int, n2: int) -> tuple[int, int]:
    """Grid index (i, j) of the cell at the middle of the face's first crease side."""
    face = pattern.faces[f]
    middle = {0: (n1 // 2, 0), 1: (n1 - 1, n2 // 2), 2: (n1 // 2, n2 - 1), 3: (0, n2 // 2)}
    for side in range(4):
        if pattern.assignments[_edge_of(pattern, face[side], face[(side + 1) % 4])] != "B":
            return middle[side]
    return (0, 0)


def _single_crease_side(pattern, f: int, n_points: int) -> int:
    """Index of the one crease side of quadrilateral face ``f`` (MeshError otherwise)."""
    face = pattern.faces[f]
    creases = [i for i, (u, v) in enumerate(zip(face, np.roll(face, -1)))
               if pattern.assignments[_edge_of(pattern, u, v)] != "B"]
    if len(face) != 4 or n_points != 4 or len(creases) != 1:
        raise MeshError(f"{pattern.source}: elastic panel on face {f}: only quadrilateral "
                        "faces with exactly one crease side (a bar) can be subdivided, got "
                        f"{len(face)} sides with {len(creases)} creases")
    return creases[0]


def _edge_of(pattern, u: int, v: int) -> int:
    ends = pattern.edges
    return int(np.flatnonzero(((ends[:, 0] == u) & (ends[:, 1] == v))
                              | ((ends[:, 0] == v) & (ends[:, 1] == u)))[0])


def _panel_group(pattern, points, loops, cells, thickness, stiffness):
    """The panel group (whole panels, or the cells of elastic ones) and each face's
    measuring element (the panel, or the cell next to the crease)."""
    prisms, rests, vols, source, panel_of_face = [], [], [], [], []
    n_top = len(points)
    for f, loop in enumerate(loops):
        panel_of_face.append(len(prisms))
        for cell in cells.get(f, [loop]):
            loop2d, rest = _prism(cell, points, thickness)
            prisms.append(np.concatenate([loop2d, loop2d + n_top]))
            rests.append(rest)
            vols.append(_polygon_area(points[loop2d]) * thickness)
            source.append(f)
    vols, source = np.array(vols), np.array(source, dtype=np.int64)
    factor = np.broadcast_to(np.asarray(stiffness, dtype=float), (len(loops),))[source]
    return (_group("rigid_panel", prisms, rests, np.zeros((len(prisms), 0)), vols,
                   vols * factor, source), np.array(panel_of_face, dtype=np.int64))


def _crease_panels(pattern, points, cells, panels, panel_of_face) -> np.ndarray:
    """(E, 2) the panel elements measuring each crease on its two faces (−1: none):
    the face's panel, or the cell of an elastic face whose footprint centroid is
    nearest the crease's middle (cells of face f are numbered from
    ``panel_of_face[f]`` on, in the order of ``cells[f]``)."""
    faces = pattern.edge_faces
    out = np.where(faces >= 0, panel_of_face[np.maximum(faces, 0)], -1)
    for e in pattern.creases:
        middle = pattern.vertices[pattern.edges[e]].mean(axis=0)
        for side, f in enumerate(faces[e]):
            if f >= 0 and int(f) in cells:
                out[e, side] = panel_of_face[f] + _nearest(cells[int(f)], points, middle)
    return out


def _polygon_area(xy) -> float:
    return 0.5 * float(_cross(xy, np.roll(xy, -1, axis=0)).sum())


def _hinge_group(pattern, points, strip_points, widths, ks, thickness, hinges, stiffness):
    """The bending-hinge group: k × m sub-strips per crease (m segments along it), and
    each crease's strip ids. The footprints are gathered a crease at a time; the
    prisms and parameters are built for all strips at once (per crease, small
    array operations took 28 ms of the 113 ms a Miura 20 × 20's coarse twin took
    to build; a per-strip Python loop once took ~1.2 s of 2.3 s of ``thicken``
    on Miura 50 × 50)."""
    n_top = len(points)
    creases = list(strip_points)
    quads, series, lengths, strips_of, count = [], [], [], {}, 0
    for e in creases:
        k = int(ks[e])
        grid = np.asarray(strip_points[e], dtype=np.int64)  # (k + 1, m + 1): line j, point t
        m = grid.shape[1] - 1  # segments along the crease
        strips_of[e] = np.arange(count, count + k * m, dtype=np.int64)
        count += k * m
        # segment-major: each segment's k strips left → right
        quads.append(np.stack([grid[:-1, :-1].T, grid[1:, :-1].T, grid[1:, 1:].T,
                               grid[:-1, 1:].T], axis=-1).reshape(k * m, 4))
        series.append(np.arange(k * m) % k)  # each strip's place in its series
        # per segment, as before: a vectorised norm sums differently (not bit-identical)
        lengths.append([_length(points[b] - points[a])
                        for a, b in zip(grid[0, :-1], grid[0, 1:])])
    if not creases:
        return _group("bending_hinge", [], [], np.zeros((0, len(HINGE_PARAMS))), np.zeros(0),
                      np.zeros(0), np.zeros(0, dtype=np.int64)), strips_of
    quads = np.concatenate(quads)
    rests = _prisms(quads, points, thickness)  # (S, 8, 3), local frames below
    for e in creases:
        rests[strips_of[e]] = rests[strips_of[e]] @ _hinge_frame(pattern, e)
    e_arr = np.array(creases, dtype=np.int64)
    k_arr = ks[e_arr].astype(np.int64)
    per_crease = np.array([len(strips_of[e]) for e in creases])
    src = np.repeat(e_arr, per_crease)
    params = np.repeat(_hinge_params(pattern, e_arr, widths, k_arr, thickness, hinges), per_crease,
                       axis=0)
    params[:, HINGE_PARAMS.index("series")] = np.concatenate(series)
    vols = np.concatenate([np.repeat(widths[e] / ks[e] * np.array(length) * thickness, ks[e])
                           for e, length in zip(creases, lengths)])
    stiff_e = np.broadcast_to(np.asarray(stiffness, dtype=float), (pattern.n_edges,))
    return _group("bending_hinge", list(np.concatenate([quads, quads + n_top], axis=1)),
                  [rests.reshape(-1, 3)], params, vols, vols * stiff_e[src], src), strips_of


def _check_stiffness(pattern, stiffness) -> None:
    """Stiffness factors: known keys, right lengths, positive and finite."""
    counts = {"panel": (len(pattern.faces), "face"), "hinge": (pattern.n_edges, "edge")}
    for key, value in dict(stiffness or {}).items():
        if key not in counts:
            raise MeshError(f"{pattern.source}: stiffness key {key!r} is not 'panel' or 'hinge'")
        n, item = counts[key]
        factors = np.asarray(value, dtype=float)
        if factors.ndim and factors.shape != (n,):
            raise MeshError(f"{pattern.source}: stiffness[{key!r}] needs one factor per {item} "
                            f"({n}) or one for all, got shape {factors.shape}")
        bad = np.flatnonzero(~(np.atleast_1d(factors) > 0) | ~np.isfinite(np.atleast_1d(factors)))
        if len(bad):
            where = f" ({item} {bad[0]})" if factors.ndim else ""
            raise MeshError(f"{pattern.source}: stiffness[{key!r}]{where} must be a positive "
                            f"finite factor, got {np.atleast_1d(factors)[bad[0]]!r}")


def _resolve_stretch(pattern, stretch) -> dict:
    """{crease edge id: ν} of the stretch hinges, validated."""
    out = {}
    for e, nu in dict(stretch or {}).items():
        e = int(e)
        if not 0 <= e < pattern.n_edges or pattern.assignments[e] == "B":
            raise MeshError(f"{pattern.source}: stretch hinge: edge {e} is not a crease")
        if np.isfinite(pattern.fold_angles[e]):
            raise MeshError(f"{pattern.source}: edge {e} has a fold-angle target but is a "
                            "stretch hinge (actuated by its stretch ratio, not an angle)")
        if not (np.isfinite(nu) and -1.0 <= nu <= 0.5):
            raise MeshError(f"{pattern.source}: stretch hinge on edge {e}: Poisson ratio "
                            f"must be in [-1, 0.5], got {nu!r}")
        out[e] = float(nu)
    return out


def _stretch_group(pattern, points, strip_points, stretch, widths, thickness, stiffness):
    """One stretch strip per stretch crease (its whole width), passive (λ = NaN)."""
    from elements.stretch_hinge import STRETCH_PARAMS

    n_top = len(points)
    stiff_e = np.broadcast_to(np.asarray(stiffness, dtype=float), (pattern.n_edges,))
    loops, rests, params, vols = [], [], [], []
    for e, nu in stretch.items():
        (a0, b0), (a1, b1) = strip_points[e][0], strip_points[e][-1]
        loop2d, rest = _prism([a0, a1, b1, b0], points, thickness)
        loops.append(np.concatenate([loop2d, loop2d + n_top]))
        rests.append(rest @ _hinge_frame(pattern, e))
        row = np.zeros(len(STRETCH_PARAMS))
        row[[STRETCH_PARAMS.index(k) for k in ("width", "height", "ratio", "poisson")]] = \
            (widths[e], thickness, np.nan, nu)
        params.append(row)
        vols.append(widths[e] * float(np.linalg.norm(points[b0] - points[a0])) * thickness)
    src = np.array(list(stretch), dtype=np.int64)
    vols = np.array(vols)
    return _group("stretch_hinge", loops, rests, np.array(params), vols, vols * stiff_e[src],
                  src)


def _hinge_frame(pattern, e) -> np.ndarray:
    """(3, 3) columns: local x (across, toward the left face), y (up), z (along a→b).

    x = ẑ × u written out (as ``np.cross`` evaluates it, signed zeros included:
    the call itself cost 44 µs per crease, a third of the hinge group's build).
    """
    a, b = pattern.edges[e]
    d = pattern.vertices[b] - pattern.vertices[a]
    ux, uy = d / _length(d)
    return np.array([[0.0 * 0.0 - 1.0 * uy, 0.0, ux],
                     [1.0 * ux - 0.0 * 0.0, 0.0, uy],
                     [0.0 * uy - 0.0 * ux, 1.0, 0.0]])


def _hinge_params(pattern, creases, widths, ks, thickness, hinges) -> np.ndarray:
    """(C, len(HINGE_PARAMS)) one sub-strip's parameters per crease (``series`` 0;
    ``floor`` 0, set by Simulation): width W / k, height H, target and max angle per
    sub-strip (rad), M/V sign, hinge model code, k."""
    sign = {"V": 1.0, "M": -1.0, "U": 0.0, "F": 0.0}
    kinds = pattern.assignments[creases]
    target = np.where(kinds == "F", 0.0, pattern.fold_angles[creases])
    p = np.zeros((len(creases), len(HINGE_PARAMS)))
    p[:, HINGE_PARAMS.index("width")] = widths[creases] / ks
    p[:, HINGE_PARAMS.index("height")] = thickness
    p[:, HINGE_PARAMS.index("target")] = np.radians(target) / ks
    p[:, HINGE_PARAMS.index("sign")] = [sign[a] for a in kinds]
    p[:, HINGE_PARAMS.index("max_angle")] = np.radians(pattern.max_angles[creases]) / ks
    p[:, HINGE_PARAMS.index("model")] = [float(HINGE_MODELS.index(h)) for h in hinges[creases]]
    p[:, HINGE_PARAMS.index("strips")] = ks
    return p


def _group(kind, loops, rests, params, volumes, weights, source) -> ElementGroup:
    sizes = np.array([len(x) for x in loops], dtype=np.int64)
    indptr = np.zeros(len(loops) + 1, dtype=np.int64)
    np.cumsum(sizes, out=indptr[1:])
    indices = np.concatenate(loops) if loops else np.zeros(0, np.int64)
    rest = np.vstack(rests) if rests else np.zeros((0, 3))
    return ElementGroup(kind, indptr, indices.astype(np.int64), np.ascontiguousarray(rest),
                        np.ascontiguousarray(params, dtype=np.float64),
                        np.asarray(volumes, dtype=float), np.asarray(weights, dtype=float),
                        source)
