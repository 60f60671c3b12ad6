"""Line drawings to crease patterns: the noding that SVG and ``.cp`` files share.

A drawing is (S, 2, 2) straight segments, each with a crease type (FOLD's
``M V B F U``), a target angle (degrees, NaN passive) and an owner (the
element or line that drew it, for messages). :func:`pattern_from_lines`
snaps endpoints within ``tol`` onto nearby segments (T-joins drawn a little
short or long), nodes every crossing and overlap into a shared vertex
(shapely's unary union), merges vertices within ``tol`` and types each piece
by the segments it lies along (two different types on one piece are
refused, naming both owners; in an SVG, the one Origami Simulator keeps).
Bounds checked before the work: at most :data:`MAX_MEETINGS` meetings of
segments and :data:`MAX_CLOSE_PAIRS` close pairs of noded points.
"""
from __future__ import annotations

from collections import Counter

import numpy as np

from ..errors import PatternError
from ..pattern import CreasePattern
from .conventions import note

#: Most pairs of segments that meet or cross (each a vertex to node; Origami
#: Simulator's library has at most 16 782, and noding 10⁵ takes about 2 s).
MAX_MEETINGS = 100_000
#: Most pairs of noded points closer than the merge distance (a few per T-join or
#: crossing in a drawing; many lines through one point crowd there by the million).
MAX_CLOSE_PAIRS = 1_000_000
#: A piece lies along a segment if the sine of the angle between them is at most this
#: (a piece near a crossing is near both segments but along one).
PARALLEL = 0.1
#: A segment a piece lies along covers at least this share of it (projected on the
#: piece's line): a collinear neighbour, which the merging of ends on the grid can
#: bring within reach, only meets it at an end.
COVERED = 0.5
#: Which of two crease types drawn over each other Origami Simulator keeps: the one
#: its SVG reader lists first (it reads borders, then mountains, valleys, facet
#: lines, hinges and cuts, and drops the later of two equal edges).
OVERLAP_ORDER = ("B", "M", "V", "F", "U", "C")
#: Times the merged drawing is noded again where a merge moved a vertex across an edge.
RENODING_PASSES = 3


def pattern_from_lines(segments: np.ndarray, kinds, angles, owners, source: str, *,
                       tol: float, factor: float = 1.0, where=None,
                       sides_as_origami_simulator: bool = False,
                       numbering=None, with_drawn: bool = False):
    """The crease pattern of a line drawing (module docstring).

    Parameters
    ----------
    segments : (S, 2, 2) float
        Straight segments, the file's units.
    kinds, angles, owners : sequences of length S
        Crease type (``M V B F U``), target angle (degrees, NaN: none), owner name.
    source : str
        The file, for messages.
    tol : float
        Snap and merge distance, the file's units.
    factor : float
        mm per file unit.
    where : callable(x, y) -> str, optional
        A place in the file's words, for messages (default ``(x, y)``).
    sides_as_origami_simulator : bool
        Lines whose type contradicts their sides, and lines of different types or
        angles drawn over each other, read as Origami Simulator reads them
        (:func:`sides_read_as_origami_simulator`; :data:`OVERLAP_ORDER`) instead
        of refused.
    numbering : (S,) int, optional
        The order of the segments whose endpoints number the vertices
        (:func:`in_drawing_order`; default the file's).
    with_drawn : bool
        Return (pattern, drawn) instead: ``drawn`` (V, 2) mm, each vertex of the
        pattern at the point Origami Simulator keeps of its cluster before merging
        (the last drawn; :func:`in_drawing_order`; copies along a cut as their
        vertex).

    Returns
    -------
    CreasePattern, or (CreasePattern, (V, 2) float) with ``with_drawn``
    """
    vertices, edges, pieces, drawn = planarise(segments, tol, source, numbering)
    extra = {} if where is None else {"where": where}
    overlaps = Counter() if sides_as_origami_simulator else None
    assignments, fold_angles = piece_types(pieces, edges, vertices, segments, kinds,
                                           angles, owners, tol, source, overlaps=overlaps,
                                           **extra)
    if overlaps:
        note(source, f"{sum(overlaps.values())} pieces drawn as two crease types or angles "
                     f"read as the first in Origami Simulator's order "
                     f"({' '.join(OVERLAP_ORDER)}, then file order): "
                     + ", ".join(f"{k} over {v}" for (k, v) in sorted(overlaps)))
    if sides_as_origami_simulator:
        used, edges, assignments, fold_angles = sides_read_as_origami_simulator(
            vertices, edges, assignments, fold_angles, source)
        vertices, drawn = vertices[used], drawn[used]
    pattern = CreasePattern(vertices * factor, edges, assignments, fold_angles=fold_angles,
                            source=source)
    if not with_drawn:
        return pattern
    drawn = drawn * factor
    return pattern, np.concatenate([drawn, drawn[pattern.copied_from]])


def sides_read_as_origami_simulator(vertices, edges, assignments, fold_angles, source: str):
    """(kept vertex ids, edges, assignments, fold_angles) with the lines whose type
    contradicts their sides read as Origami Simulator reads them, each kind said once with a
    count: a crease (M, V, F, U) with the sheet on one side only is boundary (B: no
    face to fold against), a boundary line (B) with the sheet on both sides is a free
    hinge (U: a bar without a spring). Lines with the sheet on neither side (drawn
    outside it, or in a hole) fold nothing and are left out, with the vertices only
    they reach."""
    from ..planar import derive_face_loops, loop_starts, next_in_loop

    assignments = np.array(assignments, dtype="<U1")
    fold_angles = np.array(fold_angles, dtype=float)
    flat, lengths = derive_face_loops(vertices, edges, assignments == "B", source)
    following = next_in_loop(loop_starts(lengths), lengths)
    n = len(vertices)
    edge_keys = np.minimum(edges[:, 0], edges[:, 1]) * n + np.maximum(edges[:, 0], edges[:, 1])
    side_keys = np.minimum(flat, flat[following]) * n + np.maximum(flat, flat[following])
    by_key = np.argsort(edge_keys)
    per_edge = np.bincount(by_key[np.searchsorted(edge_keys[by_key], side_keys)],
                           minlength=len(edges))
    lone = np.flatnonzero((per_edge == 1) & (assignments != "B"))
    inner = np.flatnonzero((per_edge == 2) & (assignments == "B"))
    outside = per_edge == 0
    if outside.any():
        note(source, f"{int(outside.sum())} lines with the sheet on neither side (edge "
                     f"{int(np.argmax(outside))}, …) left out: drawn outside the sheet, they "
                     "fold nothing")
    if len(lone):
        note(source, f"{len(lone)} creases with the sheet on one side only (edge "
                     f"{int(lone[0])}, …) read as boundary, as Origami Simulator reads them")
        assignments[lone], fold_angles[lone] = "B", np.nan
    if len(inner):
        note(source, f"{len(inner)} boundary lines with the sheet on both sides (edge "
                     f"{int(inner[0])}, …) read as free hinges (U), as Origami Simulator "
                     "folds them")
        assignments[inner], fold_angles[inner] = "U", np.nan
    if not outside.any():
        return np.arange(len(vertices)), edges, assignments, fold_angles
    used, ends = np.unique(edges[~outside], return_inverse=True)
    return used, ends.reshape(-1, 2), assignments[~outside], fold_angles[~outside]


def check_meetings(segments: np.ndarray, source: str) -> None:
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



def planarise(segments: np.ndarray, tol: float, source: str = "<segments>", numbering=None):
    """(V, 2) vertices, (E, 2) edges, the (E, 2, 2) noded pieces of the segments and
    the (V, 2) vertices as drawn: endpoints snapped onto nearby segments, near
    coordinates merged, crossings and overlaps noded (shapely's unary union);
    vertices numbered as the segments in ``numbering``'s order reach them
    (:func:`in_drawing_order`)."""
    from ..planar import crossing_pairs

    drawn = segments
    segments = _snap_endpoints(segments, tol)
    vertices, edges, pieces = _node_and_merge(segments, tol, source)
    for _ in range(RENODING_PASSES):  # a merge moved a vertex across an edge: node again
        if not crossing_pairs(vertices, edges):
            break
        vertices, edges, pieces = _node_and_merge(vertices[edges], tol, source)
    order = slice(None) if numbering is None else numbering
    vertices, edges, drawn = in_drawing_order(vertices, edges, segments[order], tol,
                                              drawn[order])
    return vertices, edges, pieces, drawn


def _node_and_merge(segments: np.ndarray, tol: float, source: str):
    """(vertices, edges, pieces) of :func:`planarise`: the segments noded (shapely's
    unary union), points within ``tol`` merged, pieces merged to nothing dropped."""
    import shapely

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


def in_drawing_order(vertices: np.ndarray, edges: np.ndarray, segments: np.ndarray,
                     tol: float, drawn: np.ndarray):
    """(vertices, edges, drawn) renumbered in the order the drawing first reaches each
    vertex (the segments' endpoints in their order; crossings after them, as they
    were), as Origami Simulator numbers them: the diagonal a thin sheet cuts a square
    along follows the numbering (:func:`foldcore.sheet.build.face_triangles`).
    ``drawn`` (V, 2): the endpoint that last reaches each vertex as drawn (in the
    given ``drawn`` segments, (S, 2, 2): ``segments`` before snapping), before
    merging — the point Origami Simulator keeps of a cluster (its
    ``collapseNearbyVertices`` numbers a cluster by its first point and keeps the
    coordinates of its last) — or the vertex itself."""
    from scipy.spatial import cKDTree

    distance, nearest = cKDTree(vertices).query(segments.reshape(-1, 2))
    first = np.full(len(vertices), len(nearest), dtype=np.int64)
    reached = distance <= tol
    np.minimum.at(first, nearest[reached], np.flatnonzero(reached))
    order = np.lexsort((np.arange(len(vertices)), first))
    new_id = np.empty(len(vertices), dtype=np.int64)
    new_id[order] = np.arange(len(vertices))
    ends = drawn.reshape(-1, 2)
    last = np.full(len(vertices), -1, dtype=np.int64)
    np.maximum.at(last, nearest[reached], np.flatnonzero(reached))
    drawn = np.where((last >= 0)[:, None], ends[last], vertices)
    return vertices[order], new_id[edges], drawn[order]


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
                           f"merge distance {tol:g} of each other (more than "
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


def piece_types(pieces, edges, vertices, segments, kinds, angles, owners, tol, source,
                where=lambda x, y: f"({x:g}, {y:g})", overlaps=None):
    """Each piece's assignment and target: those of the segments it lies along — its
    midpoint within ``tol`` and both ends within 2 ``tol`` of the segment, and its
    direction within ``PARALLEL`` (sine) of the segment's; two different ones are
    refused (``where(x, y)``: the place in the file's words), or with ``overlaps``
    (a Counter) the first in :data:`OVERLAP_ORDER`, then in file order, is kept as
    Origami Simulator keeps it, and (kept, dropped) counted. A piece near a crossing
    is also near the crossing segment but not along it; a short piece whose merged
    ends turned it by more is typed by the segment closest to its direction, one
    whose ends merged farther by the nearest segment."""
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
    covers = _covered_share(ends[piece_ids], segments[seg_ids]) >= COVERED
    assignment = np.full(len(pieces), "", dtype="<U1")
    target = np.full(len(pieces), np.nan)
    owner = [None] * len(pieces)
    for p in np.unique(piece_ids):
        mine = np.flatnonzero(piece_ids == p)
        parallel = mine[sine[mine] <= PARALLEL]
        covering = parallel[covers[parallel]]  # not a collinear neighbour that ends at it
        chosen = (covering if len(covering) else parallel if len(parallel)
                  else mine[[int(np.argmin(sine[mine]))]])
        for s in seg_ids[chosen]:
            same = assignment[p] == kinds[s] and (np.isnan(target[p]) and np.isnan(angles[s])
                                                  or target[p] == angles[s])
            if owner[p] is None:
                assignment[p], target[p], owner[p] = kinds[s], angles[s], owners[s]
                first = s
            elif not same and overlaps is not None:
                keep, drop = sorted((first, s), key=lambda q: (_rank(kinds[q]), q))
                overlaps[(kinds[keep], kinds[drop])] += 1
                assignment[p], target[p], owner[p] = kinds[keep], angles[keep], owners[keep]
                first = keep
            elif not same:
                raise PatternError(f"{source}: {owners[s]} and {owner[p]} overlap with "
                                   f"different crease types or angles ({kinds[s]} and "
                                   f"{assignment[p]}) near {where(*vertices[edges[p, 0]])}")
    for p in [q for q, o in enumerate(owner) if o is None]:  # its ends merged far off
        s = int(tree.query_nearest(shapely.points(ends[p].mean(axis=0)))[0])
        assignment[p], target[p] = kinds[s], angles[s]
    return assignment.tolist(), [None if np.isnan(t) else float(t) for t in target]


def _covered_share(pieces: np.ndarray, segments: np.ndarray) -> np.ndarray:
    """(P,) the share of each piece ((P, 2, 2) ends) that its segment ((P, 2, 2)),
    projected onto the piece's line, covers: 1 for a piece cut from the segment, 0 for
    a collinear neighbour that only meets it at an end."""
    start = pieces[:, 0]
    axis = pieces[:, 1] - start
    length, unit = np.hypot(axis[:, 0], axis[:, 1]), _unit(axis)
    a = np.einsum("ij,ij->i", segments[:, 0] - start, unit)
    b = np.einsum("ij,ij->i", segments[:, 1] - start, unit)
    overlap = np.minimum(np.maximum(a, b), length) - np.maximum(np.minimum(a, b), 0.0)
    return np.clip(overlap, 0.0, None) / np.maximum(length, 1e-300)


def _rank(kind: str) -> int:
    """A crease type's place in :data:`OVERLAP_ORDER` (unknown types last)."""
    return OVERLAP_ORDER.index(kind) if kind in OVERLAP_ORDER else len(OVERLAP_ORDER)


def _unit(d: np.ndarray) -> np.ndarray:
    return d / np.maximum(np.hypot(d[:, 0], d[:, 1]), 1e-300)[:, None]


def _cross(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    return a[:, 0] * b[:, 1] - a[:, 1] * b[:, 0]
