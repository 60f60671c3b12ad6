"""thicken(): crease pattern → prism mesh (paper §2.2), checked independently.

Every invariant is measured from the mesh's own points and vertex loops with
shapely (never from ``mesh.volumes``): the prisms tile the sheet except for
holes at vertices, do not overlap, are conforming, and the strips start where
the mitered panel corners (Eq. 1, read with its arctan) put them.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import pytest
import shapely
from hypothesis import HealthCheck, assume, given, settings
from hypothesis import strategies as st

from foldcore import patterns
from foldcore.errors import MeshError, PatternWarning
from foldcore.simulation import Simulation
from foldcore.pattern import CreasePattern
from foldcore.thickening import auto_subdivisions, minimum_hinge_width, thicken

REL = 1e-9
FAST = settings(max_examples=60, deadline=None,
                suppress_health_check=[HealthCheck.too_slow, HealthCheck.filter_too_much])


# ====================================================================== helpers
@dataclass
class Prism:
    kind: str
    index: int          # element index within its group
    top: np.ndarray     # top-loop vertex ids (= 2D point ids)
    bottom: np.ndarray  # bottom-loop vertex ids
    poly: shapely.Polygon


def prisms_of(mesh) -> list[Prism]:
    out = []
    for name, g in mesh.groups.items():
        for i in range(len(g)):
            ids = g.indices[g.slots(i)]
            n = len(ids) // 2
            out.append(Prism(name, i, ids[:n], ids[n:], shapely.Polygon(mesh.points[ids[:n]])))
    return out


def shoelace(xy) -> float:
    x, y = np.asarray(xy).T
    return 0.5 * float(np.dot(x, np.roll(y, -1)) - np.dot(np.roll(x, -1), y))


def sheet_polygon(pattern):
    return shapely.union_all([shapely.Polygon(pattern.vertices[f]) for f in pattern.faces])


def crease_frame(pattern, e):
    a, b = pattern.edges[e]
    pa, pb = pattern.vertices[a], pattern.vertices[b]
    length = float(np.linalg.norm(pb - pa))
    u = (pb - pa) / length
    return pa, u, np.array([-u[1], u[0]]), length


def interior_angle(pattern, face, v):
    """Interior angle (rad, in (0, 2π)) of CCW face ``face`` at vertex ``v``, and
    the vertices before and after ``v`` in the loop."""
    f = [int(x) for x in pattern.faces[face]]
    i = f.index(int(v))
    prev, nxt = f[i - 1], f[(i + 1) % len(f)]
    p = pattern.vertices[int(v)]
    d_next, d_prev = pattern.vertices[nxt] - p, pattern.vertices[prev] - p
    ang = math.atan2(d_next[0] * d_prev[1] - d_next[1] * d_prev[0], d_next @ d_prev)
    return ang % (2 * math.pi), prev, nxt


def edge_id(pattern, u, v):
    hit = np.flatnonzero(((pattern.edges[:, 0] == u) & (pattern.edges[:, 1] == v))
                         | ((pattern.edges[:, 0] == v) & (pattern.edges[:, 1] == u)))
    return int(hit[0])


def eq1_along(w1, w2, theta):
    """Distance along crease 1 (width w1) from the vertex to the mitered corner with
    a side of width w2 at angle θ (rad): a = (w2 + w1 cos θ) / (2 sin θ)."""
    if abs(math.sin(theta)) < 1e-12:  # straight corner: the corner is abeam the vertex
        return 0.0
    return (w2 + w1 * math.cos(theta)) / (2 * math.sin(theta))


def expected_cut(pattern, widths, e, end):
    """Where the strip of crease e starts, measured from its vertex ``end``: the
    farther of the two neighbouring panel corners (Eq. 1), clamped at 0."""
    a, b = (int(x) for x in pattern.edges[e])
    other = b if end == a else a
    w = np.nan_to_num(widths)  # boundary edges: width 0
    cuts = [0.0]
    for face in pattern.edge_faces[e]:
        if face < 0:
            continue
        theta, prev, nxt = interior_angle(pattern, face, end)
        side = nxt if prev == other else prev
        cuts.append(eq1_along(w[e], w[edge_id(pattern, end, side)], theta))
    return max(cuts)


def strip_coords(mesh, pattern, e):
    """(along, across) coordinates of every top point of crease e's sub-strips."""
    g = mesh.groups["bending_hinge"]
    pa, u, n, _ = crease_frame(pattern, e)
    out = []
    for s in mesh.strips_of_crease[e]:
        top = g.indices[g.slots(int(s))][:4]
        d = mesh.points[top] - pa
        out.append(np.column_stack([d @ u, d @ n]))
    return out


def true_corners(points):
    """Indices of the loop points where the outline turns (inserted collinear points
    are skipped)."""
    p = np.asarray(points)
    d_in, d_out = p - np.roll(p, 1, axis=0), np.roll(p, -1, axis=0) - p
    cross = d_in[:, 0] * d_out[:, 1] - d_in[:, 1] * d_out[:, 0]
    scale = np.linalg.norm(d_in, axis=1) * np.linalg.norm(d_out, axis=1)
    return np.flatnonzero(np.abs(cross) > 1e-9 * scale)


def panel_corner_near(mesh, face, point):
    g = mesh.groups["rigid_panel"]
    top = g.indices[g.slots(int(mesh.panel_of_face[face]))]
    top = top[: len(top) // 2]
    xy = mesh.points[top]
    corners = xy[true_corners(xy)]
    return corners[np.argmin(np.linalg.norm(corners - point, axis=1))]


# =================================================================== invariants
def slit_end_points(pattern) -> list:
    """Positions (2,) mm of the ends of boundary edges drawn twice (a cut's two sides)."""
    xy = pattern.vertices[pattern.edges[pattern.assignments == "B"]]  # (B, 2, 2)
    keys = [tuple(sorted(map(tuple, np.round(seg, 9).tolist()))) for seg in xy]
    twice = {k for k in keys if keys.count(k) > 1}
    return [np.array(p) for k in twice for p in k]


def check_mesh(pattern, mesh, H, widths=None, ks=None):
    """All acceptance invariants (a)–(f) plus strip geometry; raises AssertionError."""
    creases = pattern.creases
    widths = mesh.hinge_width if widths is None else np.asarray(widths, float)
    ks = mesh.subdivisions if ks is None else np.asarray(ks)
    M = len(mesh.points)
    prisms = prisms_of(mesh)
    panels = [p for p in prisms if p.kind == "rigid_panel"]
    strips = [p for p in prisms if p.kind == "bending_hinge"]
    sheet = sheet_polygon(pattern)
    scale = float(np.ptp(pattern.vertices, axis=0).max())

    # (e) counts and vertex numbering
    assert len(panels) == len(pattern.faces)
    assert len(strips) == int(sum(ks[e] for e in creases))
    assert set(mesh.groups) == {"rigid_panel", "bending_hinge"}
    assert mesh.n_vertices == 2 * M and mesh.rest_positions.shape == (2 * M, 3)
    used = np.zeros(M, bool)
    for p in prisms:
        assert len(p.top) == len(p.bottom) >= 3
        assert (p.top >= 0).all() and (p.top < M).all()
        assert np.array_equal(p.bottom, p.top + M), "bottom loop must mirror the top loop"
        assert len(set(p.top.tolist())) == len(p.top), "repeated vertex in a prism"
        used[p.top] = True
    assert used.all(), "orphan points"
    # conforming at points too: no two ids at the same place, but at the ends of a
    # slit's two sides (a cut), whose panels are apart
    near = shapely.STRtree(shapely.points(mesh.points)).query(
        shapely.points(mesh.points), predicate="dwithin", distance=1e-9 * scale)
    twins = near[0] != near[1]
    slit_ends = slit_end_points(pattern)
    assert all(any(np.allclose(mesh.points[i], q, atol=1e-9 * scale) for q in slit_ends)
               for i in near[0][twins]), "two point ids at the same position"
    assert np.allclose(mesh.rest_positions[:M, 2], H / 2)
    assert np.allclose(mesh.rest_positions[M:, 2], -H / 2)
    assert all(len(p.top) == 4 for p in strips)

    # (b) every prism positive: simple, valid, CCW footprint
    for p in prisms:
        assert p.poly.is_valid and p.poly.exterior.is_simple, (p.kind, p.index)
        assert shoelace(mesh.points[p.top]) > 0, (p.kind, p.index, "not CCW / zero area")

    # (a) total volume = H (sheet area − holes), footprints inside the sheet
    areas = np.array([p.poly.area for p in prisms])
    union = shapely.union_all([p.poly for p in prisms])
    holes = sheet.difference(union)
    assert math.isclose(H * areas.sum(), H * (sheet.area - holes.area), rel_tol=REL)
    assert union.difference(sheet).area <= REL * sheet.area, "prisms outside the sheet"
    # holes only at vertices of the pattern
    for hole in getattr(holes, "geoms", [holes]):
        if hole.area > 1e-7 * sheet.area:
            d = min(hole.distance(shapely.Point(v)) for v in pattern.vertices)
            assert d <= 1e-7 * scale, f"hole of area {hole.area:g} away from every vertex"

    # (c) no overlap
    assert math.isclose(union.area, areas.sum(), rel_tol=REL)
    polys = [p.poly for p in prisms]
    tree = shapely.STRtree(polys)
    left, right = tree.query(polys, predicate="intersects")
    for i, j in zip(left, right):
        if i < j:
            assert polys[i].intersection(polys[j]).area <= REL * sheet.area, (prisms[i].kind,
                                                                               prisms[j].kind)

    # (d) conforming: each long side of a sub-strip is an edge of exactly one other prism
    owners: dict[tuple[int, int], list[tuple[int, tuple[int, int]]]] = {}
    for idx, p in enumerate(prisms):
        for a, b in zip(p.top, np.roll(p.top, -1)):
            owners.setdefault((min(a, b), max(a, b)), []).append((idx, (int(a), int(b))))
    n_panels = len(panels)
    g = mesh.groups["bending_hinge"]
    for e in creases:
        sub = [int(s) for s in mesh.strips_of_crease[e]]
        f_left, f_right = (int(x) for x in pattern.edge_faces[e])
        for j, s in enumerate(sub):
            top = g.indices[g.slots(s)][:4]
            # the strip's loop runs 0→1→2→3 (CCW): left side 3→0, right side 1→2;
            # a CCW neighbour must run the shared edge the other way
            for side, (a, b) in (("left", (top[3], top[0])), ("right", (top[1], top[2]))):
                others = [(i, d) for i, d in owners.get((min(a, b), max(a, b)), [])
                          if i != n_panels + s]
                assert len(others) == 1, f"crease {e} sub-strip {j} {side} side shared by " \
                                         f"{len(others)} prisms"
                i, d = others[0]
                assert d == (int(b), int(a)), f"crease {e} sub-strip {j}: neighbour reversed"
                if side == "left":
                    want = (n_panels + sub[j - 1]) if j > 0 else int(mesh.panel_of_face[f_left])
                else:
                    want = ((n_panels + sub[j + 1]) if j < len(sub) - 1
                            else int(mesh.panel_of_face[f_right]))
                assert i == want, f"crease {e} sub-strip {j} {side}: neighbour {i} != {want}"

    # (f) volumes and weights
    for name, group in mesh.groups.items():
        mine = np.array([p.poly.area for p in prisms if p.kind == name]) * H
        np.testing.assert_allclose(group.volumes, mine, rtol=REL, atol=REL * scale ** 2 * H)
        np.testing.assert_allclose(group.weights, group.volumes, rtol=1e-15)
    assert math.isclose(mesh.volume(), H * areas.sum(), rel_tol=REL)

    # sources and maps
    np.testing.assert_array_equal(mesh.groups["rigid_panel"].source, np.arange(len(panels)))
    np.testing.assert_array_equal(mesh.panel_of_face, np.arange(len(pattern.faces)))
    assert set(mesh.strips_of_crease) == {int(e) for e in creases}
    for e in creases:
        assert len(mesh.strips_of_crease[e]) == ks[e]
        assert (g.source[mesh.strips_of_crease[e]] == e).all()
    assert np.isnan(mesh.hinge_width[pattern.assignments == "B"]).all()
    assert (mesh.subdivisions[pattern.assignments == "B"] == 0).all()

    # rest shapes: centred, congruent with the rest positions
    X = mesh.rest_positions
    for name, group in mesh.groups.items():
        for i in range(len(group)):
            ids = group.indices[group.slots(i)]
            rest = group.rest[group.slots(i)]
            np.testing.assert_allclose(rest.mean(axis=0), 0, atol=1e-9 * scale)
            d_rest = np.linalg.norm(rest[:, None] - rest[None], axis=2)
            d_mesh = np.linalg.norm(X[ids][:, None] - X[ids][None], axis=2)
            np.testing.assert_allclose(d_rest, d_mesh, atol=1e-9 * scale)

    # strips: rectangles of width W/k side by side across the crease (left → right),
    # cut square where Eq. 1 says
    for e in creases:
        W, k = widths[e], int(ks[e])
        a, b = (int(x) for x in pattern.edges[e])
        _, _, _, length = crease_frame(pattern, e)
        cut_a, cut_b = expected_cut(pattern, widths, e, a), expected_cut(pattern, widths, e, b)
        tol = 1e-9 * scale
        for j, c in enumerate(strip_coords(mesh, pattern, e)):
            np.testing.assert_allclose(c[[0, 1], 0], cut_a, atol=tol)
            np.testing.assert_allclose(c[[2, 3], 0], length - cut_b, atol=tol)
            np.testing.assert_allclose(c[[0, 3], 1], W / 2 - j * W / k, atol=tol)
            np.testing.assert_allclose(c[[1, 2], 1], W / 2 - (j + 1) * W / k, atol=tol)
        # hinge element rest frame: x across (toward the left), y up, z along a → b
        for j, s in enumerate(mesh.strips_of_crease[e]):
            rest = g.rest[g.slots(int(s))]
            np.testing.assert_allclose(rest[:4, 1], H / 2, atol=tol)
            np.testing.assert_allclose(rest[4:, 1], -H / 2, atol=tol)
            np.testing.assert_allclose(rest[[0, 3, 4, 7], 0], W / (2 * k), atol=tol)
            np.testing.assert_allclose(rest[[1, 2, 5, 6], 0], -W / (2 * k), atol=tol)
            L = length - cut_a - cut_b
            np.testing.assert_allclose(rest[[0, 1, 4, 5], 2], -L / 2, atol=tol)
            np.testing.assert_allclose(rest[[2, 3, 6, 7], 2], L / 2, atol=tol)
    return holes


# ================================================================== patterns
def star(directions_deg, widths, radius=50.0, lengths=None, kinds=None):
    """One interior vertex (id 0) with creases 0..n−1 toward ``directions_deg``;
    rim chords (extra rim points every ≤ 90°, so a sector may be reflex) are boundary."""
    d = np.radians(np.asarray(directions_deg, float))
    n = len(d)
    lengths = np.full(n, radius) if lengths is None else np.asarray(lengths, float)
    verts = [(0.0, 0.0)] + [tuple(r * np.array([math.cos(t), math.sin(t)]))
                            for r, t in zip(lengths, d)]
    rim = []
    for i in range(n):
        rim.append(i + 1)
        t0, t1 = d[i], d[(i + 1) % n] + (2 * math.pi if i == n - 1 else 0)
        steps = math.ceil((t1 - t0) / (math.pi / 2) - 1e-9)
        r = 0.5 * (lengths[i] + lengths[(i + 1) % n])
        for q in range(1, steps):
            tm = t0 + (t1 - t0) * q / steps
            verts.append((r * math.cos(tm), r * math.sin(tm)))
            rim.append(len(verts) - 1)
    edges = [(0, i + 1) for i in range(n)] + list(zip(rim, rim[1:] + rim[:1]))
    kinds = kinds or ["V" if i % 2 else "M" for i in range(n)]
    return CreasePattern(verts, edges, list(kinds) + ["B"] * len(rim),
                         widths=list(widths) + [None] * len(rim), source="star")


def l_shape():
    """A 20 × 20 sheet: an L-shaped (non-convex) panel and a square panel, split by
    creases 6 (2→6) and 7 (6→4) meeting at the reflex corner (10, 10)."""
    v = [(0, 0), (20, 0), (20, 10), (20, 20), (10, 20), (0, 20), (10, 10)]
    e = [(0, 1), (1, 2), (2, 3), (3, 4), (4, 5), (5, 0), (2, 6), (6, 4)]
    return CreasePattern(v, e, ["B"] * 6 + ["V", "V"], source="l_shape")


def slanted(angle_deg=60.0, size=20.0):
    """A square sheet cut by one crease (edge 0) meeting the bottom and top
    boundaries at ``angle_deg``."""
    x0 = size / 4
    x1 = x0 + size / math.tan(math.radians(angle_deg))
    right = max(size, x1 + size / 4)
    v = [(0, 0), (x0, 0), (right, 0), (right, size), (x1, size), (0, size)]
    e = [(1, 4), (0, 1), (1, 2), (2, 3), (3, 4), (4, 5), (5, 0)]
    return CreasePattern(v, e, ["V"] + ["B"] * 6, source="slanted")


def frame():
    """A square frame of 4 trapezoids around a square hole."""
    v = [(0, 0), (30, 0), (30, 30), (0, 30), (10, 10), (20, 10), (20, 20), (10, 20)]
    e = [(0, 1), (1, 2), (2, 3), (3, 0), (4, 5), (5, 6), (6, 7), (7, 4),
         (0, 4), (1, 5), (2, 6), (3, 7)]
    return CreasePattern(v, e, ["B"] * 8 + ["V", "M", "V", "M"], source="frame")


def t_vertex(w_low=2.0, w_high=2.0, w_right=1.0):
    """single_hinge's crease split at (0, 5) into edges 0 (lower) and 1 (upper), with
    crease 2 going right from there: the left panel has a straight (180°) corner."""
    v = [(0, 0), (0, 5), (0, 10), (10, 0), (10, 5), (10, 10), (-10, 10), (-10, 0)]
    e = [(0, 1), (1, 2), (1, 4), (0, 3), (3, 4), (4, 5), (5, 2), (2, 6), (6, 7), (7, 0)]
    return CreasePattern(v, e, ["V", "V", "M"] + ["B"] * 7,
                         widths=[w_low, w_high, w_right] + [None] * 7, source="t_vertex")


GENERATORS = {
    "pehrson": (lambda: patterns.degree4_vertex(), dict(thickness=2.0, subdivisions=3)),
    "pehrson-auto": (lambda: patterns.degree4_vertex(), dict(thickness=1.0)),
    "waterbomb6": (lambda: patterns.waterbomb(6, width=4.0), dict(thickness=1.0, subdivisions=2)),
    "waterbomb8": (lambda: patterns.waterbomb(8, width=4.0), dict(thickness=1.5, subdivisions=4)),
    "miura3x3": (lambda: patterns.miura(3, 3, width=2.0), dict(thickness=1.0, subdivisions=2)),
    "miura5x4": (lambda: patterns.miura(5, 4, gamma=45.0, width=1.5),
                 dict(thickness=0.5, subdivisions=3)),
    "single_hinge": (lambda: patterns.single_hinge(width=2.0),
                     dict(thickness=1.0, subdivisions=4)),
    "grid3x3U": (lambda: patterns.grid(3, 3, assignment="U"),
                 dict(thickness=1.0, hinge_width=2.0, subdivisions=1)),
    "grid3x3V": (lambda: patterns.grid(3, 3, assignment="V"),
                 dict(thickness=0.7, hinge_width=1.0, subdivisions=5)),
    "star7-acute": (lambda: star(np.cumsum([0, 20, 40, 60, 70, 50, 90]),
                                 [1.0, 2.0, 1.5, 3.0, 1.0, 2.0, 2.5]),
                    dict(thickness=1.0, subdivisions=2)),
    "star6-uneven": (lambda: star([0, 20, 110, 180, 200, 290], [4, 1, 3, 0.5, 2, 6],
                                  lengths=[50, 30, 40, 45, 35, 60]),
                     dict(thickness=1.0, subdivisions=3)),
    "l_shape": (l_shape, dict(thickness=1.0, hinge_width=2.0, subdivisions=2)),
    "slanted60": (slanted, dict(thickness=1.0, hinge_width=3.0, subdivisions=2)),
    "slanted20": (lambda: slanted(20.0, size=10.0), dict(thickness=0.5, hinge_width=1.0,
                                                         subdivisions=3)),
    "frame": (frame, dict(thickness=1.0, hinge_width=2.0, subdivisions=2)),
    "t_vertex": (t_vertex, dict(thickness=1.0, subdivisions=2)),
}


@pytest.mark.parametrize("name", list(GENERATORS))
def test_invariants_on_generators(name):
    build, kw = GENERATORS[name]
    pattern = build()
    mesh = thicken(pattern, **kw)
    check_mesh(pattern, mesh, kw["thickness"])


@pytest.mark.parametrize("name", ["pehrson", "l_shape", "frame", "star7-acute"])
def test_prism_faces_closed_and_outward(name):
    """mesh.prism_faces(): per prism, top + bottom + n sides, outward (divergence
    theorem gives +volume) and closed (every directed edge used once, reversed once)."""
    build, kw = GENERATORS[name]
    pattern = build()
    mesh = thicken(pattern, **kw)
    X = mesh.rest_positions
    faces, kinds = mesh.prism_faces()
    at = 0
    for p in prisms_of(mesh):
        n = len(p.top)
        mine = faces[at: at + n + 2]
        assert kinds[at: at + n + 2] == [p.kind] * (n + 2)
        at += n + 2
        vol, edges = 0.0, []
        for f in mine:
            q = X[f]
            for j in range(1, len(f) - 1):  # fan triangles
                vol += np.dot(q[0], np.cross(q[j], q[j + 1])) / 6
            edges += list(zip(f, np.roll(f, -1)))
        assert vol == pytest.approx(p.poly.area * kw["thickness"], rel=1e-9)
        assert sorted(edges) == sorted((b, a) for a, b in edges)
        assert len(set(edges)) == len(edges)
    assert at == len(faces)


def test_stiffness_scales_weights():
    pattern = patterns.degree4_vertex()
    factors = np.array([1.0, 2.0, 3.0, 4.0] + [1.0] * 6)
    mesh = thicken(pattern, 1.0, subdivisions=2, stiffness={"panel": 5.0, "hinge": factors})
    panels, hinges = mesh.groups["rigid_panel"], mesh.groups["bending_hinge"]
    np.testing.assert_allclose(panels.weights, 5.0 * panels.volumes)
    np.testing.assert_allclose(hinges.weights, factors[hinges.source] * hinges.volumes)


# ======================================================================= Eq. 1
def test_square_corner_equal_widths_shortens_by_half_width():
    w = 2.5
    pattern = patterns.grid(2, 2, size=10.0, assignment="V")
    mesh = thicken(pattern, 1.0, hinge_width=w, subdivisions=2)
    centre = 4
    at_centre = [e for e in pattern.creases if centre in pattern.edges[e]]
    assert len(at_centre) == 4
    for e in at_centre:
        c = np.vstack(strip_coords(mesh, pattern, e))
        along = c[:, 0] if pattern.edges[e][0] == centre else 10.0 - c[:, 0]
        assert along.min() == pytest.approx(w / 2, abs=1e-12)   # Eq. 1: a = w/2
        assert along.max() == pytest.approx(10.0, abs=1e-12)    # square at the boundary
    # hole at the centre: a w × w square
    holes = check_mesh(pattern, mesh, 1.0)
    assert holes.area == pytest.approx(w * w, rel=1e-9)
    assert holes.centroid.distance(shapely.Point(10, 10)) < 1e-9


SECTOR_CASES = {
    # directions (deg), widths: acute 50° and obtuse 110° sectors, unequal widths
    "acute-obtuse": ([0, 50, 160, 260], [6.0, 2.0, 3.0, 5.0]),
    # Pehrson's vertex: a 135° sector between widths 16 and 4 (corner behind the vertex)
    "pehrson": ([0, 135, 225, 270], [16.0, 4.0, 8.0, 4.0]),
    "three-obtuse": ([0, 120, 240], [16.0, 4.0, 4.0]),
    "acute20": ([0, 20, 150, 250], [3.0, 1.0, 2.0, 4.0]),
}


@pytest.mark.parametrize("case", list(SECTOR_CASES))
def test_eq1_panel_corner_position(case):
    dirs, widths = SECTOR_CASES[case]
    pattern = star(dirs, widths, radius=76.2)
    mesh = thicken(pattern, 1.0, subdivisions=2)
    check_mesh(pattern, mesh, 1.0)
    n = len(dirs)
    for i in range(n):
        j = (i + 1) % n
        theta = math.radians((dirs[j] - dirs[i]) % 360)
        w1, w2 = widths[i], widths[j]
        # the face between crease i and crease i+1: left of crease i, right of crease i+1
        face = int(pattern.edge_faces[i][0])
        assert face == int(pattern.edge_faces[j][1])
        _, u1, n1, _ = crease_frame(pattern, i)
        _, u2, _, _ = crease_frame(pattern, j)
        x = panel_corner_near(mesh, face, np.zeros(2))
        a1 = (w2 + w1 * math.cos(theta)) / (2 * math.sin(theta))
        a2 = (w1 + w2 * math.cos(theta)) / (2 * math.sin(theta))
        assert x @ u1 == pytest.approx(a1, abs=1e-9)          # along crease i
        assert x @ n1 == pytest.approx(w1 / 2, abs=1e-9)      # offset by half its width
        assert x @ u2 == pytest.approx(a2, abs=1e-9)          # along crease i+1
        # Eq. 1 read with its arctan: |OX| = w1 / (2 sin A), A = atan2(sin θ, w2/w1 + cos θ)
        A = math.atan2(math.sin(theta), w2 / w1 + math.cos(theta))
        assert np.linalg.norm(x) == pytest.approx(w1 / (2 * math.sin(A)), rel=1e-9)


def test_eq1_obtuse_sector_corner_behind_vertex_is_clamped():
    # Pehrson: the 135° sector between widths 16 and 4 puts the corner behind the vertex
    theta = math.radians(135)
    a = (4 + 16 * math.cos(theta)) / (2 * math.sin(theta))
    assert a < 0
    pattern = patterns.degree4_vertex(widths=(16.0, 4.0, 8.0, 4.0))
    mesh = thicken(pattern, 1.0, subdivisions=2)
    check_mesh(pattern, mesh, 1.0)
    x = panel_corner_near(mesh, 0, np.zeros(2))
    assert x[0] == pytest.approx(a, abs=1e-9) and x[1] == pytest.approx(8.0, abs=1e-9)
    # crease 0's strip starts at the other side's corner: 90° sector, width 4 → a = 2
    c = np.vstack(strip_coords(mesh, pattern, 0))
    assert c[:, 0].min() == pytest.approx(2.0, abs=1e-9)
    # both sides behind the vertex: strip starts at the vertex itself (clamped to 0)
    pattern = star([0, 120, 240], [16.0, 4.0, 4.0])
    mesh = thicken(pattern, 1.0, subdivisions=3)
    check_mesh(pattern, mesh, 1.0)
    c = np.vstack(strip_coords(mesh, pattern, 0))
    assert c[:, 0].min() == pytest.approx(0.0, abs=1e-12)
    for e in (1, 2):
        theta = math.radians(120)
        want = max((16 + 4 * math.cos(theta)) / (2 * math.sin(theta)),
                   (4 + 4 * math.cos(theta)) / (2 * math.sin(theta)))
        assert np.vstack(strip_coords(mesh, pattern, e))[:, 0].min() == pytest.approx(want)


def test_boundary_crease_at_60_degrees():
    w = 3.0
    pattern = slanted(60.0)
    mesh = thicken(pattern, 1.0, hinge_width=w, subdivisions=2)
    check_mesh(pattern, mesh, 1.0)
    _, _, _, length = crease_frame(pattern, 0)
    c = np.vstack(strip_coords(mesh, pattern, 0))
    cut = w * math.cos(math.radians(60)) / (2 * math.sin(math.radians(60)))  # 60° side
    assert c[:, 0].min() == pytest.approx(cut, abs=1e-9)
    assert c[:, 0].max() == pytest.approx(length - cut, abs=1e-9)


def test_l_shaped_panel_and_hole():
    w = 2.0
    pattern = l_shape()
    mesh = thicken(pattern, 1.0, hinge_width=w, subdivisions=2)
    holes = check_mesh(pattern, mesh, 1.0)
    assert holes.area == pytest.approx(w * w, rel=1e-9)  # the square between the corners
    areas = [p.poly.area for p in prisms_of(mesh) if p.kind == "rigid_panel"]
    face_l = int(np.argmax([len(f) for f in pattern.faces]))
    # L panel: 300 − its share of the two strips − the hole corner square
    assert areas[face_l] == pytest.approx(300 - 2 * 10 * w / 2 - (w / 2) ** 2)
    # the reflex corner sits at (10 − w/2, 10 − w/2): Eq. 1 with θ = 270°, a = −w/2
    x = panel_corner_near(mesh, face_l, np.array([10.0, 10.0]))
    np.testing.assert_allclose(x, [10 - w / 2, 10 - w / 2], atol=1e-12)


def test_straight_corner_equal_widths_builds():
    pattern = t_vertex(2.0, 2.0, 1.0)
    mesh = thicken(pattern, 1.0, subdivisions=2)
    check_mesh(pattern, mesh, 1.0)
    # creases 0 and 1 stop short of (0, 5) by half of crease 2's width
    assert np.vstack(strip_coords(mesh, pattern, 0))[:, 0].max() == pytest.approx(4.5)
    assert np.vstack(strip_coords(mesh, pattern, 1))[:, 0].min() == pytest.approx(0.5)


def test_straight_corner_unequal_widths_steps():
    # the left panel's straight corner between creases of widths 2 and 3: a step
    pattern = t_vertex(2.0, 3.0, 1.0)
    check_mesh(pattern, thicken(pattern, 1.0, subdivisions=2), 1.0)


def test_high_degree_vertex_waterbomb8_holes_at_centre():
    w, n = 4.0, 8
    pattern = patterns.waterbomb(n, width=w)
    mesh = thicken(pattern, 1.0, subdivisions=3)
    holes = check_mesh(pattern, mesh, 1.0)
    central = [h for h in getattr(holes, "geoms", [holes])
               if h.distance(shapely.Point(0, 0)) < 1e-9]
    # equal widths: the strip-end corners are the panel corners, so the central
    # hole is the regular n-gon of circumradius (w/2) / sin(θ/2), θ = 360°/n
    R = (w / 2) / math.sin(math.pi / n)
    assert len(central) == 1
    assert central[0].area == pytest.approx(0.5 * n * R * R * math.sin(2 * math.pi / n))
    # 45° sectors, equal widths: every strip starts (w/2)(1 + cos 45°)/sin 45° out
    want = 4.0 * (1 + math.cos(math.pi / 4)) / (2 * math.sin(math.pi / 4))
    for e in range(8):
        assert np.vstack(strip_coords(mesh, pattern, e))[:, 0].min() == pytest.approx(want)


# =============================================================== widths and k
def test_hinge_width_scalar_overrides_pattern():
    pattern = patterns.degree4_vertex()
    mesh = thicken(pattern, 1.0, hinge_width=3.0, subdivisions=2)
    np.testing.assert_allclose(mesh.hinge_width[:4], 3.0)
    check_mesh(pattern, mesh, 1.0)


def test_hinge_width_per_edge_array():
    pattern = patterns.degree4_vertex()
    w = np.full(pattern.n_edges, np.nan)
    w[:4] = [5.0, 1.0, 2.5, 7.0]
    mesh = thicken(pattern, 1.0, hinge_width=w, subdivisions=[3, 1, 2, 4] + [0] * 6)
    np.testing.assert_allclose(mesh.hinge_width[:4], w[:4])
    np.testing.assert_array_equal(mesh.subdivisions[:4], [3, 1, 2, 4])
    check_mesh(pattern, mesh, 1.0)


def test_pattern_widths_used_by_default():
    pattern = patterns.degree4_vertex(widths=(16.0, 4.0, 8.0, 4.0))
    mesh = thicken(pattern, 1.0, subdivisions=2)
    np.testing.assert_allclose(mesh.hinge_width[:4], [16, 4, 8, 4])


@pytest.mark.parametrize("H, theta, r, want", [
    (1.0, 180.0, 0.0, math.pi / 2),
    (2.0, 90.0, 0.0, math.pi / 2),
    (1.0, 180.0, 1.0, 1.5 * math.pi),
    (0.5, 60.0, 2.0, 2.25 * math.pi / 3),
])
def test_auto_hinge_width_eq7(H, theta, r, want):
    assert minimum_hinge_width(H, theta, r) == pytest.approx(want)
    pattern = patterns.single_hinge(max_angle=theta)
    mesh = thicken(pattern, H, bend_radius=r, subdivisions=2)
    assert mesh.hinge_width[0] == pytest.approx(want)
    check_mesh(pattern, mesh, H)
    c = np.vstack(strip_coords(mesh, pattern, 0))
    assert np.ptp(c[:, 1]) == pytest.approx(want)  # the strip really is that wide


def test_auto_hinge_width_only_for_nan_entries():
    pattern = patterns.degree4_vertex(widths=[16.0, None, 8.0, None])
    mesh = thicken(pattern, 1.0, subdivisions=2)
    np.testing.assert_allclose(mesh.hinge_width[:4], [16, math.pi / 2, 8, math.pi / 2])


def reference_k(W, H, theta_deg, cap=16):
    """k = max(2, ⌈θ/45°⌉), raised while θ/k > 2 atan(W/(kH)) (capped)."""
    theta = math.radians(theta_deg)
    k = max(2, math.ceil(theta_deg / 45.0 - 1e-9))
    while k < cap and theta / k > 2 * math.atan(W / (k * H)):
        k += 1
    return k


@pytest.mark.parametrize("W, H, theta, want", [
    (2.0, 1.0, 180.0, 4),     # paper: W = 2, H = 1 → 4 × 45°, each reachable
    (1.6, 1.0, 180.0, 7),     # raised: 45° > 2 atan(0.4) = 43.6°, … 25.7° < 25.75°
    (4.0, 1.0, 30.0, 2),      # floor of 2
    (4.0, 1.0, 100.0, 3),     # ceil(100/45)
    (0.5, 1.0, 45.0, 2),
    (0.53, 1.0, 60.0, 3),     # raised from 2: 30° > 2 atan(0.265) = 29.7°
])
def test_auto_subdivisions_rule(W, H, theta, want):
    assert reference_k(W, H, theta) == want
    assert int(auto_subdivisions(W, H, theta, hinge="eq8")[0]) == want
    # the chosen k is the smallest that lets every sub-strip reach θmax/k
    t = math.radians(theta)
    assert t / want <= 2 * math.atan(W / (want * H))
    if want > max(2, math.ceil(theta / 45 - 1e-9)):
        assert t / (want - 1) > 2 * math.atan(W / ((want - 1) * H))


@given(W=st.floats(0.05, 20), H=st.floats(0.05, 5), theta=st.floats(1.0, 180.0))
@FAST
def test_auto_subdivisions_matches_reference(W, H, theta):
    assert int(auto_subdivisions(W, H, theta, hinge="eq8")[0]) == reference_k(W, H, theta)


def test_auto_subdivisions_in_mesh():
    pattern = patterns.degree4_vertex(widths=[16.0, 1.6, 4.0, 2.0]).replace(
        max_angles=[180.0, 180.0, 100.0, 30.0] + [180.0] * 6)
    mesh = thicken(pattern, 1.0, subdivisions="auto", hinge="eq8")
    want = [reference_k(w, 1.0, t) for w, t in zip([16.0, 1.6, 4.0, 2.0],
                                                   [180.0, 180.0, 100.0, 30.0])]
    assert want == [4, 7, 3, 2]
    np.testing.assert_array_equal(mesh.subdivisions[:4], want)
    check_mesh(pattern, mesh, 1.0)


def test_auto_width_with_auto_subdivisions_eq8_hits_the_cap():
    # Eq. 7 with r = 0 gives W = Hθ/2; then θ/k > 2 atan(θ/(2k)) for every k, so the
    # Eq. 8 rule can never be satisfied and k stops at its cap (16).
    pattern = patterns.single_hinge()
    mesh = thicken(pattern, 1.0, hinge="eq8")
    assert mesh.subdivisions[0] == 16
    check_mesh(pattern, mesh, 1.0)


def test_auto_subdivisions_of_arcs_use_the_smoothness_rule_only():
    # the arc reaches 2W/H = θmax at W = Hθ/2 for any k, the axis hinge pivots past
    # 2·atan(W/H): k = ceil(180/45) = 4 for both, Eq. 8 per hinge only where asked
    pattern = patterns.single_hinge()
    for model in ("arc", "axis", None):
        assert thicken(pattern, 1.0, hinge=model).subdivisions[0] == 4
    assert int(auto_subdivisions(0.2, 1.0, 30.0, hinge="arc")[0]) == 2
    mixed = auto_subdivisions([0.2, 0.2], 1.0, 30.0, hinge=["axis", "eq8"])
    assert mixed[0] == 2 and mixed[1] > 2


def test_hinge_models_per_edge_reach_the_kernel_and_bad_names_are_refused():
    from elements.bending_hinge import AXIS, EQ8, MODEL, STRIPS

    pattern = patterns.degree4_vertex()
    models = ["eq8", None, "axis", "arc"] + [None] * (pattern.n_edges - 4)
    mesh = thicken(pattern, 2.0, hinge=models)
    assert list(mesh.hinge_model[:4]) == ["eq8", "axis", "axis", "arc"]
    assert (mesh.hinge_model[4:] == "").all()
    g = mesh.groups["bending_hinge"]
    codes = {e: set(g.params[g.source == e, MODEL]) for e in range(4)}
    assert codes == {0: {EQ8}, 1: {AXIS}, 2: {AXIS}, 3: {1.0}}
    np.testing.assert_array_equal(g.params[:, STRIPS], mesh.subdivisions[g.source])
    with pytest.raises(MeshError, match="edge 2: unknown hinge model 'hinged'"):
        thicken(pattern, 2.0, hinge=["axis", "arc", "hinged"] + [None] * (pattern.n_edges - 3))


# ====================================================================== errors
def test_widths_too_large_for_face():
    with pytest.raises(MeshError, match=r"face [01]\b"):
        thicken(patterns.single_hinge(panel_length=10.0), 1.0, hinge_width=25.0)


def test_widths_too_large_for_face_named():
    # the thin 20° sector between creases 2 and 3 (12 mm hinges, 30 mm long) has no
    # room for a panel; the other faces are fine
    pattern = star([0, 110, 230, 250], [1.0, 1.0, 12.0, 12.0], radius=30.0)
    face = int(pattern.edge_faces[2][0])
    assert face == int(pattern.edge_faces[3][1]) and face != 0
    with pytest.raises(MeshError, match=rf"face {face}\b.*too large"):
        thicken(pattern, 1.0, subdivisions=2)
    mesh = thicken(pattern, 1.0, hinge_width=[1.0, 1.0, 5.0, 5.0] + [np.nan] * 7,
                   subdivisions=2)
    check_mesh(pattern, mesh, 1.0)


def tee():
    """A 2 × 2 mm sheet whose lower face (face 0) has a straight side through vertex
    3: creases 2 and 3 meet there in line (both sides of face 0), crease 9 goes up."""
    v = [(0, 0), (2, 0), (2, 1), (1, 1), (0, 1), (0, 2), (1, 2), (2, 2)]
    e = [(0, 1), (1, 2), (2, 3), (3, 4), (4, 0), (4, 5), (5, 6), (6, 7), (7, 2), (3, 6)]
    return CreasePattern(v, e, ["B", "B", "V", "V", "B", "B", "B", "B", "B", "M"],
                         source="tee")


def test_collinear_sides_of_unequal_width_step_the_panel():
    """Creases 2 and 3 in line at vertex 3 with different widths: no mitre exists, so
    the lower panel's outline steps from one strip's end to the other's, and the
    sheet is still tiled exactly by panels and strips (check_mesh)."""
    pattern = tee()
    (face,) = set(pattern.edge_faces[2].tolist()) & set(pattern.edge_faces[3].tolist())
    widths = np.full(pattern.n_edges, 0.05)
    widths[9] = 0.08  # the crossing crease
    check_mesh(pattern, thicken(pattern, 0.01, hinge_width=widths), 0.01)
    widths[2] = 0.08  # in line with crease 3 (0.05)
    mesh = thicken(pattern, 0.01, hinge_width=widths)
    check_mesh(pattern, mesh, 0.01)
    (panel,) = [p for p in prisms_of(mesh) if p.kind == "rigid_panel" and p.index == face]
    y = np.round(mesh.points[panel.top][:, 1], 12)
    assert {0.96, 0.975} <= set(y)  # its upper side at each strip's half width


def pop_up():
    """A 4 × 2 mm sheet cut along y = 1 from x = 0 to 2, the line going on as a valley
    crease from x = 2 to 4 (a pop-up's flap): the cut's sides are boundaries, in
    line with the crease at (2, 1)."""
    v = [(0, 0), (4, 0), (4, 2), (0, 2), (0, 1), (2, 1), (4, 1)]
    e = [(0, 1), (1, 6), (6, 2), (2, 3), (3, 4), (4, 0), (4, 5), (5, 6)]
    return CreasePattern(v, e, ["B"] * 6 + ["C", "V"], fold_angles=[None] * 7 + [90.0],
                         source="pop-up")


def test_a_crease_going_on_as_a_cut_steps_both_panels_and_folds():
    with pytest.warns(PatternWarning, match="cut"):
        pattern = pop_up()
    crease = int(np.flatnonzero(pattern.assignments == "V")[0])
    mesh = thicken(pattern, 0.1, hinge_width=0.3)
    check_mesh(pattern, mesh, 0.1)
    for panel in (p for p in prisms_of(mesh) if p.kind == "rigid_panel"):
        xy = mesh.points[panel.top][:, :2]
        step = xy[np.isclose(xy[:, 0], 2.0)]  # each panel: the crease's end and the cut's
        assert sorted(np.round(np.abs(step[:, 1] - 1.0), 12)) == [0.0, 0.15]
    result = Simulation(mesh, pattern).run(tolerance=1e-10)
    assert result.converged
    assert result.fold_angles_deg[crease] == pytest.approx(90.0, abs=1e-3)


def short_crease():
    """Crease 6 (vertex 0 → 1, 1 mm) crosses a thin sheet at 30° to its sides: each
    end has an acute panel corner on one side only, so the strip loses
    w cos 30° / (2 sin 30°) at each end while neither panel is in danger."""
    d30 = np.array([math.cos(math.radians(30)), math.sin(math.radians(30))])
    A, B = np.array([0.0, 0.0]), np.array([1.0, 0.0])
    v = [A, B, B + 10 * d30, A + 10 * d30, B - 10 * d30, A - 10 * d30]
    e = [(1, 2), (2, 3), (3, 0), (0, 5), (5, 4), (4, 1), (0, 1)]
    return CreasePattern(v, e, ["B"] * 6 + ["V"], source="short")


def test_crease_too_short():
    pattern = short_crease()
    mesh = thicken(pattern, 1.0, hinge_width=0.5, subdivisions=2)
    check_mesh(pattern, mesh, 1.0)
    c = np.vstack(strip_coords(mesh, pattern, 6))
    cut = 0.5 * math.cos(math.radians(30)) / (2 * math.sin(math.radians(30)))
    assert c[:, 0].min() == pytest.approx(cut) and c[:, 0].max() == pytest.approx(1 - cut)
    with pytest.raises(MeshError, match=r"edge 6\b.*too short"):
        thicken(pattern, 1.0, hinge_width=1.0, subdivisions=2)


@pytest.mark.parametrize("H", [0.0, -1.0, np.nan, np.inf])
def test_thickness_must_be_positive(H):
    with pytest.raises(MeshError, match="thickness"):
        thicken(patterns.single_hinge(), H, hinge_width=2.0)


@pytest.mark.parametrize("k", [0, -1, 2.5, "three"])
def test_bad_subdivisions(k):
    with pytest.raises(MeshError, match="subdivisions"):
        thicken(patterns.single_hinge(), 1.0, hinge_width=2.0, subdivisions=k)


@pytest.mark.parametrize("w", [0.0, -1.0])
def test_bad_hinge_width(w):
    pattern = patterns.degree4_vertex()
    widths = np.array([2.0, 2.0, w, 2.0] + [np.nan] * 6)
    with pytest.raises(MeshError, match=r"edge 2\b"):
        thicken(pattern, 1.0, hinge_width=widths)


# ================================================================= hypothesis
@st.composite
def jittered_grids(draw, safe=True):
    """Random n × m grids with jittered vertices (boundary ones slide along the
    rim; some faces non-convex), some cells split by a diagonal, random M/V/U/F;
    per-crease widths (``safe``: small enough that thicken must succeed)."""
    n, m = draw(st.integers(1, 4)), draw(st.integers(1, 4))
    if n * m == 1:
        assume(draw(st.booleans()))  # need at least one crease: split the cell below
    size = 10.0
    darts = draw(st.booleans())
    jit = draw(st.floats(0.0, 0.1 if darts else 0.3)) * size
    rng = np.random.default_rng(draw(st.integers(0, 2 ** 32 - 1)))
    ids = np.arange((n + 1) * (m + 1)).reshape(m + 1, n + 1)
    verts = []
    for j in range(m + 1):
        for i in range(n + 1):
            dx, dy = rng.uniform(-jit, jit, 2)
            if i in (0, n):
                dx = 0.0
            if j in (0, m):
                dy = 0.0
            if darts and i % 2 and j % 2 and 0 < i < n and 0 < j < m:
                # push the vertex across the diagonal of one of its cells: a dart
                dx, dy = rng.choice([-1, 1], 2) * rng.uniform(0.55, 0.7) * size
            verts.append((i * size + dx, j * size + dy))
    edges, kinds = [], []

    def add(a, b, boundary):
        edges.append((int(a), int(b)))
        kinds.append("B" if boundary else str(rng.choice(["M", "V", "U", "F"])))

    for j in range(m + 1):
        for i in range(n):
            add(ids[j, i], ids[j, i + 1], j in (0, m))
    for i in range(n + 1):
        for j in range(m):
            add(ids[j, i], ids[j + 1, i], i in (0, n))
    split = rng.random((m, n)) < draw(st.floats(0.0, 1.0))
    if n * m == 1:
        split[:] = True
    for j in range(m):
        for i in range(n):
            if split[j, i]:
                if rng.random() < 0.5:
                    add(ids[j, i], ids[j + 1, i + 1], False)
                else:
                    add(ids[j, i + 1], ids[j + 1, i], False)
    try:
        pattern = CreasePattern(verts, edges, kinds, source="random")
    except Exception:  # pragma: no cover - jitter made an invalid pattern
        assume(False)
    assume(len(pattern.creases) > 0)
    # geometry bounds for the "safe" widths: face angles (reflex ones included) at
    # least 15° away from 0°, 180° and 360°
    angles = np.degrees([interior_angle(pattern, f, v)[0] for f in range(len(pattern.faces))
                         for v in pattern.faces[f]])
    assume(np.abs(np.sin(np.radians(angles))).min() > math.sin(math.radians(15)))
    min_len = float(pattern.edge_lengths().min())
    scale = 0.05 * min_len if safe else draw(st.floats(0.05, 2.5)) * min_len
    widths = np.full(pattern.n_edges, np.nan)
    widths[pattern.creases] = scale * rng.uniform(0.05, 1.0, len(pattern.creases))
    if draw(st.booleans()):
        k = draw(st.integers(1, 6))
    else:
        k = np.zeros(pattern.n_edges, np.int64)
        k[pattern.creases] = rng.integers(1, 7, len(pattern.creases))
    H = draw(st.floats(0.05, 5.0))
    return pattern, widths, k, H


@given(jittered_grids())
@FAST
def test_invariants_random_grids(case):
    pattern, widths, k, H = case
    mesh = thicken(pattern, H, hinge_width=widths, subdivisions=k)
    check_mesh(pattern, mesh, H, widths=widths)


@given(jittered_grids(safe=False))
@FAST
def test_large_widths_error_or_valid_mesh(case):
    """Any width: either a MeshError, or a mesh meeting every invariant."""
    pattern, widths, k, H = case
    try:
        mesh = thicken(pattern, H, hinge_width=widths, subdivisions=k)
    except MeshError as exc:
        assert "face" in str(exc) or "edge" in str(exc)
        return
    check_mesh(pattern, mesh, H, widths=widths)


@st.composite
def star_vertices(draw):
    """Random vertex of degree 2..8: sectors in [20°, 270°] (one may be reflex),
    crease lengths 30..60 mm, widths 0.2..5 mm."""
    n = draw(st.integers(2, 8))
    lo, hi = 20.0, 270.0
    raw = np.array(draw(st.lists(st.floats(0.0, 1.0), min_size=n, max_size=n)))
    sectors = lo + raw / max(raw.sum(), 1e-9) * (360 - n * lo)
    assume(sectors.max() <= hi and abs(sectors.sum() - 360) < 1e-9)
    # unequal widths on nearly collinear creases cannot be mitered (see
    # test_straight_corner_unequal_widths_refused)
    assume(np.abs(sectors - 180).min() > 10)
    dirs = np.concatenate([[0.0], np.cumsum(sectors)[:-1]]) + draw(st.floats(0, 360))
    lengths = draw(st.lists(st.floats(30.0, 60.0), min_size=n, max_size=n))
    widths = draw(st.lists(st.floats(0.2, 5.0), min_size=n, max_size=n))
    return star(dirs, widths, lengths=lengths), draw(st.integers(1, 6)), draw(st.floats(0.1, 4))


@given(star_vertices())
@FAST
def test_invariants_random_vertices(case):
    pattern, k, H = case
    mesh = thicken(pattern, H, subdivisions=k)
    check_mesh(pattern, mesh, H)


def test_elastic_panels_are_cells_along_the_bar():
    """A bar face split into n cells: n prisms of the panel group, total volume kept,
    the cell next to the crease measures the fold; refusals name the face."""
    pattern = patterns.single_hinge(panel_length=40.0, depth=10.0, width=3.0)
    plain = thicken(pattern, 2.0, subdivisions=2)
    mesh = thicken(pattern, 2.0, subdivisions=2, elastic={1: 5}, stiffness={"panel": [1.0, 3.0]})
    panels = mesh.groups["rigid_panel"]
    assert len(panels) == 1 + 5 and list(panels.source) == [0, 1, 1, 1, 1, 1]
    assert panels.volumes.sum() == pytest.approx(plain.groups["rigid_panel"].volumes.sum())
    np.testing.assert_allclose(panels.weights[1:], 3.0 * panels.volumes[1:])
    first = mesh.points[panels.indices[panels.slots(int(mesh.panel_of_face[1]))][:4]]
    assert first[:, 0].min() == pytest.approx(1.5)          # it touches the hinge (W/2)
    assert mesh.n_vertices == plain.n_vertices + 2 * 2 * 4   # 4 cut lines, 2 points, 2 layers
    with pytest.raises(MeshError, match="face 1: the number of cells"):
        thicken(pattern, 2.0, elastic={1: 0})
    # panel 40 − W/2 = 38.5 mm long: cells of at most 5 mm → 8 cells
    auto = thicken(pattern, 2.0, elastic={1: "auto"}, cell_size=5.0)
    assert (auto.groups["rigid_panel"].source == 1).sum() == 8
    with pytest.raises(MeshError, match="'auto' needs a positive cell_size"):
        thicken(pattern, 2.0, elastic={1: "auto"})
    with pytest.raises(MeshError, match="face 7 does not exist"):
        thicken(pattern, 2.0, elastic={7: 3})
    grid = patterns.grid(2, 2, size=20.0, assignment="V")  # quads with two crease sides
    with pytest.raises(MeshError, match="only quadrilateral faces with exactly one crease"):
        thicken(grid, 1.0, elastic={0: 3})
    vertex = patterns.degree4_vertex(radius=20.0, widths=[1.0] * 4)  # not quads: rings
    assert thicken(vertex, 1.0, elastic={0: 3}).elastic == {0: ("rings", 3)}


# ============================================================ 2D elastic plates
def hanging_points(mesh) -> list:
    """Points lying inside another prism's footprint edge (a T-junction: the mesh would
    not conform there). Tolerance 1e-9 of the sheet size."""
    pts = mesh.points
    scale = float(np.ptp(pts, axis=0).max())
    bad = []
    for p in prisms_of(mesh):
        for a, b in zip(p.top, np.roll(p.top, -1)):
            d = pts[b] - pts[a]
            t = (pts - pts[a]) @ d / (d @ d)
            off = np.linalg.norm(pts - pts[a] - np.outer(t, d), axis=1)
            inside = (t > 1e-9) & (t < 1 - 1e-9) & (off < 1e-9 * scale)
            bad += [(p.kind, p.index, int(r)) for r in np.flatnonzero(inside)]
    return bad


def test_plate_cells_tile_the_panel_and_conform_with_the_split_hinge():
    """A plate face split n1 × n2: n1·n2 cells tiling the panel (same volume as the
    undivided mesh), every cell and strip sharing whole edges (no T-junctions), the
    crease's strip split into n2 segments along it, each segment k strips across."""
    pattern = patterns.single_hinge(panel_length=40.0, depth=20.0, width=3.0)
    plain = thicken(pattern, 2.0, subdivisions=2)
    mesh = thicken(pattern, 2.0, subdivisions=2, elastic={1: (4, 3)})
    panels, hinges = mesh.groups["rigid_panel"], mesh.groups["bending_hinge"]
    assert list(panels.source) == [0] + [1] * 12
    assert mesh.segments[0] == 3 and len(mesh.strips_of_crease[0]) == 2 * 3
    assert panels.volumes.sum() == pytest.approx(plain.groups["rigid_panel"].volumes.sum())
    assert hinges.volumes.sum() == pytest.approx(plain.groups["bending_hinge"].volumes.sum())
    assert not hanging_points(mesh)
    assert all(shoelace(mesh.points[p.top]) > 0 for p in prisms_of(mesh))
    union = shapely.union_all([p.poly for p in prisms_of(mesh)])
    assert union.area == pytest.approx(sum(p.poly.area for p in prisms_of(mesh)))
    # the measuring cell touches the crease side, at its middle (y from D/3 to 2D/3)
    first = mesh.points[panels.indices[panels.slots(int(mesh.panel_of_face[1]))][:4]]
    assert first[:, 0].min() == pytest.approx(1.5)
    assert sorted(np.unique(np.round(first[:, 1], 9))) == pytest.approx([20 / 3, 40 / 3])
    # the strip outline is still one rectangle W × crease length
    from foldcore.fabrication import sheet_outlines

    (strip,) = sheet_outlines(mesh)["HINGE"]
    assert shapely.Polygon(strip).area == pytest.approx(3.0 * 20.0)


def test_plates_on_both_sides_share_the_strip_segments_or_are_refused():
    """(n1, n2) count cells along a face's sides 0/2 and 1/3 in pattern order: face 0
    is [0, 1, 4, 5] (crease 0→1 is its side 0), face 1 is [0, 2, 3, 1] (side 3)."""
    pattern = patterns.single_hinge(panel_length=40.0, depth=20.0, width=3.0)
    mesh = thicken(pattern, 1.0, subdivisions=3, elastic={0: (4, 2), 1: (5, 4)})
    assert mesh.segments[0] == 4 and not hanging_points(mesh)
    assert len(mesh.groups["rigid_panel"]) == 4 * 2 + 5 * 4
    with pytest.raises(MeshError, match="faces 0 and 1 put 4 and 3 cells along their shared "
                                        "edge 0"):
        thicken(pattern, 1.0, elastic={0: (4, 2), 1: (5, 3)})
    with pytest.raises(MeshError, match="face 1: cell counts must be positive"):
        thicken(pattern, 1.0, elastic={1: (0, 3)})
    with pytest.raises(MeshError, match="face 1: give two cell counts"):
        thicken(pattern, 1.0, elastic={1: (2, 3, 4)})
    auto = thicken(pattern, 1.0, hinge_width=3.0, elastic={1: ("auto", "auto")}, cell_size=5.0)
    # inset panel 38.5 × 20 mm, cells of at most 5 mm: 8 × 4
    assert (auto.groups["rigid_panel"].source == 1).sum() == 8 * 4
    vertex = patterns.degree4_vertex(radius=20.0, widths=[1.0] * 4)
    with pytest.raises(MeshError, match="only quadrilateral faces can be gridded"):
        thicken(vertex, 1.0, elastic={1: (2, 2)})
    with pytest.raises(MeshError, match="stretch hinge"):
        thicken(pattern, 1.0, elastic={1: (2, 2)}, stretch={0: 0.3})
    with pytest.raises(MeshError, match="elastic bar on face 0 shares edge 0 with the plate "
                                        "on face 1"):
        thicken(pattern, 1.0, elastic={0: 3, 1: (2, 3)})


def test_plate_folded_by_a_compatible_hinge_stays_flat():
    """Hinge actuated to 90°, nothing else: the target is compatible, so the split
    strips fold as one and the plate's cells stay at their rest shapes (to the
    solver's tolerance, 1e-6 of the panel length) while the fold reaches 90°."""
    from foldcore.simulation import Simulation

    pattern = patterns.single_hinge(panel_length=20.0, depth=20.0, width=3.0, angle=90.0)
    mesh = thicken(pattern, 1.0, subdivisions=2, elastic={1: (4, 4)})
    result = Simulation(mesh, pattern).run(tolerance=1e-12, max_iterations=5_000)
    assert result.converged
    assert result.fold_angles_deg[0] == pytest.approx(90.0, abs=1e-4)
    cells = mesh.groups["rigid_panel"]
    x = result.positions
    for i in range(len(cells)):
        ids = cells.indices[cells.slots(i)]
        d_now = np.linalg.norm(x[ids][:, None] - x[ids][None], axis=2)
        d_rest = np.linalg.norm(cells.rest[cells.slots(i)][:, None]
                                - cells.rest[cells.slots(i)][None], axis=2)
        assert np.abs(d_now - d_rest).max() <= 1e-6 * 20.0
    assert mesh.crease_bends(result.strip_angles_deg)[0] == pytest.approx(90.0, abs=1e-3)


def test_every_quad_face_a_plate_on_a_grid_and_on_a_miura():
    """elastic="plates": a 3 × 2 grid of 20 mm squares with cells of ≤ 5 mm: 4 × 4 cells
    per face, every crease split into 4 segments, conforming. A Miura sheet's strips
    stop short of its parallelograms' acute/obtuse corners (Eq. 1 cuts): the gap
    becomes an extra grid column (or a triangle where the opposite side has none);
    still conforming, counter-clockwise, and the same volume as the undivided mesh."""
    grid = patterns.grid(3, 2, size=20.0, assignment="V")
    mesh = thicken(grid, 1.0, hinge_width=2.0, subdivisions=2, elastic="plates", cell_size=5.0)
    assert len(mesh.groups["rigid_panel"]) == 6 * 16
    assert set(mesh.segments[grid.creases]) == {4} and not hanging_points(mesh)
    sheet = mesh.groups["rigid_panel"].volumes.sum() + mesh.groups["bending_hinge"].volumes.sum()
    plain = thicken(grid, 1.0, hinge_width=2.0, subdivisions=2)
    assert sheet == pytest.approx(plain.volume())
    miura = patterns.miura(3, 3, a=20.0, b=20.0, gamma=60.0, width=2.0)
    plates = thicken(miura, 1.0, subdivisions=2, elastic="plates", cell_size=5.0)
    assert not hanging_points(plates)
    assert all(shoelace(plates.points[p.top]) > 0 for p in prisms_of(plates))
    assert plates.volume() == pytest.approx(thicken(miura, 1.0, subdivisions=2).volume())
    cells = [p for p in prisms_of(plates) if p.kind == "rigid_panel"]
    assert len(cells) > 9 * 16 and {len(p.top) for p in cells} <= {3, 4}
    with pytest.raises(MeshError, match="elastic must be a dict"):
        thicken(grid, 1.0, elastic="cells")


# ============================================================ elastic facets (rings)
def test_facets_are_rings_that_tile_every_face_and_conform():
    """elastic="facets": every face (here the waterbomb's triangles) cut into rings —
    scaled copies of its outline toward its centroid — quads between rings and a
    fan of triangles at the centre. The outline is the panel's own, so the cells
    tile it (same volume as the rigid mesh), share whole edges with the strips
    (no T-junctions), run counter-clockwise; the ring count is ⌈reach / cell_size⌉
    (reach: farthest outline point from the centroid)."""
    pattern = patterns.waterbomb(radius=30.0)
    plain = thicken(pattern, 1.0, subdivisions=2)
    mesh = thicken(pattern, 1.0, subdivisions=2, elastic="facets", cell_size=6.0)
    assert mesh.volume() == pytest.approx(plain.volume())
    assert not hanging_points(mesh)
    assert all(shoelace(mesh.points[p.top]) > 0 for p in prisms_of(mesh))
    panels = mesh.groups["rigid_panel"]
    for f in range(len(pattern.faces)):
        outline = plain.points[_top(plain, int(plain.panel_of_face[f]))]
        centre = shapely.Polygon(outline).centroid
        reach = max(np.hypot(*(p - np.array(centre.coords[0]))) for p in outline)
        rings = math.ceil(reach / 6.0)
        assert mesh.elastic[f] == ("rings", rings)
        # m outline points: m quads per ring between rings, m triangles at the centre
        assert (panels.source == f).sum() == len(outline) * rings
    with pytest.raises(MeshError, match="face 0: the number of rings must be"):
        thicken(pattern, 1.0, elastic={0: ("rings", 0)})
    with pytest.raises(MeshError, match="'auto' needs a positive cell_size"):
        thicken(pattern, 1.0, elastic="facets")


def _top(mesh, panel: int) -> np.ndarray:
    """Footprint point ids of a panel element's top loop."""
    group = mesh.groups["rigid_panel"]
    ids = group.indices[group.slots(panel)]
    return ids[: len(ids) // 2]


def test_facet_not_star_shaped_from_its_centroid_is_refused():
    """A C-shaped face (a 30 mm square with a 20 × 10 notch, filled by a square face)
    has its centroid (13.6, 15) in the notch, outside the face: refused, naming it."""
    v = [(0, 0), (30, 0), (30, 10), (10, 10), (10, 20), (30, 20), (30, 30), (0, 30)]
    e = [(0, 1), (1, 2), (2, 3), (3, 4), (4, 5), (5, 6), (6, 7), (7, 0), (2, 5)]
    pattern = CreasePattern(v, e, ["B", "B", "V", "V", "V", "B", "B", "B", "B"], source="c")
    (c_face,) = [f for f, face in enumerate(pattern.faces) if len(face) == 8]
    with pytest.raises(MeshError, match=f"face {c_face}: its outline is not star-shaped"):
        thicken(pattern, 1.0, hinge_width=1.0, elastic={c_face: ("rings", 2)})


def test_each_crease_is_measured_by_the_cells_beside_it():
    """On an elastic face each crease's fold angle comes from the face's cell nearest
    the crease's middle (a bent face is not counted as fold); the cell touches that
    crease's strip. Rigid faces measure with their one panel."""
    pattern = patterns.waterbomb(radius=30.0)
    mesh = thicken(pattern, 1.0, subdivisions=2, elastic="facets", cell_size=6.0)
    strips = mesh.groups["bending_hinge"]
    panels = mesh.groups["rigid_panel"]
    for e in pattern.creases:
        strip_ids = set(np.concatenate([strips.indices[strips.slots(int(s))]
                                        for s in mesh.strips_of_crease[int(e)]]))
        for side, f in enumerate(pattern.edge_faces[e]):
            cell = int(mesh.crease_panels[e, side])
            assert panels.source[cell] == f
            assert strip_ids & set(panels.indices[panels.slots(cell)])
    rigid = thicken(pattern, 1.0, subdivisions=2)
    left, right = rigid.measuring_panels(pattern, pattern.creases)
    np.testing.assert_array_equal(left, rigid.panel_of_face[pattern.edge_faces[pattern.creases, 0]])
    np.testing.assert_array_equal(right, rigid.panel_of_face[pattern.edge_faces[pattern.creases, 1]])


def test_facet_folded_by_a_compatible_hinge_stays_unstrained():
    """A hinge driven to 90° with its two faces in rings: the target is compatible,
    so the cells keep their rest shapes (to 1e-6 of the panel length) and the
    crease reaches 90° measured by the cells beside it."""
    from foldcore.simulation import Simulation

    pattern = patterns.single_hinge(panel_length=20.0, depth=20.0, width=3.0, angle=90.0)
    mesh = thicken(pattern, 1.0, subdivisions=2, elastic={0: ("rings", 2), 1: ("rings", 3)})
    result = Simulation(mesh, pattern).run(tolerance=1e-12, max_iterations=20_000)
    assert result.converged
    assert result.fold_angles_deg[0] == pytest.approx(90.0, abs=1e-4)
    cells, x = mesh.groups["rigid_panel"], result.positions
    for i in range(len(cells)):
        ids = cells.indices[cells.slots(i)]
        d_now = np.linalg.norm(x[ids][:, None] - x[ids][None], axis=2)
        rest = cells.rest[cells.slots(i)]
        d_rest = np.linalg.norm(rest[:, None] - rest[None], axis=2)
        assert np.abs(d_now - d_rest).max() <= 1e-6 * 20.0


# ------------------------------------------------------- widths fitted to small faces
def _strip_with_small_face():
    """A 100 × 10 mm strip with a 1 mm face at its left end: its crease x = 1 in two
    collinear halves (meeting a crease along y = 5 that runs to the right end)."""
    xy = [(0, 0), (1, 0), (100, 0), (100, 10), (1, 10), (0, 10), (1, 5), (100, 5)]
    edges = [(0, 1), (1, 2), (2, 7), (7, 3), (3, 4), (4, 5), (5, 0), (1, 6), (6, 4), (6, 7)]
    kinds = ["B"] * 7 + ["V", "V", "M"]
    return CreasePattern(xy, edges, kinds, fold_angles=[None] * 7 + [90.0, 90.0, -90.0])


def test_automatic_widths_too_wide_for_a_face_are_narrowed_with_their_collinear_creases():
    """Eq. 7's width at H = 2 mm (π mm) would inset the 1 mm face to nothing: its side's
    two collinear halves are halved together (a straight panel side keeps one inset),
    the crease elsewhere keeps Eq. 7's width; said once, in the mesh and the report."""
    from foldcore.errors import PatternWarning
    from foldcore.outputs import _narrowed_entries

    pattern = _strip_with_small_face()
    eq7 = minimum_hinge_width(2.0, 180.0)
    with pytest.warns(PatternWarning, match=r"2 hinges narrowed to fit small faces \(edge 7, "
                                            r"…; down to 0\.5 of Eq\. 7's width\)"):
        mesh = thicken(pattern, 2.0)
    np.testing.assert_allclose(mesh.hinge_width[7:], [eq7 / 2, eq7 / 2, eq7])
    assert mesh.width_share[7:].tolist() == [0.5, 0.5, 1.0]
    entries = _narrowed_entries(mesh)["narrowed_hinges"]
    assert [e["edge"] for e in entries] == [7, 8] and entries[0]["share_of_eq7"] == 0.5
    assert thicken(pattern.replace(vertices=pattern.vertices * 10), 2.0).width_share is None
    with pytest.raises(MeshError, match="face 0: hinge widths are too large for this face"):
        thicken(pattern, 2.0, hinge_width=eq7)  # widths the user gave are kept
