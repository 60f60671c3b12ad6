"""The solids that touch: every rigid panel's closed prism and every crease's hinge
strip, which of them are joined, and a part-level broad phase that proves most
pairs apart without a narrow phase.

A panel is a prism: its top loop, the same loop H lower, and side quads, all
vertices its own (the rigid-body layout checks that panels share none). A
crease's hinge strip is the outer surface of its sub-strips' prisms (top,
bottom and the ends; not the faces it shares with its panels or between its
sub-strips). Two panels are *joined* when a crease's hinge strip connects
them: near their crease the hinge model decides how they meet, and at a flat
fold they touch face to face by design, so contact sees them trimmed of a
hinge zone and a hair thinner (:class:`JoinedZones`). A strip and a part
that meet at a vertex of the pattern (its crease's panels, the panels and
strips around its end points) are left to the hinges: there the thickened
sheet's strips and panel corners overlap by construction, as the hinge model
places them. Every other pair is a contact candidate as it is.

The broad phase has two stages, both in numba (:mod:`.kernels`): axis-aligned
boxes (within a margin, sweep and prune), then a separating-axis bound: the gap
between the two panels' vertex intervals along their normals, the bisectors
of those and the line between their centroids. That bound is a lower bound
of the true distance, so a pair it proves farther than the
margin cannot touch. Units: mm.
"""
from __future__ import annotations

import numpy as np

from ..mesh import prism_face_loops
from ..triangulation import triangulate_polygons
from . import kernels


class PartSolids:
    """Every rigid panel of a thick mesh as a closed triangulated prism, then every
    crease's hinge strip as its outer surface: the parts contact keeps apart.

    Parameters
    ----------
    mesh : foldcore.mesh.ThickMesh
    pattern : foldcore.pattern.CreasePattern

    Attributes
    ----------
    n_panels : int
        Parts 0 … n_panels − 1 are the panels (panel element p is part p).
    n_parts : int
        Panels, then strips.
    part_crease : (n_parts,) int64
        The crease of each strip part (−1 for a panel).
    vertices : (n,) int64
        Model vertex ids of every part: a panel's corners (top loop, then
        bottom), a strip's surface vertices (top, then bottom), part by part.
    ptr : (n_parts + 1,) int64
        Part p's vertices are ``vertices[ptr[p]:ptr[p + 1]]``.
    triangles : list of (T_p, 3) int32
        Each part's outward surface triangles, indices local to its vertices.
    joined : (J,) int64
        Sorted codes a · n_parts + b (a < b) of the panel pairs a crease joins.
    joined_pairs : (J, 2) int64
        The joined pairs themselves (a < b).
    left_out : (L,) int64
        Sorted codes of the joined pairs and of the strip pairs that meet at a
        vertex of the pattern: the pairs the broad phase never returns.
    """

    def __init__(self, mesh, pattern):
        group = mesh.groups.get(mesh.panel_group)
        self.n_panels = len(group) if group is not None else 0
        rest = mesh.rest_positions  # a property that builds the array anew
        ids = [_corners(group.indices[group.slots(p)], rest) for p in range(self.n_panels)]
        triangles = self._triangles(mesh, ids)
        creases, strip_ids, strip_triangles = _strips(mesh)
        self.n_parts = self.n_panels + len(creases)
        self.part_crease = np.concatenate([np.full(self.n_panels, -1), creases]).astype(np.int64)
        ids += strip_ids
        sizes = np.array([len(i) for i in ids], dtype=np.int64)
        self.vertices = np.concatenate(ids).astype(np.int64) if ids else np.zeros(0, np.int64)
        self.ptr = np.concatenate([[0], np.cumsum(sizes)]).astype(np.int64)
        self.triangles = triangles + strip_triangles
        self.joined = self._joined(mesh, pattern)
        self.left_out = np.union1d(self.joined, self._meeting(mesh, pattern))

    def _meeting(self, mesh, pattern) -> np.ndarray:
        """Sorted codes of the pairs of a strip and another part that meet at a vertex
        of the pattern or share a model vertex."""
        faces = pattern.faces
        sizes = np.array([len(f) for f in faces], dtype=np.int64)
        strips = np.arange(self.n_panels, self.n_parts)
        part = np.concatenate([np.repeat(mesh.panel_of_face[:len(faces)], sizes),
                               np.repeat(strips, 2),
                               np.repeat(np.arange(self.n_parts), np.diff(self.ptr))])
        key = np.concatenate([np.concatenate(faces).astype(np.int64) if len(faces) else [],
                              pattern.edges[self.part_crease[strips]].ravel(),
                              len(pattern.vertices) + self.vertices]).astype(np.int64)
        return _pairs_sharing(key, part.astype(np.int64), self.n_panels, self.n_parts)

    def _triangles(self, mesh, ids) -> list:
        """Outward triangles of each prism, local vertex indices."""
        n_top = len(mesh.points)
        caps = []
        for panel_ids in ids:
            for loop, is_cap in prism_face_loops(np.arange(len(panel_ids))):
                if is_cap:
                    caps.append(mesh.points[panel_ids[loop] % n_top])
        cap_tris = triangulate_polygons(caps)
        out = []
        for p, panel_ids in enumerate(ids):
            tris = []
            for loop, is_cap in prism_face_loops(np.arange(len(panel_ids))):
                tris.append(loop[cap_tris.pop(0)] if is_cap else loop[[[0, 1, 2], [0, 2, 3]]])
            out.append(np.ascontiguousarray(np.vstack(tris), dtype=np.int32))
        return out

    def _joined(self, mesh, pattern) -> np.ndarray:
        creases = np.array(sorted(mesh.strips_of_crease), dtype=np.int64)
        if not len(creases):
            self.joined_pairs = np.zeros((0, 2), dtype=np.int64)
            self.joined_crease = np.zeros(0, dtype=np.int64)
            return np.zeros(0, dtype=np.int64)
        left, right = mesh.measuring_panels(pattern, creases)
        a, b = np.minimum(left, right), np.maximum(left, right)
        codes, first = np.unique(a * self.n_parts + b, return_index=True)
        self.joined_pairs = np.column_stack([codes // self.n_parts, codes % self.n_parts])
        self.joined_crease = creases[first]
        return codes

    # ---------------------------------------------------------- geometry
    def boxes(self, x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(lo, hi), each (n_parts, 3): every part's axis-aligned box at positions x."""
        lo, hi = np.empty((self.n_parts, 3)), np.empty((self.n_parts, 3))
        kernels.boxes(_positions(x), self.vertices, self.ptr, lo, hi)
        return lo, hi

    def pairs_near(self, lo, hi, margin: float) -> np.ndarray:
        """(K, 2) part pairs (a < b, sorted), not left out (:attr:`left_out`), whose
        boxes (lo, hi), each (n_parts, 3), come within ``margin`` mm of each other.

        Sweep and prune in numba (:func:`.kernels.boxes_near`), anew per call: on a
        Miura 40 × 40 it costs about what the exact box test alone cost on a
        Verlet list kept between calls, whose rebuilds (most steps of a fold move
        the panels by more than its skin) cost ten times as much."""
        if self.n_parts < 2:
            return np.zeros((0, 2), dtype=np.int64)
        return kernels.boxes_near(np.ascontiguousarray(lo, np.float64),
                                  np.ascontiguousarray(hi, np.float64), float(margin),
                                  self.left_out)

    def gap_bounds(self, x: np.ndarray, pairs: np.ndarray, edges=None,
                   later: np.ndarray | None = None) -> np.ndarray:
        """(K,) a lower bound (mm) of each pair's distance at positions x (≤ 0: not
        proved apart): the widest gap between the two panels' vertex intervals
        along any of five axes: the panels' normals, their sum and difference
        (the bisector planes of two panels hinged together) and the line between
        their centroids (two panels side by side in one plane); given ``edges``
        (K, 2) vertex ids of an edge per pair, also the in-plane normals to it
        (two panels a crease joins, flat). A gap along any axis separates the
        panels' convex hulls, which contain the panels.

        With ``later`` positions, the bound holds for the whole straight-line
        motion x → later (axes taken at x): along a fixed axis, b's lowest point
        less a's highest is concave in the motion's parameter, so the smaller of
        its two end values bounds it, and so for a over b; the larger of those
        two bounds the gap. (The smaller of the two ends' gaps is not a bound: a
        panel that passes through the other in one step is apart at both ends.)
        In numba: :func:`.kernels.gap_bounds`."""
        out = np.empty(len(pairs))
        if len(pairs):
            x = _positions(x)
            kernels.gap_bounds(x, x if later is None else _positions(later), later is not None,
                               self.vertices, self.ptr, np.ascontiguousarray(pairs, np.int64),
                               _NO_EDGES if edges is None else
                               np.ascontiguousarray(edges, np.int64), out)
        return out

    def part_of(self, other: "PartSolids", panels: np.ndarray) -> np.ndarray:
        """(other.n_parts,) this thickening's part of each of ``other``'s (another
        thickening of the same pattern): its panel p is ``panels[p]``, its strips
        this one's strips of the same creases."""
        strip = {int(e): p for p, e in enumerate(self.part_crease) if e >= 0}
        return np.concatenate([np.asarray(panels, dtype=np.int64)[:other.n_panels],
                               [strip[int(e)] for e in other.part_crease[other.n_panels:]]]
                              ).astype(np.int64)

    def part_vertices(self, p: int) -> np.ndarray:
        """Model vertex ids of part p."""
        return self.vertices[self.ptr[p]:self.ptr[p + 1]]

    def pair_vertices(self, a: int, b: int) -> np.ndarray:
        """Model vertex ids of parts a then b."""
        return np.concatenate([self.vertices[self.ptr[a]:self.ptr[a + 1]],
                               self.vertices[self.ptr[b]:self.ptr[b + 1]]])


class JoinedZones:
    """Two panels a crease joins, as contact sees them: each without its *hinge zone*
    (a band along its side on their crease, as deep as the crease's hinge is wide)
    and with its two faces ``share`` × H closer together.

    Their hinge owns what happens near the crease: an axis hinge past its pivot
    angle turns the panels about their touching inner edges, and a hinge that
    binds at a vertex lets their corners there overlap by its misfit. Away from
    it two joined panels meet only face to face at a flat fold, where the thinned
    faces stay ``share`` × H apart. Each trimmed corner is a fixed convex
    combination of its panel's corners (a point on the neighbouring side, the
    zone's depth from the crease side's line but at most ``MAX_TRIM`` of the way
    along that side, moved toward its twin on the other face), so the geometry
    is linear in the positions: y = M x, and derivatives pull back through Mᵀ.

    Parameters
    ----------
    solids : PartSolids
    mesh : foldcore.mesh.ThickMesh
    pattern : foldcore.pattern.CreasePattern
    depths : (J,) float
        Each joined pair's zone depth, mm.
    share : float
        The faces' approach, a share of H.

    Attributes
    ----------
    pairs : (J, 2) int64
        The joined panel pairs (``PartSolids.joined_pairs``).
    ptr : (2J + 1,) int64
        Rows of y: panel a of pair k is ``ptr[2k]:ptr[2k + 1]``, its b the next run.
    matrix : (ptr[-1], N) scipy.sparse.csr_matrix
        y = matrix @ x: the trimmed corners of every pair at model positions x.
    edges : (J, 2) int64
        Rows of y of panel a's trimmed side along the crease (its in-plane normal
        separates the pair while it is flat).
    """

    MAX_TRIM = 0.25

    def __init__(self, solids: PartSolids, mesh, pattern, depths: np.ndarray, share: float):
        self.pairs = solids.joined_pairs
        self._solids = solids
        panels = self.pairs.ravel()  # side 2k: panel a of pair k, 2k + 1: its b
        sizes = np.diff(solids.ptr)[panels]
        self.ptr = np.concatenate([[0], np.cumsum(sizes)]).astype(np.int64)
        lines = pattern.vertices[pattern.edges[np.repeat(solids.joined_crease, 2)]]
        rows, cols, vals = [], [], []
        self.edges = np.zeros((len(self.pairs), 2), dtype=np.int64)
        for m in np.unique(sizes // 2):  # sides grouped by their panels' corner count
            sides = np.flatnonzero(sizes == 2 * m)
            ids = solids.vertices[solids.ptr[panels[sides]][:, None] + np.arange(2 * m)]
            i, j, t_i, t_j = _trimmed_side(mesh.rest_positions[ids[:, :m], :2], lines[sides],
                                           np.repeat(depths, 2)[sides], self.MAX_TRIM)
            r, c, v = _trim_entries(ids, i, j, t_i, t_j, share)
            rows.append(self.ptr[sides][:, None, None] + r)
            cols.append(c)
            vals.append(v)
            first = sides % 2 == 0
            self.edges[sides[first] // 2] = self.ptr[sides[first]][:, None] + \
                np.column_stack([i, j])[first]
        import scipy.sparse as sp

        n = mesh.n_vertices
        self.matrix = sp.csr_matrix((np.concatenate([v.ravel() for v in vals]),
                                     (np.concatenate([r.ravel() for r in rows]),
                                      np.concatenate([c.ravel() for c in cols]))),
                                    shape=(int(self.ptr[-1]), n)) if rows else \
            sp.csr_matrix((0, n))
        self.rest = self.matrix @ mesh.rest_positions

    def positions(self, x: np.ndarray) -> np.ndarray:
        """(ptr[-1], 3) the trimmed corners at model positions x (N, 3), mm."""
        return np.ascontiguousarray(self.matrix @ x)

    def rows(self, k: int) -> np.ndarray:
        """Rows of y of pair k's corners (panel a's, then b's)."""
        return np.arange(self.ptr[2 * k], self.ptr[2 * k + 2])

    def pair(self, k: int) -> tuple[np.ndarray, np.ndarray]:
        """(model vertex ids (n,) of pair k's corners (``PartSolids.pair_vertices``),
        (n, n) weights: its trimmed corners are weights @ x[ids])."""
        a, b = (int(p) for p in self.pairs[k])
        ids = self._solids.pair_vertices(a, b)
        return ids, self.matrix[self.rows(k)][:, ids].toarray()

    def gap_bounds(self, y: np.ndarray, which: np.ndarray) -> np.ndarray:
        """(K,) :meth:`PartSolids.gap_bounds` of the trimmed pairs ``which`` (K,) at
        trimmed positions y."""
        out = np.empty(len(which))
        if len(which):
            pairs = np.column_stack([2 * which, 2 * which + 1]).astype(np.int64)
            kernels.gap_bounds(y, y, False, np.arange(len(y), dtype=np.int64), self.ptr,
                               pairs, np.ascontiguousarray(self.edges[which]), out)
        return out


def _trimmed_side(top: np.ndarray, lines: np.ndarray, depths: np.ndarray, max_trim: float):
    """Which side of each prism loses its hinge zone, and how far its ends move.

    Parameters
    ----------
    top : (S, m, 2) float
        Each prism's top loop at rest, mm.
    lines : (S, 2, 2) float
        The crease joining it to its pair's other panel (end points, mm).
    depths : (S,) float
        The zone's depth, mm.

    Returns
    -------
    i, j : (S,) int
        The side (corners i, j = i + 1) nearest the crease line among those
        parallel to it (else the most nearly parallel).
    t_i, t_j : (S,) float
        Corner i moves this share of the way to corner i − 1, j to j + 1: to the
        zone's depth from the side's line, at most ``max_trim``.
    """
    s, m = top.shape[:2]
    d = lines[:, 1] - lines[:, 0]
    d /= np.linalg.norm(d, axis=1)[:, None]
    edge = np.roll(top, -1, axis=1) - top
    length = np.maximum(np.linalg.norm(edge, axis=2), 1e-300)
    cosine = np.abs(np.einsum("smk,sk->sm", edge, d)) / length
    mid = top + 0.5 * edge
    off = np.abs(np.einsum("smk,sk->sm", mid - lines[:, None, 0], d[:, ::-1] * [-1.0, 1.0]))
    parallel = cosine > 1.0 - 1e-6
    i = np.where(parallel.any(axis=1), np.argmin(np.where(parallel, off, np.inf), axis=1),
                 np.argmax(cosine, axis=1))
    j = (i + 1) % m
    at = np.arange(s)
    side = edge[at, i] / length[at, i][:, None]
    normal = side[:, ::-1] * [-1.0, 1.0]
    inward = top.mean(axis=1) - top[at, i]
    normal *= np.where(np.einsum("sk,sk->s", inward, normal) < 0, -1.0, 1.0)[:, None]
    reach_i = np.einsum("sk,sk->s", top[at, (i - 1) % m] - top[at, i], normal)
    reach_j = np.einsum("sk,sk->s", top[at, (j + 1) % m] - top[at, j], normal)
    t_i = np.where(reach_i > 0, np.minimum(depths / np.where(reach_i > 0, reach_i, 1.0),
                                           max_trim), 0.0)
    t_j = np.where(reach_j > 0, np.minimum(depths / np.where(reach_j > 0, reach_j, 1.0),
                                           max_trim), 0.0)
    return i, j, t_i, t_j


def _trim_entries(ids: np.ndarray, i, j, t_i, t_j, share: float):
    """(rows, cols, values), each (S, 2m, 4), of the trimmed corners of S prisms of
    m corners (ids (S, 2m): top loop, then bottom): row r (corner r mod m of face
    r // m) = (1 − share/2) × its in-plane combination on its face + share/2 × the
    same on the other face; the in-plane combination is the corner itself, except
    for corners i and j (:func:`_trimmed_side`)."""
    s, two_m = ids.shape
    m = two_m // 2
    at = np.arange(s)
    corner = np.arange(m)[None, :].repeat(s, axis=0)       # (S, m)
    toward = corner.copy()
    keep = np.ones((s, m))
    for c, step, t in ((i, -1, t_i), (j, 1, t_j)):
        toward[at, c] = (c + step) % m
        keep[at, c] = 1.0 - t
    plane_cols = np.stack([corner, toward], axis=2)         # (S, m, 2) local corners
    plane_vals = np.stack([keep, 1.0 - keep], axis=2)
    rows = np.arange(two_m)[None, :, None].repeat(s, axis=0).repeat(4, axis=2)
    cols, vals = np.empty((s, two_m, 4), dtype=np.int64), np.empty((s, two_m, 4))
    for face in (0, 1):
        rows_of_face = slice(face * m, (face + 1) * m)
        own = ids[at[:, None, None], face * m + plane_cols]  # (S, m, 2)
        other = ids[at[:, None, None], (1 - face) * m + plane_cols]
        cols[:, rows_of_face] = np.concatenate([own, other], axis=2)
        vals[:, rows_of_face] = np.concatenate([(1.0 - 0.5 * share) * plane_vals,
                                                0.5 * share * plane_vals], axis=2)
    return rows, cols, vals


def _pairs_sharing(key: np.ndarray, part: np.ndarray, n_panels: int,
                   n_parts: int) -> np.ndarray:
    """Sorted codes a · n_parts + b (a < b, one of them a strip: ≥ ``n_panels``) of the
    parts that share a key (incidences (key, part), each (K,))."""
    order = np.lexsort((part, key))
    key, part = key[order], part[order]
    codes = []
    for shift in range(1, len(key)):
        same = key[shift:] == key[:-shift]
        if not same.any():
            break
        a, b = part[:-shift][same], part[shift:][same]
        a, b = np.minimum(a, b), np.maximum(a, b)
        keep = (a < b) & (b >= n_panels)
        codes.append(a[keep] * n_parts + b[keep])
    return np.unique(np.concatenate(codes)) if codes else np.zeros(0, dtype=np.int64)


def _strips(mesh) -> tuple[np.ndarray, list, list]:
    """((C,) creases with a hinge strip, [(n_c,) model vertex ids: its surface's top
    vertices, then its bottom's], [(T_c, 3) int32 triangles, local]) of every
    crease's strip: the faces of its sub-strips' prisms that no other of its
    sub-strips shares and that do not lie on a panel (all corners one panel's)."""
    group = mesh.groups.get("bending_hinge")
    if group is None or not mesh.strips_of_crease:
        return np.zeros(0, dtype=np.int64), [], []
    owner = np.full(mesh.n_vertices, -1, dtype=np.int64)
    panels = mesh.groups.get(mesh.panel_group)
    if panels is not None:
        owner[panels.indices] = np.repeat(np.arange(len(panels)), np.diff(panels.indptr))
    n_top = len(mesh.points)
    creases, ids, triangles = [], [], []
    for e in sorted(mesh.strips_of_crease):
        loops = [loop for s in mesh.strips_of_crease[e]
                 for loop, _ in prism_face_loops(group.indices[group.slots(int(s))])]
        keys = [tuple(sorted(loop.tolist())) for loop in loops]
        kept = [loop for loop, key in zip(loops, keys)
                if keys.count(key) == 1 and not (owner[loop[0]] >= 0 and
                                                 (owner[loop] == owner[loop[0]]).all())]
        if not kept:
            continue
        used = np.unique(np.concatenate(kept))
        used = np.concatenate([used[used < n_top], used[used >= n_top]])
        local = {int(v): i for i, v in enumerate(used)}
        fans = [[local[int(loop[0])], local[int(loop[i])], local[int(loop[i + 1])]]
                for loop in kept for i in range(1, len(loop) - 1)]
        creases.append(e)
        ids.append(used.astype(np.int64))
        triangles.append(np.array(fans, dtype=np.int32))
    return np.array(creases, dtype=np.int64), ids, triangles


def _corners(ids: np.ndarray, rest: np.ndarray) -> np.ndarray:
    """A prism's vertex ids (top loop, then bottom) without the points on straight
    runs of its loop: a panel shares such points with its hinge strips, and the
    zero-area triangles they leave in a triangulation read as intersections to
    a collision check. The solid is the same."""
    n = len(ids) // 2
    top = rest[ids[:n]]
    before, after = top - np.roll(top, 1, axis=0), np.roll(top, -1, axis=0) - top
    turn = np.linalg.norm(np.cross(before, after), axis=1)
    keep = turn > 1e-9 * np.linalg.norm(before, axis=1) * np.linalg.norm(after, axis=1)
    return np.concatenate([ids[:n][keep], ids[n:][keep]])


def _positions(x: np.ndarray) -> np.ndarray:
    """x as the kernels take it: (N, 3) float64, C-contiguous (a view where it is)."""
    return np.ascontiguousarray(x, dtype=np.float64)


_NO_EDGES = np.zeros((0, 2), dtype=np.int64)

