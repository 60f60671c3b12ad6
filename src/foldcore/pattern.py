"""CreasePattern: a validated 2D crease pattern (first box of the data flow).

Units: coordinates, widths in mm; angles in degrees, valley positive (FOLD).
"""
from __future__ import annotations

import warnings

import numpy as np

from .errors import PatternError, PatternWarning
from .planar import (
    Loops,
    crossing_pairs,
    derive_face_loops,
    loop_starts,
    loops_of,
    next_in_loop,
    shared_or_copy,
    signed_area,
    signed_areas,
)

#: Assignments foldcore simulates. ``C`` (cut) is read and split (:mod:`foldcore.cuts`);
#: ``J`` (join) is refused.
ASSIGNMENTS = ("M", "V", "B", "F", "U")
#: Assignments a pattern is given with.
GIVEN_ASSIGNMENTS = ASSIGNMENTS + ("C",)
DEFAULT_MAX_ANGLE_DEG = 180.0
#: Largest coordinate magnitude, mm; beyond it squared lengths and areas overflow.
MAX_COORDINATE_MM = 1e100
#: Smallest sheet size (largest extent), mm; below it squared lengths and areas underflow.
MIN_EXTENT_MM = 1e-100


class CreasePattern:
    """A flat crease pattern with per-edge fold data, validated on construction.

    Parameters
    ----------
    vertices : (V, 2) array_like of float
        Vertex coordinates in the flat sheet, mm; within ±:data:`MAX_COORDINATE_MM`,
        the sheet at least :data:`MIN_EXTENT_MM` across.
    edges : (E, 2) array_like of int
        Vertex ids of each edge.
    assignments : (E,) sequence of str
        ``M`` mountain, ``V`` valley, ``B`` boundary, ``F`` flat (held at 0°),
        ``U`` unassigned (passive, either direction), ``C`` cut: the sheet is
        split along it (:mod:`foldcore.cuts`; a :class:`PatternWarning` says
        so), so the pattern then has more vertices and edges than given, and
        no ``C``.
    fold_angles : (E,) array_like of float or None, optional
        Target fold angle per edge in degrees, valley positive. ``None``/NaN
        means passive (the crease folds as the mechanism dictates). Default:
        all passive.
    widths : (E,) array_like of float or None, optional
        Hinge width per crease in mm; NaN means "choose from Eq. 7 when the
        mesh is thickened". Default: all NaN.
    max_angles : (E,) array_like of float or None, optional
        Largest fold magnitude per crease in degrees, in (0, 180]. Default 180.
    faces : sequence of (n,) int arrays, optional
        Panels as vertex loops (or :class:`foldcore.planar.Loops`). Derived from
        the planar graph when omitted. Clockwise loops are reversed with a
        :class:`PatternWarning`.
    source : str, optional
        File name (or description) used in every error message.

    NumPy arrays of the pattern's own dtypes that are already read-only (a
    reader's, another pattern's) are shared, not copied; the others are copied.

    Raises
    ------
    PatternError
        On any malformed input; the message names the offending item.
    """

    def __init__(self, vertices, edges, assignments, fold_angles=None, widths=None,
                 max_angles=None, faces=None, source: str = "<pattern>"):
        self.source = source
        self.vertices = _frozen(_as_vertices(vertices, source))
        self.edges = _frozen(_as_edges(edges, len(self.vertices), source))
        n_edges = len(self.edges)
        self.assignments = _frozen(_as_assignments(assignments, n_edges, source))
        self.fold_angles = _frozen(_per_edge(fold_angles, n_edges, np.nan, "fold_angles", source))
        self.widths = _frozen(_per_edge(widths, n_edges, np.nan, "widths", source))
        self.max_angles = _frozen(_per_edge(max_angles, n_edges, DEFAULT_MAX_ANGLE_DEG,
                                            "max_angles", source))
        self._validate_edges()
        self._validate_edge_values()
        boundary = self.assignments == "B"
        if faces is None:
            flat, lengths = derive_face_loops(self.vertices, self.edges, boundary, source)
        else:
            loops = loops_of(faces)
            flat, lengths = self._counter_clockwise(loops.flat, loops.lengths)
        self._faces = None
        self.edge_faces = _frozen(self._match_faces(flat, lengths))
        #: (V' − V,) int: the given vertex each copy made along a cut came from
        self.copied_from = np.zeros(0, dtype=np.int64)
        if (self.assignments == "C").any():
            flat = self._split_cuts(flat, lengths)
        self._loops = Loops(_frozen(flat), _frozen(lengths))

    # ----------------------------------------------------------------- queries
    @property
    def faces(self) -> tuple:
        """Panels as counter-clockwise vertex loops: a tuple of (n,) int64 arrays,
        read-only views of one array, made on first use."""
        if self._faces is None:
            self._faces = tuple(self._loops)
        return self._faces

    @property
    def face_loops(self) -> Loops:
        """The faces as one array of vertex ids and the length of each loop."""
        return self._loops

    @property
    def n_vertices(self) -> int:
        return len(self.vertices)

    @property
    def n_edges(self) -> int:
        return len(self.edges)

    @property
    def creases(self) -> np.ndarray:
        """(C,) int: ids of the edges that become hinges (every non-``B`` edge)."""
        return np.flatnonzero(self.assignments != "B")

    @property
    def actuated(self) -> np.ndarray:
        """(E,) bool: edges with a target fold angle (``F`` edges count, at 0°)."""
        return ~np.isnan(self.fold_angles) | (self.assignments == "F")

    @property
    def side_slots(self) -> np.ndarray:
        """(N,) int: the edge along each face side (the side from each corner of
        :attr:`face_loops` to the next): ``e`` where the face is on edge e's left
        (the side runs u → v), ``e + E`` where it is on its right."""
        return self._side_slots

    def edge_lengths(self) -> np.ndarray:
        """(E,) float: edge lengths in mm."""
        d = self.vertices[self.edges[:, 1]] - self.vertices[self.edges[:, 0]]
        return np.hypot(d[:, 0], d[:, 1])

    def area(self) -> float:
        """Sheet area in mm² (sum of the faces)."""
        return sum(signed_area(self.vertices[f]) for f in self.faces)

    def replace(self, **changes) -> "CreasePattern":
        """A copy with some per-edge arrays replaced (re-validated)."""
        args = dict(vertices=self.vertices, edges=self.edges, assignments=self.assignments,
                    fold_angles=self.fold_angles, widths=self.widths,
                    max_angles=self.max_angles, faces=self._loops, source=self.source)
        args.update(changes)
        out = CreasePattern(**args)
        if "vertices" not in changes:
            out.copied_from = self.copied_from
        return out

    def __repr__(self) -> str:
        counts = {a: int(np.count_nonzero(self.assignments == a)) for a in ASSIGNMENTS}
        summary = " ".join(f"{a}={n}" for a, n in counts.items() if n)
        return (f"CreasePattern({self.source!r}: {self.n_vertices} vertices, "
                f"{self.n_edges} edges [{summary}], {len(self._loops)} faces)")

    def _split_cuts(self, flat: np.ndarray, lengths: np.ndarray) -> np.ndarray:
        """Split the pattern along its ``C`` edges (:mod:`foldcore.cuts`), said in a
        warning; the renumbered face loops (``flat``, ``lengths``) in return."""
        from .cuts import cut_note, split_along_cuts

        cut = self.assignments == "C"
        split = split_along_cuts(self.vertices, self.edges, flat, lengths, self._side_slots,
                                 cut)
        twice = np.concatenate([np.arange(self.n_edges), split.second_side_of])
        assignments = np.where(cut, np.where(split.shut, "U", "B"), self.assignments)[twice]
        fold_angles = np.where(cut, np.nan, self.fold_angles)[twice]
        self.vertices, self.edges = _frozen(split.vertices), _frozen(split.edges)
        self.assignments, self.fold_angles = _frozen(assignments), _frozen(fold_angles)
        self.widths = _frozen(np.where(cut, np.nan, self.widths)[twice])
        self.max_angles = _frozen(self.max_angles[twice])
        self.copied_from = _frozen(split.copied_from)
        self._validate_connected()
        self.edge_faces = _frozen(self._match_faces(split.flat, lengths))
        warnings.warn(f"{self.source}: {cut_note(split)}", PatternWarning, stacklevel=4)
        return split.flat

    # -------------------------------------------------------------- validation
    def _fail(self, message: str):
        raise PatternError(f"{self.source}: {message}")

    def _validate_edges(self):
        lengths = self.edge_lengths()
        scale = float(np.ptp(self.vertices, axis=0).max()) if self.n_vertices else 0.0
        for i in np.flatnonzero(lengths <= 1e-12 * max(scale, 1e-300)):
            self._fail(f"edge {i} {tuple(self.edges[i].tolist())} has zero length")
        # the smallest repeated (min, max) vertex pair: its first and second edge
        key = self.edges.min(axis=1) * self.n_vertices + self.edges.max(axis=1)
        _, first, counts = np.unique(key, return_index=True, return_counts=True)
        for i in first[counts > 1]:
            j = np.flatnonzero(key == key[i])[1]
            self._fail(f"edge {j} duplicates edge {i} (vertices {tuple(self.edges[i].tolist())})")
        degree = np.bincount(self.edges.ravel(), minlength=self.n_vertices)
        for v in np.flatnonzero(degree == 0):
            self._fail(f"vertex {v} is not on any edge")
        self._validate_dangling(np.flatnonzero(degree == 1))
        del lengths, key, first, counts, degree  # not held through the crossing test
        self._validate_connected()
        self._validate_crossings()

    def _validate_dangling(self, ends: np.ndarray):
        """Record the creases that end inside a face (``ends``: the vertices of degree
        1) as :attr:`dangling`; refuse a dangling boundary or cut edge."""
        on_end = np.flatnonzero(np.isin(self.edges, ends).any(axis=1))
        for e in on_end[np.isin(self.assignments[on_end], ("B", "C"))][:1]:
            v = int(np.intersect1d(self.edges[e], ends)[0])
            self._fail(f"edge {e} is dangling (vertex {v} has no other edge) and is assigned "
                       f"{str(self.assignments[e])!r}: only a crease may end inside a face")
        #: (D,) int: the creases with an end inside a face (a vertex on no other edge)
        self.dangling = _frozen(on_end)

    def check_no_dangling(self, what: str = "a thick sheet") -> None:
        """PatternError naming the first crease that ends inside a face (a thin sheet
        folds them, as Origami Simulator does; a thick one has no panel to end in)."""
        if len(self.dangling):
            e = int(self.dangling[0])
            self._fail(f"edge {e} is a crease that ends inside a face (dangling); {what} "
                       "needs every crease to run from edge to edge: extend it, remove it, "
                       "or fold the pattern as a thin sheet (no thickness)")

    def _validate_crossings(self):
        """Refuse edges that cross or overlap. Vertices at one point are one there (the
        two sides of a slit, :mod:`foldcore.cuts`): their edges may meet at it, and two
        boundary edges may lie on each other; any other coincidence is refused."""
        from .cuts import welded_ids

        weld = welded_ids(self.vertices)
        if weld is None:
            for i, j in crossing_pairs(self.vertices, self.edges):
                self._fail(f"edges {i} and {j} cross or overlap")
            return
        ends = np.sort(weld[self.edges], axis=1)
        _, first, inverse = np.unique(ends, axis=0, return_index=True, return_inverse=True)
        inverse = inverse.ravel()
        twins = np.flatnonzero(first[inverse] != np.arange(self.n_edges))
        for j in twins:
            i = int(first[inverse[j]])
            if self.assignments[i] != "B" or self.assignments[j] != "B":
                self._fail(f"edges {i} and {j} lie on each other (their ends are at the "
                           "same points); only the two boundary sides of a slit may")
        slit_ends = np.zeros(self.n_vertices, dtype=bool)
        slit_ends[self.edges[np.concatenate([twins, first[inverse[twins]]])]] = True
        shared = np.bincount(weld, minlength=self.n_vertices)[weld] > 1
        for v in np.flatnonzero(shared & ~slit_ends)[:1]:
            other = int(np.flatnonzero((weld == weld[v]) & (np.arange(self.n_vertices) != v))[0])
            self._fail(f"vertex {v} is at the same point as vertex {other} but not on a slit "
                       "(two boundary edges on each other): join them into one vertex")
        for i, j in crossing_pairs(self.vertices, ends[first]):
            self._fail(f"edges {int(first[i])} and {int(first[j])} cross or overlap")

    def _validate_connected(self):
        """Count the separate pieces (:attr:`pieces`); a thick sheet needs one
        (:meth:`check_one_piece`), a thin sheet folds them all."""
        from scipy.sparse import coo_matrix
        from scipy.sparse.csgraph import connected_components

        n = self.n_vertices
        graph = coo_matrix((np.ones(self.n_edges), (self.edges[:, 0], self.edges[:, 1])),
                           shape=(n, n))
        self.pieces, self._piece_of = connected_components(graph, directed=False)

    def check_one_piece(self, what: str = "a thick sheet") -> None:
        """PatternError naming a vertex of a second piece when the pattern is several,
        or a vertex where faces meet at the vertex alone (:attr:`pinched`)."""
        for v in self.pinched[:1]:
            self._fail(f"vertex {v}: faces meet only at this vertex (a bow-tie); {what} "
                       "must hang together along its edges: simulate each piece on its own, "
                       "join the faces along an edge, or fold it as a thin sheet (no "
                       "thickness)")
        if self.pieces > 1:
            v = int(np.flatnonzero(self._piece_of != self._piece_of[0])[0])
            e = int(np.flatnonzero((self.edges == v).any(axis=1))[0])
            self._fail(f"the pattern is not connected ({self.pieces} separate pieces): vertex "
                       f"{v} (edge {e}) is not connected to vertex 0; {what} needs one "
                       "piece: simulate each piece on its own, or fold it as a thin sheet "
                       "(no thickness)")

    def _validate_edge_values(self):
        kind, angle = self.assignments, self.fold_angles
        with np.errstate(invalid="ignore"):
            bad = ~np.isnan(angle) & ((np.abs(angle) > 180.0) | (kind == "M") & (angle > 0)
                                      | (kind == "V") & (angle < 0)
                                      | np.isin(kind, ("B", "F", "C")) & (angle != 0))
        for e in np.flatnonzero(bad)[:1]:  # the first edge in error, its first error
            self._check_angle(e, kind[e], angle[e])
        bad_w = ~np.isnan(self.widths) & ~(self.widths > 0)
        for e in np.flatnonzero(bad_w):
            self._fail(f"edge {e}: hinge width {self.widths[e]:g} mm must be > 0")
        bad_m = ~((self.max_angles > 0) & (self.max_angles <= 180))
        for e in np.flatnonzero(bad_m):
            self._fail(f"edge {e}: max angle {self.max_angles[e]:g}° must be in (0, 180]")
        for e in np.flatnonzero(np.abs(np.nan_to_num(self.fold_angles)) > self.max_angles + 1e-9):
            self._fail(f"edge {e}: fold angle {self.fold_angles[e]:g}° exceeds its "
                       f"max angle {self.max_angles[e]:g}°")

    def _check_angle(self, e: int, kind: str, angle: float):
        """Refuse edge ``e``'s target ``angle`` (degrees) if it is out of range or
        contradicts its assignment ``kind``."""
        if not np.isnan(angle):
            if abs(angle) > 180.0:
                self._fail(f"edge {e}: fold angle {angle:g}° is outside [-180, 180]")
            if kind == "M" and angle > 0 or kind == "V" and angle < 0:
                self._fail(f"edge {e}: fold angle {angle:g}° contradicts assignment "
                           f"{str(kind)!r} (valley > 0, mountain < 0)")
            if kind in "BFC" and angle != 0:
                self._fail(f"edge {e}: fold angle {angle:g}° on a {str(kind)!r} edge "
                           "(must be 0 or passive)")

    def _counter_clockwise(self, flat: np.ndarray, lengths: np.ndarray):
        """Check the face loops (``flat`` ids, ``lengths`` per face); reverse clockwise
        ones (a warning each). Faces are checked in order; the first bad one is named."""
        starts = loop_starts(lengths)
        out_of_range = (flat < 0) | (flat >= self.n_vertices)
        broken = (lengths < 3) | (np.bincount(np.repeat(np.arange(len(lengths)), lengths),
                                              weights=out_of_range, minlength=len(lengths)) > 0)
        n_ok = int(np.argmax(broken)) if broken.any() else len(lengths)
        areas = signed_areas(self.vertices, flat[:int(starts[n_ok]) if n_ok < len(lengths)
                                               else len(flat)], lengths[:n_ok])
        zero = np.flatnonzero(np.abs(areas) <= 0)  # (a NaN area is not zero)
        n_ok = int(zero[0]) if len(zero) else n_ok
        for i in np.flatnonzero(areas[:n_ok] < 0):
            warnings.warn(f"{self.source}: face {i} was clockwise; reversed to "
                          "counter-clockwise", PatternWarning, stacklevel=4)
        if n_ok < len(lengths):
            face = flat[starts[n_ok]:starts[n_ok] + lengths[n_ok]]
            if len(face) < 3:
                self._fail(f"face {n_ok} has {len(face)} vertices (needs at least 3)")
            if face.min() < 0 or face.max() >= self.n_vertices:
                self._fail(f"face {n_ok} refers to a vertex out of range "
                           f"0..{self.n_vertices - 1}")
            self._fail(f"face {n_ok} has zero area")
        return _reversed_loops(flat, starts, lengths, areas < 0), lengths

    def _match_faces(self, flat: np.ndarray, lengths: np.ndarray) -> np.ndarray:
        """(E, 2) int: face on the left / right of each edge (u→v), −1 if none.

        Sides are matched in face order, side by side; the first side that is
        not an edge, or that repeats an edge side already taken, is named.
        """
        n, n_edges = self.n_vertices, self.n_edges
        keys = np.concatenate([self.edges[:, 0] * n + self.edges[:, 1],
                               self.edges[:, 1] * n + self.edges[:, 0]])
        order = np.argsort(keys)
        u, v = flat, flat[next_in_loop(loop_starts(lengths), lengths)]
        side_key = u * n + v
        at = np.minimum(np.searchsorted(keys[order], side_key), len(keys) - 1)
        slot = order[at]  # e (left) or e + E (right)
        missing = keys[slot] != side_key
        face_of = np.repeat(np.arange(len(lengths)), lengths)
        by_slot = np.argsort(np.where(missing, -1, slot), kind="stable")
        taken = np.zeros(len(flat), dtype=bool)  # the slot was filled before, in order
        same = slot[by_slot][1:] == slot[by_slot][:-1]
        taken[by_slot[1:][same & ~missing[by_slot][1:]]] = True
        wrong = missing | taken
        if wrong.any():
            k = int(np.argmax(wrong))
            if missing[k]:
                self._fail(f"face {face_of[k]}: its side {int(u[k])}→{int(v[k])} is not an edge")
            e = int(slot[k] % n_edges)
            earlier = face_of[np.flatnonzero(slot == slot[k])[0]]
            self._fail(f"edge {e} has faces {earlier} and {face_of[k]} on the "
                       "same side (overlapping faces)")
        edge_faces = np.full((n_edges, 2), -1, dtype=np.int64)
        edge_faces[slot % n_edges, slot // n_edges] = face_of
        self._side_slots = _frozen(slot)
        n_sides = (edge_faces >= 0).sum(axis=1)
        for e in np.flatnonzero(n_sides == 0):
            self._fail(f"edge {e} belongs to no face")
        for e in np.flatnonzero((n_sides == 1) & (self.assignments != "B")):
            self._fail(f"edge {e} is assigned {str(self.assignments[e])!r} but lies on the "
                       "sheet boundary (only one face); assign it 'B'")
        for e in np.flatnonzero((n_sides == 2) & (self.assignments == "B")):
            self._fail(f"edge {e} is assigned 'B' but has faces on both sides")
        self._validate_fans(flat, n_sides == 2)
        return edge_faces

    def _validate_fans(self, flat: np.ndarray, inner: np.ndarray):
        """Record as :attr:`pinched` the vertices where the sheet is pinched: their faces
        (``flat``: every face corner's vertex) form more than one fan, joined at the
        vertex alone (a bow-tie). A thin sheet folds them, as Origami Simulator does;
        a thick one refuses them (:meth:`check_one_piece`).

        The faces about a vertex, linked across its edges with a face on each side
        (``inner``), are a path (on the boundary: one face more than such edges) or a
        cycle (inside: as many); one more face than edges again is another fan.
        """
        n = self.n_vertices
        corners = np.bincount(flat, minlength=n)
        links = np.bincount(self.edges[inner].ravel(), minlength=n)
        #: (P,) int: vertices where faces meet at the vertex alone (bow-ties)
        self.pinched = _frozen(np.flatnonzero(corners - links > 1))


def _reversed_loops(flat, starts, lengths, flip) -> np.ndarray:
    """``flat`` with the loops where ``flip`` is True in reverse vertex order."""
    if not flip.any():
        return flat
    face_of = np.repeat(np.arange(len(lengths)), lengths)
    index = np.arange(len(flat))
    mirror = 2 * starts[face_of] + lengths[face_of] - 1 - index
    return flat[np.where(flip[face_of], mirror, index)]


# ------------------------------------------------------------------ coercion
def _frozen(a: np.ndarray) -> np.ndarray:
    a = np.ascontiguousarray(a)
    a.setflags(write=False)
    return a


def _as_vertices(vertices, source: str) -> np.ndarray:
    try:
        v = np.asarray(vertices, dtype=np.float64)
    except (TypeError, ValueError) as exc:
        raise PatternError(f"{source}: vertices are not numbers ({exc})") from None
    if v.ndim != 2 or v.shape[1] not in (2, 3):
        raise PatternError(f"{source}: vertices must be an (V, 2) array, got shape {v.shape}")
    if v.shape[1] == 3:
        off = np.flatnonzero(v[:, 2] != 0)
        if len(off):
            raise PatternError(f"{source}: vertex {off[0]} has z = {v[off[0], 2]:g}; "
                               "a crease pattern must be flat (z = 0)")
        v = v[:, :2]
    bad = np.flatnonzero(~np.isfinite(v).all(axis=1))
    if len(bad):
        raise PatternError(f"{source}: vertex {bad[0]} has a non-finite coordinate "
                           f"{tuple(v[bad[0]].tolist())}")
    _check_scale(v, source)
    return v


def _check_scale(v: np.ndarray, source: str):
    """Refuse coordinates whose lengths² and areas cannot be computed in float64."""
    huge = np.flatnonzero((np.abs(v) > MAX_COORDINATE_MM).any(axis=1))
    if len(huge):
        raise PatternError(f"{source}: vertex {huge[0]} {tuple(v[huge[0]].tolist())} is "
                           f"beyond ±{MAX_COORDINATE_MM:g} mm (wrong units?)")
    extent = float(np.ptp(v, axis=0).max()) if len(v) else 0.0
    if 0 < extent < MIN_EXTENT_MM:
        raise PatternError(f"{source}: the pattern is only {extent:g} mm across, smaller "
                           f"than {MIN_EXTENT_MM:g} mm (wrong units?)")


def _as_edges(edges, n_vertices: int, source: str) -> np.ndarray:
    raw = np.asarray(edges)
    if raw.size == 0:
        raise PatternError(f"{source}: the pattern has no edges")
    if raw.ndim != 2 or raw.shape[1] != 2:
        raise PatternError(f"{source}: edges must be an (E, 2) array, got shape {raw.shape}")
    if not np.issubdtype(raw.dtype, np.integer):
        as_float = np.asarray(raw, dtype=np.float64)
        bad = np.flatnonzero((as_float != np.round(as_float)).any(axis=1)
                             | ~np.isfinite(as_float).all(axis=1))
        if len(bad):
            raise PatternError(f"{source}: edge {bad[0]} has a non-integer vertex id")
    e = shared_or_copy(raw, np.int64)
    bad = np.flatnonzero(((e < 0) | (e >= n_vertices)).any(axis=1))
    if len(bad):
        raise PatternError(f"{source}: edge {bad[0]} refers to vertex "
                           f"{tuple(e[bad[0]].tolist())} out of range 0..{n_vertices - 1}")
    loops = np.flatnonzero(e[:, 0] == e[:, 1])
    if len(loops):
        raise PatternError(f"{source}: edge {loops[0]} has zero length (both ends are "
                           f"vertex {e[loops[0], 0]})")
    return e


def _as_assignments(assignments, n_edges: int, source: str) -> np.ndarray:
    if _all_known(assignments):  # at once; else item by item, naming the first bad one
        if len(assignments) != n_edges:
            raise PatternError(f"{source}: {len(assignments)} assignments for {n_edges} edges")
        return np.array(assignments, dtype="<U1")
    a = [str(x) for x in assignments]
    if len(a) != n_edges:
        raise PatternError(f"{source}: {len(a)} assignments for {n_edges} edges")
    for e, kind in enumerate(a):
        if kind == "J":
            raise PatternError(f"{source}: edge {e} has assignment 'J' (join edges are not "
                               "supported; merge the faces in the pattern instead)")
        if kind not in GIVEN_ASSIGNMENTS:
            raise PatternError(f"{source}: edge {e} has unknown assignment {kind!r} "
                               f"(expected one of {', '.join(GIVEN_ASSIGNMENTS)})")
    return np.array(a, dtype="<U1")


def _all_known(assignments) -> bool:
    """True for a 1-D str array or a list/tuple of str, every one in ASSIGNMENTS."""
    if isinstance(assignments, np.ndarray):
        return assignments.ndim == 1 and assignments.dtype.kind == "U" \
            and bool(np.isin(assignments, GIVEN_ASSIGNMENTS).all())
    return isinstance(assignments, (list, tuple)) and set(map(type, assignments)) <= {str} \
        and set(assignments) <= set(GIVEN_ASSIGNMENTS)


def _per_edge(values, n_edges: int, default: float, name: str, source: str) -> np.ndarray:
    if values is None:
        return np.full(n_edges, default, dtype=np.float64)
    try:
        if isinstance(values, np.ndarray) and values.ndim == 1 and values.dtype.kind in "fiu":
            out = shared_or_copy(values, np.float64)
        else:
            out = np.array([np.nan if x is None else x for x in values], dtype=np.float64)
    except (TypeError, ValueError):
        raise PatternError(f"{source}: {name} must be numbers or null") from None
    if out.shape != (n_edges,):
        raise PatternError(f"{source}: {len(out)} {name} for {n_edges} edges")
    bad = np.flatnonzero(np.isinf(out))
    if len(bad):
        raise PatternError(f"{source}: edge {bad[0]}: {name} is infinite")
    if default == default:  # a numeric default: NaN is not allowed
        nan = np.flatnonzero(np.isnan(out))
        if len(nan):
            raise PatternError(f"{source}: edge {nan[0]}: {name} is NaN")
    return out
