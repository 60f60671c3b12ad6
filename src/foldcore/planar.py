"""Planar-graph helpers for crease patterns: faces from edges, edge crossings.

All coordinates are 2D (mm). Faces are returned counter-clockwise (seen from +z).

The functions are vectorised (NumPy and SciPy; crossings from a cell grid or
a shapely STRtree), so a 10⁶-vertex pattern is checked in seconds. Where a
floating-point sign is too close to call (a near-degenerate face, nearly
collinear or touching edges) they ask per-item code (``signed_area``, GEOS),
so the results are those of the one-by-one reference versions in
``tests/naive.py``; ``bench/reading.py`` measures their speed.
"""
from __future__ import annotations

from itertools import chain

import numpy as np

from .errors import PatternError

#: Relative margin of the sign tests (float error bound ≈ 1e-15; kept wide).
_SURE = 1e-9
#: Below this |value| a product may have lost its relative precision (subnormal range).
_TINY = 1e-280
#: Candidate edge pairs classified per block: as many as edges, within these bounds
#: (memory: ~200 bytes a pair, so at most ~6 MB; larger blocks are no faster).
_BLOCK_PAIRS = (1024, 32_768)
#: Smallest angle (radians) between two edges at a vertex below which the
#: crossing test checks each pair of edges sharing a vertex for overlap.
_MIN_GAP_RAD = 1e-6


def signed_area(polygon: np.ndarray) -> float:
    """Signed area (mm²) of a closed polygon, positive when counter-clockwise.

    Parameters
    ----------
    polygon : (n, 2) float array
        Vertex coordinates in order; the closing edge is implied.
    """
    x, y = polygon[:, 0], polygon[:, 1]
    return 0.5 * float(np.dot(x, np.roll(y, -1)) - np.dot(np.roll(x, -1), y))


def loop_starts(lengths: np.ndarray) -> np.ndarray:
    """(F,) int64: offset of each loop in the concatenated vertex list."""
    starts = np.zeros(len(lengths), dtype=np.int64)
    np.cumsum(lengths[:-1], out=starts[1:])
    return starts


def next_in_loop(starts: np.ndarray, lengths: np.ndarray) -> np.ndarray:
    """(N,) int64: index of the following corner of each corner's loop (wrapping);
    every loop has at least one corner."""
    nxt = np.arange(1, int(lengths.sum()) + 1, dtype=np.int64)
    nxt[starts + lengths - 1] = starts
    return nxt


def signed_areas(vertices: np.ndarray, flat: np.ndarray, lengths: np.ndarray) -> np.ndarray:
    """Signed areas (mm²) of many loops at once, each equal in sign to :func:`signed_area`.

    Parameters
    ----------
    vertices : (V, 2) float array, mm
    flat : (N,) int array
        The loops' vertex ids, concatenated.
    lengths : (F,) int array
        Vertices per loop (each ≥ 1), summing to N.

    Returns
    -------
    (F,) float array
        Areas whose sign (or zero) is certain come from the vectorised sum;
        the others are recomputed with :func:`signed_area`, so every sign and
        every zero is the one-by-one function's.
    """
    if not len(lengths):
        return np.zeros(0)
    starts = loop_starts(lengths)
    x, y = vertices[flat, 0], vertices[flat, 1]
    nxt = next_in_loop(starts, lengths)
    a, b = x * y[nxt], x[nxt] * y
    with np.errstate(all="ignore"):
        area = 0.5 * (np.add.reduceat(a, starts) - np.add.reduceat(b, starts))
        bound = np.add.reduceat(np.abs(a) + np.abs(b), starts) * (lengths * _SURE)
        unsure = ~(np.abs(area) > bound) | ~(bound > _TINY) | ~np.isfinite(bound)
    for f in np.flatnonzero(unsure):
        area[f] = signed_area(vertices[flat[starts[f]:starts[f] + lengths[f]]])
    return area


def _half_edges(vertices: np.ndarray, edges: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Next half-edge (the face on the left) and origin of each of the 2E half-edges.

    Half-edge ``h < E`` runs ``edges[h, 0] → edges[h, 1]``, ``h + E`` the other
    way. Around each vertex the outgoing half-edges are ordered by
    counter-clockwise angle (ties: edge order, as a stable sort of each
    vertex's neighbour list); the next of ``u → v`` leaves ``v`` just
    clockwise of ``v → u``.
    """
    n_edges = len(edges)
    origin = np.concatenate([edges[:, 0], edges[:, 1]])
    target = np.concatenate([edges[:, 1], edges[:, 0]])
    d = vertices[target] - vertices[origin]
    angle = np.arctan2(d[:, 1], d[:, 0])
    order = np.lexsort((np.tile(np.arange(n_edges), 2), angle, origin))
    rank = np.empty(2 * n_edges, dtype=np.int64)
    rank[order] = np.arange(2 * n_edges)
    degree = np.bincount(origin, minlength=len(vertices))
    first = np.concatenate([[0], np.cumsum(degree)[:-1]])
    twin = np.concatenate([np.arange(n_edges, 2 * n_edges), np.arange(n_edges)])
    at = rank[twin]  # position of v → u in the sorted list
    start = first[target]
    prev = start + (at - start - 1) % degree[target]
    return order[prev], origin


def _cycles(nxt: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The cycles of the permutation ``nxt``, each from its smallest member.

    Returns
    -------
    members : (H,) int64
        Half-edges cycle by cycle (cycles in order of their smallest member),
        each cycle in ``nxt`` order from its smallest member.
    lengths : (C,) int64
    """
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components

    n = len(nxt)
    if not n:
        return np.zeros(0, dtype=np.int64), np.zeros(0, dtype=np.int64)
    graph = coo_matrix((np.ones(n), (np.arange(n), nxt)), shape=(n, n))
    _, label = connected_components(graph, directed=True, connection="strong")
    head = np.full(label.max() + 1, n, dtype=np.int64)
    np.minimum.at(head, label, np.arange(n))
    # steps from each member to its cycle's last one (list ranking by pointer
    # jumping on the cycle cut before the head): log2(longest cycle) passes
    is_last = nxt == head[label]
    succ = np.where(is_last, np.arange(n), nxt)
    dist = (~is_last).astype(np.int64)
    while True:
        jump = succ[succ]
        if np.array_equal(jump, succ):
            break
        dist, succ = dist + dist[succ], jump
    lengths_by_label = np.bincount(label)
    position = lengths_by_label[label] - 1 - dist  # 0 at the head
    order = np.lexsort((position, head[label]))
    cycle_order = np.argsort(head, kind="stable")
    return order, lengths_by_label[cycle_order]


def face_cycles(vertices: np.ndarray, edges: np.ndarray) -> tuple[np.ndarray, ...]:
    """All face cycles of a plane graph without repeated edges, concatenated.

    Returns
    -------
    corners : (2E,) int64
        Vertex ids cycle by cycle, as :func:`trace_faces` lists them.
    halfedges : (2E,) int64
        The half-edge leaving each corner (edge id ``h % E``).
    lengths : (C,) int64
        Corners per cycle.
    """
    nxt, origin = _half_edges(vertices, edges)
    members, lengths = _cycles(nxt)
    return origin[members], members, lengths


def trace_faces(vertices: np.ndarray, edges: np.ndarray) -> list[np.ndarray]:
    """All face cycles of a connected plane graph, each as a vertex loop.

    Every directed edge lies on exactly one cycle, the face to its left.
    Interior faces come out counter-clockwise (positive area); the outer face
    comes out clockwise. Cycles are listed in order of their first directed
    edge in ``edges`` then ``edges`` reversed, each from that edge.

    Parameters
    ----------
    vertices : (V, 2) float array, mm
    edges : (E, 2) int array
        No edge twice and no edge from a vertex to itself (see
        :func:`has_repeats`).

    Returns
    -------
    list of (n,) int arrays
    """
    corners, _, lengths = face_cycles(vertices, edges)
    return split_loops(corners, lengths)


class Loops:
    """Vertex loops (faces) as one array of ids and the length of each loop.

    A read-only sequence of (n,) id arrays (views of ``flat``), so it goes
    wherever a list of faces does, without an array object per face.

    Parameters
    ----------
    flat : (N,) int64 array
        The loops' vertex ids, concatenated.
    lengths : (F,) int64 array
        Ids per loop, summing to N.
    """

    __slots__ = ("flat", "lengths", "_starts")

    def __init__(self, flat: np.ndarray, lengths: np.ndarray):
        self.flat, self.lengths, self._starts = flat, lengths, None

    def __len__(self) -> int:
        return len(self.lengths)

    def __getitem__(self, i):
        if isinstance(i, slice):
            return [self[k] for k in range(*i.indices(len(self)))]
        if self._starts is None:
            self._starts = loop_starts(self.lengths)
        start = int(self._starts[i])  # IndexError past the end, as a list
        return self.flat[start:start + int(self.lengths[i])]

    def __iter__(self):
        return iter(split_loops(self.flat, self.lengths))


def loops_of(faces) -> Loops:
    """Faces (a sequence of vertex-id sequences, or :class:`Loops`) as :class:`Loops`.

    Lists of Python ints and 1-D integer arrays are joined at once; anything
    else is coerced face by face with ``np.asarray(face, dtype=np.int64)``.
    """
    if isinstance(faces, Loops):
        return Loops(shared_or_copy(faces.flat, np.int64),
                     shared_or_copy(faces.lengths, np.int64))
    faces = list(faces)
    kinds = set(map(type, faces))
    if kinds <= {list, tuple} and set(map(type, chain.from_iterable(faces))) <= {int}:
        lengths = np.fromiter(map(len, faces), dtype=np.int64, count=len(faces))
        try:
            flat = np.fromiter(chain.from_iterable(faces), dtype=np.int64,
                               count=int(lengths.sum()))
        except OverflowError:  # an id beyond int64: out of range, as the slow path says
            flat = None
        if flat is not None:
            return Loops(flat, lengths)
    if not (kinds <= {np.ndarray} and all(f.ndim == 1 and f.dtype.kind in "iu" for f in faces)):
        faces = [np.asarray(face, dtype=np.int64).ravel() for face in faces]
    lengths = np.fromiter(map(len, faces), dtype=np.int64, count=len(faces))
    flat = np.concatenate(faces).astype(np.int64, copy=False) if faces \
        else np.zeros(0, dtype=np.int64)
    return Loops(flat, lengths)


def shared_or_copy(a: np.ndarray, dtype) -> np.ndarray:
    """``a`` itself if it is a read-only array of ``dtype`` that no writeable array
    holds (a reader's arrays, a pattern's: no one writes them, so they can be shared),
    else a copy of it as ``dtype``."""
    base = a.base
    if a.dtype == dtype and not a.flags.writeable and (
            base is None or isinstance(base, np.ndarray) and not base.flags.writeable):
        return a
    return a.astype(dtype)


def freeze(*arrays) -> None:
    """Make a reader's own arrays read-only, so the pattern built from them shares them
    (:func:`shared_or_copy`) instead of holding a copy beside them; other values are
    left as they are."""
    for a in arrays:
        if isinstance(a, Loops):
            freeze(a.flat, a.lengths)
        elif isinstance(a, np.ndarray):
            a.setflags(write=False)


def split_loops(flat: np.ndarray, lengths: np.ndarray) -> list[np.ndarray]:
    """``flat`` cut into consecutive pieces of ``lengths`` (views, read-only if it is)."""
    ends = np.cumsum(lengths).tolist()
    return [flat[a:b] for a, b in zip([0] + ends[:-1], ends)]


def has_repeats(edges: np.ndarray) -> bool:
    """True if an edge joins a vertex to itself or two edges join the same vertices."""
    if (edges[:, 0] == edges[:, 1]).any():
        return True
    lo, hi = edges.min(axis=1), edges.max(axis=1)
    key = lo * (int(edges.max()) + 1) + hi
    return len(np.unique(key)) < len(key)


def derive_faces(vertices: np.ndarray, edges: np.ndarray, boundary: np.ndarray,
                 source: str) -> list[np.ndarray]:
    """Panels of a connected crease pattern, derived from its planar graph.

    The outer face (clockwise) is dropped, and so are holes: counter-clockwise
    cycles made only of boundary edges that have a panel on their other side.

    Parameters
    ----------
    vertices : (V, 2) float array, mm
    edges : (E, 2) int array
        No edge twice, none from a vertex to itself (:func:`has_repeats`).
    boundary : (E,) bool array
        True for edges assigned ``B``.
    source : str
        Name used in error messages.

    Returns
    -------
    list of (n,) int64 arrays
        Counter-clockwise vertex loops, in :func:`trace_faces` order.
    """
    return split_loops(*derive_face_loops(vertices, edges, boundary, source))


def derive_face_loops(vertices: np.ndarray, edges: np.ndarray, boundary: np.ndarray,
                      source: str) -> tuple[np.ndarray, np.ndarray]:
    """:func:`derive_faces` as (N,) concatenated vertex ids and (F,) loop lengths."""
    corners, halfedges, lengths = face_cycles(vertices, edges)
    areas = signed_areas(vertices, corners, lengths)
    edge_of = halfedges % max(len(edges), 1)
    cycle_of = np.repeat(np.arange(len(lengths)), lengths)
    outer = np.zeros(len(edges), dtype=bool)
    outer[edge_of[areas[cycle_of] < 0]] = True
    boundary = np.asarray(boundary, dtype=bool)
    not_hole_side = ~boundary[edge_of] | outer[edge_of]
    is_hole = np.bincount(cycle_of, weights=not_hole_side, minlength=len(lengths)) == 0
    keep = (areas > 0) & ~is_hole
    flat, kept = corners[keep[cycle_of]], lengths[keep]
    if np.count_nonzero(areas < 0) > 1:
        _check_pieces_apart(vertices, flat, kept, source)
    return flat, kept


def _check_pieces_apart(vertices, flat, lengths, source: str) -> None:
    """PatternError naming a vertex inside a face (loops ``flat``, ``lengths``) of another
    piece (drawn over each other); a piece in another's hole is apart from it."""
    import shapely

    face_of = np.repeat(np.arange(len(lengths)), lengths)
    tree = shapely.STRtree(shapely.polygons(shapely.linearrings(vertices[flat], indices=face_of)))
    inside, face = tree.query(shapely.points(vertices), predicate="within")
    if len(inside):
        k = int(np.argmin(inside))
        raise PatternError(f"{source}: vertex {int(inside[k])} lies inside another piece, "
                           f"in its face {int(face[k])} (pieces drawn over each other)")


def crossing_pairs(vertices: np.ndarray, edges: np.ndarray) -> list[tuple[int, int]]:
    """Pairs of edges that cross, overlap, or touch other than at a shared end.

    The pairs whose bounding boxes meet come from a uniform grid of cells
    one edge wide (NumPy; a mesh of similar-sized edges), or from a shapely
    STRtree when the edge sizes vary too much for it; both are near-linear in
    the number of edges. Orientation signs with an error margin settle almost
    all of them at once, and GEOS decides the few too close to call (exactly
    as the one-pair-at-a-time test in ``tests/naive.py``).

    Parameters
    ----------
    vertices : (V, 2) float array, mm
    edges : (E, 2) int array
        No zero-length edge and no edge twice.

    Returns
    -------
    list of (i, j) with i < j, sorted
    """
    crowded = _crowded_vertices(vertices, edges)
    bad = []
    for left, right in box_pairs(vertices, edges):
        bad += _bad_pairs(vertices, edges, left, right, crowded)
    return sorted(bad)


def box_pairs(vertices: np.ndarray, edges: np.ndarray):
    """Blocks ``(left, right)`` of all edge pairs ``left < right`` whose (closed)
    bounding boxes meet, each pair once; see :func:`crossing_pairs`."""
    p, q = vertices[edges[:, 0]], vertices[edges[:, 1]]
    lo, hi = np.minimum(p, q), np.maximum(p, q)
    del p, q
    plan = _grid_plan(lo, hi)
    block = min(max(len(edges), _BLOCK_PAIRS[0]), _BLOCK_PAIRS[1])
    if plan is None:
        del lo, hi
        yield from _tree_pairs(vertices, edges, block)
        return
    order, starts, counts, links = plan
    # boxes in cell order, one contiguous array per side (cheap gathers)
    x0, y0, x1, y1 = (np.ascontiguousarray(c[order]) for c in (lo[:, 0], lo[:, 1],
                                                               hi[:, 0], hi[:, 1]))
    del lo, hi  # held while the blocks are classified
    for cells in _grid_blocks(counts, links, block):
        yield _meeting((x0, y0, x1, y1), order, starts, counts, *cells)


def _meeting(boxes, order, starts, counts, here, there, n, same):
    """(left, right): the pairs of edges of one block of linked cells (``here[k]`` with
    ``there[k]``, ``n[k]`` pairs) whose boxes meet, as edge ids, left < right; the
    block's temporaries are freed on return, before its pairs are classified."""
    x0, y0, x1, y1 = boxes
    pair = np.repeat(np.arange(len(n)), n)
    rank = np.arange(int(n.sum())) - np.repeat(np.cumsum(n) - n, n)
    width = counts[there][pair]
    a, b = starts[here][pair] + rank // width, starts[there][pair] + rank % width
    del pair, rank, width
    meet = np.flatnonzero((x0[a] <= x1[b]) & (x0[b] <= x1[a]) & (a < b if same else True))
    a, b = a[meet], b[meet]
    meet = (y0[a] <= y1[b]) & (y0[b] <= y1[a])
    a, b = order[a[meet]], order[b[meet]]
    return np.minimum(a, b), np.maximum(a, b)


def _tree_pairs(vertices, edges, pairs: int):
    import shapely

    lines = shapely.linestrings(vertices[edges])
    tree = shapely.STRtree(lines)
    block = max(1, pairs // 16)  # ~16 box neighbours per edge on a mesh
    for s in range(0, len(edges), block):
        left, right = tree.query(lines[s:s + block])
        left += s
        keep = left < right
        yield left[keep], right[keep]


#: Cell offsets that reach every neighbouring cell once (with the cell itself).
_HALF_NEIGHBOURS = ((0, 0), (1, -1), (1, 0), (1, 1), (0, 1))
#: The grid is used while it yields at most this many candidate pairs per edge.
_GRID_PAIRS_PER_EDGE = 40


def _grid_plan(lo: np.ndarray, hi: np.ndarray):
    """Edges sorted into square cells a little wider than the widest edge box.

    Each edge sits in the cell of its box's lower-left corner; boxes that meet
    then sit in the same or adjacent cells. Returns (order, cell starts,
    counts, [(cells, neighbour cells) per offset]), or None when that would
    give more than :data:`_GRID_PAIRS_PER_EDGE` candidates per edge (edges of
    very different sizes) or too many cells.
    """
    size = 1.01 * float((hi - lo).max())
    origin = lo.min(axis=0)
    with np.errstate(all="ignore"):
        span = (hi.max(axis=0) - origin) / size
    if not (size > 0 and np.isfinite(span).all() and span.max() < 1e9):
        return None
    ij = np.floor((lo - origin) / size).astype(np.int64) + 1
    rows = int(ij[:, 1].max()) + 2
    key = ij[:, 0] * rows + ij[:, 1]
    order = np.argsort(key, kind="stable")
    cells, starts, counts = np.unique(key[order], return_index=True, return_counts=True)
    links, total = [], 0
    for di, dj in _HALF_NEIGHBOURS:
        target = cells + di * rows + dj
        at = np.minimum(np.searchsorted(cells, target), len(cells) - 1)
        found = np.flatnonzero(cells[at] == target)
        links.append((found, at[found], (di, dj) == (0, 0)))
        total += int((counts[found] * counts[at[found]]).sum())
    if total > _GRID_PAIRS_PER_EDGE * len(lo):
        return None
    return order, starts, counts, links


def _grid_blocks(counts, links, block: int):
    """(here, there, pairs per cell pair, same cell): the linked cells in blocks of
    about ``block`` edge pairs (:func:`_meeting` lists a block's pairs)."""
    for here, there, same in links:
        n = counts[here] * counts[there]
        ends = np.cumsum(n)
        cuts = np.searchsorted(ends, np.arange(block, int(ends[-1]) if len(n) else 0, block))
        for h, t, k in zip(np.split(here, cuts), np.split(there, cuts), np.split(n, cuts)):
            yield h, t, k, same


def _crowded_vertices(vertices: np.ndarray, edges: np.ndarray) -> np.ndarray | None:
    """(V,) bool: the vertices where two edges leave less than :data:`_MIN_GAP_RAD` apart,
    or None if an edge direction is not finite (then every vertex counts as crowded).

    Two edges that share a vertex overlap only if they leave it in exactly the same
    direction, so only pairs sharing a crowded vertex need the pair test (found in
    O(E log E); a grid with one such vertex checks its pairs there, not all of them:
    docs/architecture.md#crossing-test-at-crowded-vertices).
    """
    n_edges = len(edges)
    origin = np.concatenate([edges[:, 0], edges[:, 1]])
    d = vertices[np.concatenate([edges[:, 1], edges[:, 0]])] - vertices[origin]
    with np.errstate(all="ignore"):
        angle = np.arctan2(d[:, 1], d[:, 0])
    if not np.isfinite(angle).all():
        return None
    order = np.lexsort((angle, origin))
    origin, angle = origin[order], angle[order]
    crowded = np.zeros(len(vertices), dtype=bool)
    same = origin[1:] == origin[:-1]
    crowded[origin[1:][same & (np.diff(angle) < _MIN_GAP_RAD)]] = True
    # around each vertex of degree ≥ 2: from its last edge back to its first
    first = np.flatnonzero(np.concatenate([[True], ~same]))
    last = np.concatenate([first[1:], [2 * n_edges]]) - 1
    many = last > first
    wrap = angle[first[many]] + 2 * np.pi - angle[last[many]]
    crowded[origin[first[many]][wrap < _MIN_GAP_RAD]] = True
    return crowded


def _bad_pairs(vertices, edges, left, right, crowded) -> list[tuple[int, int]]:
    """Which of the box-overlapping pairs ``left[k] < right[k]`` meet illegally
    (``crowded``: where pairs sharing a vertex can overlap, :func:`_crowded_vertices`)."""
    import shapely

    u, v = edges[:, 0], edges[:, 1]
    ul, vl, ur, vr = u[left], v[left], u[right], v[right]
    shared = (ul == ur) | (ul == vr) | (vl == ur) | (vl == vr)
    apart = np.flatnonzero(~shared)
    a = np.stack([ul[apart], vl[apart]], axis=1)
    b = np.stack([ur[apart], vr[apart]], axis=1)
    sure_bad, unsure = _classify_apart(vertices, a, b)
    bad = [apart[sure_bad]]
    def lines(ids):  # geometries only for the few pairs GEOS decides
        return shapely.linestrings(vertices[edges[ids]])

    hit = shapely.intersects(lines(left[apart[unsure]]), lines(right[apart[unsure]]))
    bad.append(apart[unsure][hit])
    # sharing an end: only that end point may be common (GEOS decides the
    # nearly collinear, same-direction pairs, the only ones that can overlap)
    if crowded is not None:  # only pairs sharing a crowded vertex can overlap
        common = np.where((ul == ur) | (ul == vr), ul, vl)
        shared &= crowded[common]
    shared = np.flatnonzero(shared)
    if not len(shared):
        return _pair_list(left, right, bad)
    a, b = edges[left[shared]], edges[right[shared]]
    # the two edges leave the common vertex in the same sense iff both start or
    # both end there
    flip = (a[:, 0] == b[:, 0]) | (a[:, 1] == b[:, 1])
    maybe = shared[_maybe_overlapping(vertices, a, b, flip)]
    inter = shapely.intersection(lines(left[maybe]), lines(right[maybe]))
    bad.append(maybe[shapely.get_type_id(inter) != 0])
    return _pair_list(left, right, bad)


def _pair_list(left, right, picks: list) -> list[tuple[int, int]]:
    k = np.concatenate(picks)
    return list(zip(left[k].tolist(), right[k].tolist()))


def _orient(p, q, r) -> tuple[np.ndarray, np.ndarray]:
    """Orientation determinant of (p, q, r) per row, and an error margin for its sign."""
    u, w = q - p, r - p
    s, t = u[:, 0] * w[:, 1], u[:, 1] * w[:, 0]
    return s - t, _SURE * (np.abs(s) + np.abs(t))


def _sign(det: np.ndarray, margin: np.ndarray) -> np.ndarray:
    """+1 / −1 where the sign of ``det`` is certain, 0 where it is not."""
    sure = (np.abs(det) > margin) & (margin > _TINY) & np.isfinite(margin)
    return np.where(sure, np.sign(det), 0.0)


def _classify_apart(vertices, a, b) -> tuple[np.ndarray, np.ndarray]:
    """Pairs of edges with no common vertex: (surely crossing, too close to call).

    Surely apart: both ends of one edge surely on the same side of the
    other's line (tested for ``b`` against ``a`` first, which settles most).
    """
    p, q = vertices[a[:, 0]], vertices[a[:, 1]]
    r, s = vertices[b[:, 0]], vertices[b[:, 1]]
    with np.errstate(all="ignore"):
        o1, o2 = _sign(*_orient(p, q, r)), _sign(*_orient(p, q, s))
        rest = np.flatnonzero(~((o1 == o2) & (o1 != 0)))
        p, q, r, s = p[rest], q[rest], r[rest], s[rest]
        o1, o2 = o1[rest], o2[rest]
        o3, o4 = _sign(*_orient(r, s, p)), _sign(*_orient(r, s, q))
    apart = (o3 == o4) & (o3 != 0)
    crossing = (o1 * o2 < 0) & (o3 * o4 < 0)
    sure_bad = np.zeros(len(a), dtype=bool)
    unsure = np.zeros(len(a), dtype=bool)
    sure_bad[rest[crossing]] = True
    unsure[rest[~apart & ~crossing]] = True
    return sure_bad, unsure


def _maybe_overlapping(vertices, a, b, same_sense) -> np.ndarray:
    """Pairs of edges sharing a vertex: not surely meeting only there.

    ``same_sense`` is True where both edges start, or both end, at the common
    vertex (their direction vectors then point the same way from it).
    """
    da = vertices[a[:, 1]] - vertices[a[:, 0]]
    db = vertices[b[:, 1]] - vertices[b[:, 0]]
    with np.errstate(all="ignore"):
        s, t = da[:, 0] * db[:, 1], da[:, 1] * db[:, 0]
        collinear = _sign(s - t, _SURE * (np.abs(s) + np.abs(t))) == 0
        s, t = da[:, 0] * db[:, 0], da[:, 1] * db[:, 1]
        dot = _sign(s + t, _SURE * (np.abs(s) + np.abs(t)))
    opposite = np.where(same_sense, dot < 0, dot > 0)
    return collinear & ~opposite
