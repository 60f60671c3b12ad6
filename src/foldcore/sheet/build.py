"""A crease pattern as a bar-and-hinge sheet (:class:`Sheet`), Origami Simulator's way.

With ``merge_straight`` (Origami Simulator's reading of a drawing: it does
so for SVG files, not for FOLD files), a vertex of degree 2 whose two edges
run within about 8° of straight on (|cos + 1| < ``STRAIGHT``) and share their
assignment is left out, its two edges merged into one (its
``removeRedundantVertices``: vertex by vertex, in id order, each merge seen by
the next); the merged edge's target is the mean of its edges' non-zero ones. A vertex
whose merged edge would meet another line stays (on a curve drawn as a fine
polyline, a long chord can cut across a nearby crease's end: the face would
fold over itself; Origami Simulator merges it all the same). In
the folded sheet such a vertex lies on its merged edge where it lay in the flat
one (the same share of its length).

Each face is cut into triangles as Origami Simulator cuts it (a quadrilateral
along its shorter diagonal — shorter as drawn, for a drawing whose points the
reader merged — or on a tie the one through its lowest vertex id, which is the
one Origami Simulator's face order picks; a larger face by earcut);
the new diagonals are facet creases, held flat. Every edge is a bar; every
edge between two triangles is a hinge: a crease spring where the pattern
gives the crease a target (``M``, ``V`` or ``F``), a facet spring on a
diagonal, none on a passive crease (``U`` or no angle). Every triangle keeps
its corner angles. Stiffnesses follow Origami Simulator's conventions in its
normalised frame, where the sheet's bounding radius is 1 (:class:`Stiffness`).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..pattern import CreasePattern
from ..triangulation import segments_meet, slit_free_loops, triangulate_polygon

BAR, HINGE, TRIANGLE = 0, 1, 2
TIE = 1e-9  # diagonals of a quadrilateral this close (relative, squared) are equal
STRAIGHT = 0.01  # |cos + 1| of a degree-2 vertex's edges below which it is left out


@dataclass(frozen=True)
class Stiffness:
    """Origami Simulator's stiffnesses (its defaults), in its normalised frame.

    Attributes
    ----------
    axial : float, a bar's ``k = axial / L₀``
    crease : float, a crease's ``k = crease · L₀`` (per radian²)
    facet : float, a facet diagonal's ``k = facet · L₀`` (Origami Simulator's
        "panel stiffness")
    face : float, each corner angle's ``k`` (its "face stiffness")
    """

    axial: float = 20.0
    crease: float = 0.7
    facet: float = 0.7
    face: float = 0.2


@dataclass
class Sheet:
    """Bars, hinges and triangles of a thin sheet, in the normalised frame.

    Attributes
    ----------
    flat : (N, 3) float, the flat sheet's nodes, normalised (centred, bounding radius 1)
    vertex_ids : (N,) int, the pattern vertex of each node
    merged : (D, 3) int, the pattern vertices left out (module docstring), in the
        order they were, each with the two it lay between then
    merged_at : (D,) float, where each lay between them (share of the way)
    edge_alias : (E,) int, the pattern edge whose hinge stands for each edge (itself
        but on a merged edge)
    centre : (2,) float, mm, the pattern point at the origin
    radius : float, mm, the pattern's bounding radius (one normalised unit)
    triangles : (T, 3) int, node ids, counter-clockwise seen from +z
    triangle_face : (T,) int, the pattern face each triangle cuts
    hinges : (H, 4) int, (a, b, c, d): the hinge a → b, c left, d right
    hinge_edge : (H,) int, the pattern edge of each hinge, −1 for a diagonal
    nodes, sizes, kinds, stiffness, rest : the element arrays of
        :func:`foldcore.sheet.kernels.evaluate`; hinges are the elements
        ``hinge_elements``
    hinge_elements : (H,) int, element index of each hinge with a spring, −1 without
    constants : Stiffness, the stiffnesses the elements were made with
    """

    flat: np.ndarray
    vertex_ids: np.ndarray
    merged: np.ndarray
    merged_at: np.ndarray
    edge_alias: np.ndarray
    centre: np.ndarray
    radius: float
    triangles: np.ndarray
    triangle_face: np.ndarray
    hinges: np.ndarray
    hinge_edge: np.ndarray
    nodes: np.ndarray
    sizes: np.ndarray
    kinds: np.ndarray
    stiffness: np.ndarray
    rest: np.ndarray
    hinge_elements: np.ndarray
    constants: Stiffness

    def to_mm(self, x: np.ndarray) -> np.ndarray:
        """(V, 3) mm, every pattern vertex, from the nodes' positions ``x`` (N, 3) in
        the normalised frame; a vertex left out lies on its merged edge."""
        out = np.zeros((len(self.vertex_ids) + len(self.merged), 3))
        out[self.vertex_ids] = x * self.radius
        out[self.vertex_ids, :2] += self.centre
        for (v, a, b), t in zip(self.merged[::-1], self.merged_at[::-1]):
            out[v] = (1.0 - t) * out[a] + t * out[b]
        return out

    def from_mm(self, positions: np.ndarray) -> np.ndarray:
        """(N, 3) the nodes' positions in the normalised frame from every pattern
        vertex's ``positions`` (V, 3) mm."""
        x = np.array(np.asarray(positions, dtype=float)[self.vertex_ids])
        x[:, :2] -= self.centre
        return x / self.radius

    @property
    def pattern_triangles(self) -> np.ndarray:
        """(T, 3) int, the triangles as pattern vertex ids (for :meth:`to_mm`'s positions)."""
        return self.vertex_ids[self.triangles]


def face_triangles(xy: np.ndarray, loop: np.ndarray, face: int,
                   drawn: np.ndarray | None = None) -> np.ndarray:
    """(T, 3) vertex ids of face ``loop`` cut as Origami Simulator cuts it (n − 2
    triangles; a loop along a slit first cut in two, :func:`slit_free_loops`); a
    quadrilateral's diagonals compared on ``drawn`` (V, 2) when given (the vertices
    as drawn, :attr:`foldcore.io.FoldFile.drawing`), else on ``xy``."""
    if len(loop) == 3:
        return loop[None, :].copy()
    if len(loop) == 4:
        p = (xy if drawn is None else drawn)[loop]
        across_02, across_13 = np.sum((p[0] - p[2]) ** 2), np.sum((p[1] - p[3]) ** 2)
        if abs(across_02 - across_13) <= TIE * max(across_02, across_13):
            use_13 = int(np.argmin(loop)) % 2 == 1  # a tie: the diagonal through the lowest id
        else:
            use_13 = across_13 < across_02
        if use_13:
            return loop[np.array([[0, 1, 3], [1, 2, 3]])]
        return loop[np.array([[0, 1, 2], [0, 2, 3]])]
    return np.concatenate([part[triangulate_polygon(xy[part], face)]
                           for part in slit_free_loops(xy, loop)])


def _hinges(triangles: np.ndarray):
    """(H, 4) hinges and (B, 2) bars (every triangle side once) of a triangle mesh."""
    sides = np.concatenate([triangles[:, [0, 1]], triangles[:, [1, 2]], triangles[:, [2, 0]]])
    tips = np.concatenate([triangles[:, 2], triangles[:, 0], triangles[:, 1]])
    left = {(int(a), int(b)): int(c) for (a, b), c in zip(sides, tips)}
    hinges, bars = [], []
    for (a, b), c in left.items():
        d = left.get((b, a))
        if d is None or a < b:
            bars.append((a, b))
        if d is not None and a < b:
            hinges.append((a, b, c, d))
    return np.array(hinges, dtype=np.int64).reshape(-1, 4), np.array(bars, dtype=np.int64)


def corner_angles(p: np.ndarray) -> np.ndarray:
    """(T, 3) corner angles (radians) of triangles with points p (T, 3, 3), corner i
    between the sides to points i + 1 and i + 2."""
    out = np.empty(p.shape[:2])
    for i in range(3):
        u = p[:, (i + 1) % 3] - p[:, i]
        v = p[:, (i + 2) % 3] - p[:, i]
        out[:, i] = np.arctan2(np.linalg.norm(np.cross(u, v), axis=1),
                               np.einsum("ij,ij->i", u, v))
    return out


def tip_heights(flat: np.ndarray, hinges: np.ndarray) -> np.ndarray:
    """(H, 2) heights of each hinge's tips c and d over its line a → b in the flat
    sheet ``flat`` (N, 3), normalised units."""
    e = flat[hinges[:, 1], :2] - flat[hinges[:, 0], :2]
    length = np.maximum(np.linalg.norm(e, axis=1), 1e-300)
    r = flat[hinges[:, 2:], :2] - flat[hinges[:, :1], :2]          # (H, 2, 2)
    return np.abs(e[:, None, 0] * r[..., 1] - e[:, None, 1] * r[..., 0]) / length[:, None]


def _collapsed_hinges(flat: np.ndarray, hinges: np.ndarray) -> np.ndarray:
    """(H,) bool: a hinge one of whose triangles is lower over it than
    :data:`~.kernels.COLLAPSED` in the flat sheet (a face cut along collinear points)."""
    from .kernels import COLLAPSED

    return tip_heights(flat, hinges).min(axis=1) < COLLAPSED


@dataclass
class Merging:
    """Degree-2 vertices left out (module docstring) and what stands for their edges.

    Attributes
    ----------
    merged : (D, 3) int, each vertex left out and the two it lay between, in order
    merged_at : (D,) float, where it lay between them (share of the way)
    edge_alias : (E,) int, the edge standing for each edge (itself, or the first
        edge of its merged chain)
    edges : dict, (a, b) with a < b → the edge standing for it, every edge of the
        sheet (merged ones included)
    angles : (E,) float, degrees: each edge's target, a merged edge's the mean of
        its edges' non-zero ones (NaN if none)
    """

    merged: np.ndarray
    merged_at: np.ndarray
    edge_alias: np.ndarray
    edges: dict
    angles: np.ndarray


def merge_straight_vertices(pattern: CreasePattern, limit: float = STRAIGHT) -> Merging:
    """The :class:`Merging` of ``pattern``'s straight degree-2 vertices, Origami
    Simulator's rule: vertex by vertex in id order, a vertex with two neighbours
    (as earlier merges left them) whose edges' |cos + 1| is below ``limit`` (0:
    none), that share their assignment and whose neighbours are not joined, unless
    the merged edge would meet another edge."""
    xy = np.asarray(pattern.vertices, dtype=float)
    kinds = np.asarray(pattern.assignments)
    angles = np.asarray(pattern.fold_angles, dtype=float).copy()
    edges = {}  # (a, b), a < b → the edge standing for it
    neighbours = [dict() for _ in range(len(xy))]  # vertex → {neighbour: edge}
    for e, (a, b) in enumerate(np.asarray(pattern.edges)):
        neighbours[a][int(b)] = e
        neighbours[b][int(a)] = e
    alias = np.arange(pattern.n_edges)
    ends = np.array(pattern.edges)  # each live edge's ends as merges leave them
    live = np.ones(pattern.n_edges, dtype=bool)
    merged, merged_at = [], []
    for v in range(len(xy)):
        if len(neighbours[v]) != 2:
            continue
        (a, ea), (b, eb) = neighbours[v].items()
        u, w = xy[a] - xy[v], xy[b] - xy[v]
        cosine = float(u @ w) / max(float(np.sqrt((u @ u) * (w @ w))), 1e-300)
        if not abs(cosine + 1.0) < limit or kinds[ea] != kinds[eb] or b in neighbours[a] \
                or _chord_meets(xy, ends, live, a, b):
            continue
        ends[ea], live[eb] = (a, b), False
        both = [x for x in (angles[ea], angles[eb]) if x and not np.isnan(x)]
        angles[ea] = np.mean(both) if both else angles[ea]
        alias[alias == eb] = ea
        del neighbours[a][v], neighbours[b][v]
        neighbours[a][b], neighbours[b][a] = ea, ea
        neighbours[v] = {}
        span = xy[b] - xy[a]
        merged.append((v, a, b))
        merged_at.append(float((xy[v] - xy[a]) @ span / max(float(span @ span), 1e-300)))
    for a, near in enumerate(neighbours):
        for b, e in near.items():
            edges[(min(a, b), max(a, b))] = e
    return Merging(np.array(merged, dtype=np.int64).reshape(-1, 3), np.array(merged_at),
                   alias, edges, angles)


def _chord_meets(xy, ends, live, a: int, b: int) -> bool:
    """Whether the straight chord a–b meets a live edge (``ends``, ``live``) that does not
    end at a or b: merging the vertex between them would fold a face over itself."""
    other = live & (ends[:, 0] != a) & (ends[:, 1] != a) & (ends[:, 0] != b) & (ends[:, 1] != b)
    return bool(segments_meet(xy[a], xy[b], xy[ends[other, 0]], xy[ends[other, 1]]).any())


def build_sheet(pattern: CreasePattern, stiffness: Stiffness = Stiffness(),
                merge_straight: bool = False, drawn: np.ndarray | None = None) -> Sheet:
    """The bar-and-hinge :class:`Sheet` of ``pattern`` (module docstring); with
    ``merge_straight``, straight degree-2 vertices left out as Origami Simulator
    leaves them out of a drawing; with ``drawn`` ((V, 2) mm, the vertices as
    drawn, before a reader merged close points), each quadrilateral cut along the
    diagonal that is shorter as drawn, as Origami Simulator cuts it."""
    xy = np.asarray(pattern.vertices, dtype=float)
    lo, hi = xy.min(axis=0), xy.max(axis=0)
    centre = 0.5 * (lo + hi)
    radius = float(np.sqrt(np.max(np.sum((xy - centre) ** 2, axis=1))))
    merging = merge_straight_vertices(pattern, limit=STRAIGHT if merge_straight else 0.0)
    kept = np.ones(len(xy), dtype=bool)
    kept[merging.merged[:, 0]] = False
    vertex_ids = np.flatnonzero(kept)
    node = np.cumsum(kept) - 1  # pattern vertex → node (for kept vertices)
    flat = np.zeros((len(vertex_ids), 3))
    flat[:, :2] = (xy[vertex_ids] - centre) / radius
    cut = [node[face_triangles(xy, loop[kept[loop]], f, drawn)]
           for f, loop in enumerate(map(np.asarray, pattern.faces))]
    triangles = np.concatenate(cut)
    triangle_face = np.repeat(np.arange(len(cut)), [len(t) for t in cut])
    hinges, bars = _hinges(triangles)
    hinge_edge = np.array([merging.edges.get((vertex_ids[a], vertex_ids[b]), -1)
                           for a, b in hinges[:, :2]], dtype=np.int64)
    angles, kinds = merging.angles, np.asarray(pattern.assignments)
    targets = np.zeros(len(hinges))
    spring = np.zeros(len(hinges))  # per-length stiffness, 0: no spring
    collapsed = _collapsed_hinges(flat, hinges)
    for h, e in enumerate(hinge_edge):
        if collapsed[h]:
            continue  # no angle to spring: Origami Simulator disables it too
        if e < 0:
            spring[h] = stiffness.facet
        elif kinds[e] in ("M", "V", "F") and not np.isnan(angles[e]):
            targets[h] = np.radians(angles[e])
            spring[h] = stiffness.crease if angles[e] != 0 else stiffness.facet
    return _assemble((flat, vertex_ids, merging), centre, radius, (triangles, triangle_face),
                     hinges, hinge_edge, targets, spring, bars, stiffness)


def _assemble(nodes_of, centre, radius, cut, hinges, hinge_edge, targets, spring, bars,
              stiffness: Stiffness) -> Sheet:
    """The :class:`Sheet` with its element arrays: bars, sprung hinges, triangles
    (``cut``: the triangles and the face of each)."""
    triangles, triangle_face = cut
    flat, vertex_ids, merging = nodes_of
    length = np.linalg.norm(flat[bars[:, 1]] - flat[bars[:, 0]], axis=1)
    sprung = np.flatnonzero(spring > 0)
    hinge_length = np.linalg.norm(flat[hinges[sprung, 1]] - flat[hinges[sprung, 0]], axis=1)
    nb, nh, nt = len(bars), len(sprung), len(triangles)
    nodes = np.zeros((nb + nh + nt, 4), dtype=np.int64)
    nodes[:nb, :2] = bars
    nodes[nb:nb + nh] = hinges[sprung]
    nodes[nb + nh:, :3] = triangles
    sizes = np.repeat(np.array([2, 4, 3]), [nb, nh, nt])
    kinds = np.repeat(np.array([BAR, HINGE, TRIANGLE]), [nb, nh, nt])
    k = np.concatenate([stiffness.axial / length, spring[sprung] * hinge_length,
                        np.full(nt, stiffness.face)])
    rest = np.zeros((len(k), 3))
    rest[:nb, 0] = length
    rest[nb:nb + nh, 0] = targets[sprung]
    rest[nb + nh:] = corner_angles(flat[triangles])
    hinge_elements = np.full(len(hinges), -1, dtype=np.int64)
    hinge_elements[sprung] = nb + np.arange(nh)
    return Sheet(flat, vertex_ids, merging.merged, merging.merged_at, merging.edge_alias,
                 centre, radius, triangles, triangle_face, hinges, hinge_edge, nodes,
                 sizes, kinds, k, rest, hinge_elements, stiffness)
