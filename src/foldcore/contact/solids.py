"""The solids that touch: every rigid panel's closed prism, which panels are joined,
and a panel-level broad phase that proves most pairs apart without a narrow phase.

A panel is a prism: its top loop, the same loop H lower, and side quads, all
vertices its own (the rigid-body layout checks that panels share none). Two
panels are *joined* when a crease's hinge strip connects them: near their
crease the hinge model decides how they meet, and at a flat fold they touch
face to face by design, so contact sees them trimmed of a hinge zone and a
hair thinner (:class:`JoinedZones`). Every other pair is a contact candidate
as it is.

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


class PanelSolids:
    """Every rigid panel of a thick mesh as a closed triangulated prism.

    Parameters
    ----------
    mesh : foldcore.mesh.ThickMesh
    pattern : foldcore.pattern.CreasePattern

    Attributes
    ----------
    n_panels : int
    vertices : (n,) int64
        Model vertex ids of every panel's corners (top loop, then bottom), panel
        by panel.
    ptr : (n_panels + 1,) int64
        Panel p's vertices are ``vertices[ptr[p]:ptr[p + 1]]``.
    triangles : list of (T_p, 3) int32
        Each panel's outward surface triangles, indices local to its vertices.
    joined : (J,) int64
        Sorted codes a · n_panels + b (a < b) of the panel pairs a crease joins.
    joined_pairs : (J, 2) int64
        The joined pairs themselves (a < b).
    """

    def __init__(self, mesh, pattern):
        group = mesh.groups.get(mesh.panel_group)
        self.n_panels = len(group) if group is not None else 0
        ids = [_corners(group.indices[group.slots(p)], mesh.rest_positions)
               for p in range(self.n_panels)]
        sizes = np.array([len(i) for i in ids], dtype=np.int64)
        self.vertices = np.concatenate(ids).astype(np.int64) if ids else np.zeros(0, np.int64)
        self.ptr = np.concatenate([[0], np.cumsum(sizes)]).astype(np.int64)
        self.triangles = self._triangles(mesh, ids)
        self.joined = self._joined(mesh, pattern)

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
        codes, first = np.unique(a * self.n_panels + b, return_index=True)
        self.joined_pairs = np.column_stack([codes // self.n_panels, codes % self.n_panels])
        self.joined_crease = creases[first]
        return codes

    # ---------------------------------------------------------- geometry
    def boxes(self, x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(lo, hi), each (n_panels, 3): every panel's axis-aligned box at positions x."""
        lo, hi = np.empty((self.n_panels, 3)), np.empty((self.n_panels, 3))
        kernels.boxes(_positions(x), self.vertices, self.ptr, lo, hi)
        return lo, hi

    def pairs_near(self, lo, hi, margin: float) -> np.ndarray:
        """(K, 2) panel pairs (a < b, sorted), not joined, whose boxes (lo, hi), each
        (n_panels, 3), come within ``margin`` mm of each other.

        Sweep and prune in numba (:func:`.kernels.boxes_near`), anew per call: on a
        Miura 40 × 40 it costs about what the exact box test alone cost on a
        Verlet list kept between calls, whose rebuilds (most steps of a fold move
        the panels by more than its skin) cost ten times as much."""
        if self.n_panels < 2:
            return np.zeros((0, 2), dtype=np.int64)
        return kernels.boxes_near(np.ascontiguousarray(lo, np.float64),
                                  np.ascontiguousarray(hi, np.float64), float(margin),
                                  self.joined)

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

    def pair_vertices(self, a: int, b: int) -> np.ndarray:
        """Model vertex ids of panels a then b."""
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
    solids : PanelSolids
    mesh : foldcore.mesh.ThickMesh
    pattern : foldcore.pattern.CreasePattern
    depths : (J,) float
        Each joined pair's zone depth, mm.
    share : float
        The faces' approach, a share of H.

    Attributes
    ----------
    pairs : (J, 2) int64
        The joined panel pairs (``PanelSolids.joined_pairs``).
    ptr : (2J + 1,) int64
        Rows of y: panel a of pair k is ``ptr[2k]:ptr[2k + 1]``, its b the next run.
    matrix : (ptr[-1], N) scipy.sparse.csr_matrix
        y = matrix @ x: the trimmed corners of every pair at model positions x.
    edges : (J, 2) int64
        Rows of y of panel a's trimmed side along the crease (its in-plane normal
        separates the pair while it is flat).
    """

    MAX_TRIM = 0.25

    def __init__(self, solids: PanelSolids, mesh, pattern, depths: np.ndarray, share: float):
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
        """(model vertex ids (n,) of pair k's corners (``PanelSolids.pair_vertices``),
        (n, n) weights: its trimmed corners are weights @ x[ids])."""
        a, b = (int(p) for p in self.pairs[k])
        ids = self._solids.pair_vertices(a, b)
        return ids, self.matrix[self.rows(k)][:, ids].toarray()

    def gap_bounds(self, y: np.ndarray, which: np.ndarray) -> np.ndarray:
        """(K,) :meth:`PanelSolids.gap_bounds` of the trimmed pairs ``which`` (K,) at
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

