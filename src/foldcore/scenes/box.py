"""box — a five-crease multiple-vertex box folded at H = 1 mm and H = 4 mm (paper §6.2).

Provenance. The paper folds "the five-crease multiple-vertex origami used by
Chen et al. [4] to make boxes (Fig. 2 of their paper)": six vertices, five
hinges at each; folded, "the two panels adjacent to the mountain-fold hinge
are put together and protrude in the inside volume". Chen, Peng & You's
pattern (Science 2015, Fig. 2) is **not available here**, so this scene
uses a **reconstruction** from that description, not the source pattern: a
hexagonal tray (:func:`hexagonal_tray`) —

* bottom: a regular hexagon of side ``SIDE`` = 50 mm;
* six rectangular walls ``SIDE`` × ``HEIGHT`` (25 mm) hinged on its edges;
* between neighbouring walls a gusset of two right triangles (30° apex at
  the bottom corner, legs ``HEIGHT`` and ``HEIGHT``·tan 30°) split by a
  mountain diagonal.

Each bottom corner is a degree-5 vertex with sectors 120° (bottom), 90°
(wall), 30°, 30° (gusset), 90° (wall). The flat sheet is a regular hexagon
of apothem a + h (a = SIDE·√3/2): the gusset's outer sides continue the wall
tops. Folded as a thin sheet (:func:`thin_tray`, sheet top inside the box,
valley positive): bottom–wall creases +90°, wall–gusset creases +120° (the
top-side dihedral between a wall and its gusset triangle is 60°, half the
corner's 120°), gusset diagonal −180° (the triangles' bottom faces pressed
together into a fin on the corner's bisector plane, pointing inward). These
angles come from geometry and are checked numerically: the thin folded
state is an isometry of the pattern with exactly these fold angles (tests).

Thickening: every crease gets Eq. 7's width for a 180° fold, W = πH/2
(1.57 mm at H = 1 mm, 6.28 mm at H = 4 mm, the paper's numbers), k = 4
sub-strips (§6.1's 3–4), the default axis hinge; the crease pattern is the same
at both thicknesses, the thick 2D sheets are not (panels inset by W/2, larger
residual holes at the vertices). Every crease is actuated to its thin-sheet
angle. Solver: ``rigid`` by default, which converges at both H and keeps the
180° mountain at its bound where the local/global strategies let the fin
fold through itself (docs/architecture.md#scene-box-results).

What comes out (measured, not imposed): the thick tray cannot close its
corners exactly. With W = πH/2 the axis hinge pivots about its inner edges
past θ* = 2·atan(π/2) = 115° (:mod:`foldcore.hinges`), so the 120° side
creases and the 180° diagonal turn about lines off their crease lines, and
each corner binds; the least-squares compromise tilts the walls outward and
the box is a slightly flared tray, more so when thicker. The tilt does not
vanish as H → 0 with W = πH/2: the pivot offsets and the hinges' compliance
both scale with H, so only the panels' finite size makes it grow with H.
Real thick boxes avoid this with offsets (Chen et al.'s varied panel
thickness), not SJT. The 4 mm box keeps a smaller share of the thin tray's
capacity at the same tilt and a smaller absolute capacity: the paper's "the
volume of the box is also reduced".

Quantities per thickness (``runs``): iterations, convergence, wall time;
per crease family (bottom, side, diagonal) the target, the achieved mean
/ min / max (panel mid-planes; the diagonal unwrapped past ±180° with the
hinge's own bend) and the thin-sheet angle on the symmetric rigid path at
the achieved bottom angle; the wall tilt from vertical; how far the gusset
panels' centroids sit inside the corners (``fin_inward_mm``); the thick 2D sheet
(outer outline area, bounding size, panel / hinge / hole areas, mm²); and
volumes (mm³):

* ``material`` — the folded solid's own volume (its closed outer surface,
  :func:`foldcore.surface.enclosed_volume`), beside its rest volume;
* ``capacity`` = volume of the convex hull of the folded solid − material.
  It counts the fins and the walls' thickness as lost capacity; it also
  counts as capacity the small gaps between the hull and the outer
  surface (residual holes, rounded bottom edges), O(W²·perimeter);
* ``thin_same_tilt`` — the zero-thickness tray on its rigid path with the
  same bottom and the same (achieved) wall tilt: its convex hull volume
  (:func:`thin_capacity`; at 90° this is the hexagonal prism, hand formula
  (3√3/2)·SIDE²·HEIGHT, :data:`THIN_BOX_MM3`).

The SceneRun's pattern/mesh/result (FOLD, PNG) are the H = 4 mm box, where
thickness shows most.
"""
from __future__ import annotations

import time

import numpy as np

from ..fabrication import sheet_outlines
from ..surface import enclosed_volume, surface_triangles
from ..measure import dihedral_deg
from ..pattern import CreasePattern
from ..simulation import Simulation
from ..strain import estimated_strip_angles
from ..thickening import minimum_hinge_width, thicken
from . import SceneRun
from ._measure import panel_normal, rounded

SIDE, HEIGHT = 50.0, 25.0  # mm: hexagon side, wall height
THICKNESSES = (1.0, 4.0)  # mm
SIZING_ANGLE = 180.0  # degrees: Eq. 7 widths are sized for the 180° fin fold
SUBDIVISIONS = 4
TOLERANCE = 1e-10
#: Thin-sheet fold angle (degrees, valley > 0) of each crease family.
TARGETS = {"bottom": 90.0, "side": 120.0, "diagonal": -180.0}
#: Crease families of one corner's seven edges (hexagonal_tray's order); "" = boundary.
CORNER_EDGES = ("bottom", "side", "diagonal", "side", "", "", "")
N_CORNERS = 6
APEX = np.radians(30.0)  # gusset triangle angle at the bottom corner
#: Zero-thickness box capacity, mm³: hexagon area × wall height (hand formula).
THIN_BOX_MM3 = 1.5 * np.sqrt(3.0) * SIDE ** 2 * HEIGHT


def run(quick: bool = False, solver: str | None = None,
        contact="auto") -> SceneRun:
    """Fold the tray at H = 1 mm and 4 mm (see module docstring); the result is 4 mm."""
    solver = solver or "rigid"
    budget = (300 if quick else 400) if solver == "rigid" else (5_000 if quick else 40_000)
    rows = []
    for thickness in THICKNESSES:
        start = time.perf_counter()
        pattern, mesh, result = fold(thickness, solver, budget, contact)
        rows.append(measure(pattern, mesh, result, thickness, time.perf_counter() - start))
    quantities = {"thin_box_mm3": round(float(THIN_BOX_MM3), 2), "runs": rows}
    settings = {"solver": solver, "contact": result.contact is not None, "tolerance": TOLERANCE,
                "max_iterations": budget,
                "thicknesses_mm": list(THICKNESSES), "side_mm": SIDE, "height_mm": HEIGHT,
                "subdivisions": SUBDIVISIONS, "shown_thickness_mm": THICKNESSES[-1]}
    return SceneRun("box", pattern, mesh, THICKNESSES[-1], result, quantities, settings)


def headline(quantities: dict) -> str:
    """One line for the demo: per thickness, the capacity, the walls' flare and the
    share of the thin tray's capacity at that flare."""
    return "; ".join(
        f"H {r['thickness_mm']:g} mm: {r['volume_mm3']['capacity'] / 1e3:.1f} cm³, walls "
        f"flared {r['wall_tilt_deg']:.1f}°, {r['volume_mm3']['capacity_vs_thin_same_tilt']:.3f}"
        " of the thin tray" for r in quantities["runs"])


def fold(thickness: float, solver: str, budget: int, contact="auto"):
    """Build, thicken and fold the tray at one thickness H (mm) (``contact``: panels
    kept from passing through each other).

    Returns
    -------
    pattern : CreasePattern
        With Eq. 7 widths W = (H/2)·π and every crease actuated to its target.
    mesh : ThickMesh
    result : Result
    """
    width = float(minimum_hinge_width(thickness, SIZING_ANGLE))
    pattern = hexagonal_tray(SIDE, HEIGHT, width)
    mesh = thicken(pattern, thickness, subdivisions=SUBDIVISIONS)
    result = Simulation(mesh, pattern, solver=solver, contact=contact).run(
        tolerance=TOLERANCE, max_iterations=budget)
    return pattern, mesh, result


# ------------------------------------------------------------------ geometry
def hexagonal_tray(side: float, height: float, width: float | None = None) -> CreasePattern:
    """The reconstructed five-crease box pattern (module docstring), actuated.

    Parameters
    ----------
    side : float, mm
        Side of the regular hexagonal bottom.
    height : float, mm
        Wall height (the gusset triangles' long leg).
    width : float, mm, optional
        Hinge width of every crease (None: chosen by ``thicken``).

    Returns
    -------
    CreasePattern
        Vertices: bottom corners P_i (ids 0–5, P_i at angle 60°·i), then per
        corner i the wall-top corner of wall i−1 (6 + 3i), the gusset apex
        R_i (7 + 3i) and the wall-top corner of wall i (8 + 3i). Edges: 7 per
        corner (:data:`CORNER_EDGES`): P_i→P_i+1 (bottom, V), P_i→top of wall
        i−1 (side, V), P_i→R_i (diagonal, M), P_i→top of wall i (side, V),
        then the boundary (B) top of wall i−1→R_i→top of wall i→next corner.
    """
    corners = _hexagon(side)
    vertices, edges = list(corners), []
    for i in range(N_CORNERS):
        before, after = _outward_normal(corners, i - 1), _outward_normal(corners, i)
        radial = corners[i] / np.linalg.norm(corners[i])
        first = len(vertices)
        vertices += [corners[i] + height * before, corners[i] + height / np.cos(APEX) * radial,
                     corners[i] + height * after]
        top_next = N_CORNERS + 3 * ((i + 1) % N_CORNERS)
        edges += [(i, (i + 1) % N_CORNERS), (i, first), (i, first + 1), (i, first + 2),
                  (first, first + 1), (first + 1, first + 2), (first + 2, top_next)]
    families = crease_families(len(edges))
    assignments = ["B" if not f else ("M" if TARGETS[f] < 0 else "V") for f in families]
    angles = [TARGETS[f] if f else None for f in families]
    widths = [width if f else None for f in families]
    return CreasePattern(np.array(vertices), edges, assignments, fold_angles=angles,
                         widths=widths, source="box (reconstructed hexagonal tray)")


def crease_families(n_edges: int) -> np.ndarray:
    """(E,) str: "bottom", "side", "diagonal" or "" (boundary) per edge of the tray."""
    return np.array(CORNER_EDGES * (n_edges // len(CORNER_EDGES)))


def _hexagon(side: float) -> np.ndarray:
    """(6, 2) corners of the regular hexagon of ``side`` mm, CCW, corner i at 60°·i."""
    phi = np.radians(60.0 * np.arange(N_CORNERS))
    return side * np.column_stack([np.cos(phi), np.sin(phi)])


def _outward_normal(corners: np.ndarray, i: int) -> np.ndarray:
    """(2,) outward unit normal of the hexagon side P_i → P_i+1 (indices mod 6)."""
    d = corners[(i + 1) % len(corners)] - corners[i % len(corners)]
    return np.array([d[1], -d[0]]) / np.linalg.norm(d)


def thin_tray(side: float, height: float, bottom_deg: float = 90.0) -> np.ndarray:
    """(V, 3) mm: the zero-thickness tray with every bottom crease folded ``bottom_deg``.

    The symmetric rigid-folding path (every corner mirror-symmetric about its
    bisector plane, fins inward): walls rotate about the bottom edges; each
    gusset apex R_i lies in the bisector plane at |P R| = h/cos 30° from the
    corner and |T R| = h·tan 30° from both wall tops (two circles). At 90°
    the walls stand vertical and the fin closes flat (the TARGETS).
    Vertex order as :func:`hexagonal_tray`.
    """
    rho = np.radians(bottom_deg)
    corners = _hexagon(side)
    ez = np.array([0.0, 0.0, 1.0])
    out = [np.append(c, 0.0) for c in corners]
    for i in range(N_CORNERS):
        p = out[i]
        before, after = _outward_normal(corners, i - 1), _outward_normal(corners, i)
        tops = [p + height * (np.cos(rho) * np.append(n, 0.0) + np.sin(rho) * ez)
                for n in (before, after)]
        inward = -np.append(corners[i], 0.0) / np.linalg.norm(corners[i])
        out += [tops[0], p + _apex_in_plane(height, rho, inward, ez), tops[1]]
    return np.array(out)


def _apex_in_plane(height: float, rho: float, inward: np.ndarray, ez: np.ndarray):
    """(3,) offset of the gusset apex from its corner: the inward intersection, in
    the bisector plane (coordinates r along ``inward``, z up), of the circle of
    radius h/cos 30° about the corner and the section of the sphere of radius
    h·tan 30° about a wall top (at r = −h cos ρ cos 30°, z = h sin ρ, off-plane
    h cos ρ sin 30°)."""
    top = np.array([-height * np.cos(rho) * np.cos(APEX), height * np.sin(rho)])
    off_plane = height * np.cos(rho) * np.sin(APEX)
    r1 = height / np.cos(APEX)
    r2 = np.sqrt((height * np.tan(APEX)) ** 2 - off_plane ** 2)
    d = np.linalg.norm(top)
    along = (r1 ** 2 - r2 ** 2 + d ** 2) / (2.0 * d)
    across = np.sqrt(max(r1 ** 2 - along ** 2, 0.0))
    unit = top / d
    normal = np.array([unit[1], -unit[0]])
    candidates = [along * unit + s * across * normal for s in (1.0, -1.0)]
    r, z = max(candidates, key=lambda c: c[0])
    return r * inward + z * ez


def thin_fold_angles(pattern: CreasePattern, positions: np.ndarray) -> np.ndarray:
    """(E,) fold angles (degrees, valley > 0, NaN on B) of a zero-thickness folded state.

    Same convention as :func:`foldcore.measure.fold_angles`: with the face
    normals n_L, n_R (Newell, the pattern's CCW loops) and the crease
    direction d, ρ = atan2((n_R × n_L)·d, n_L·n_R) (:func:`foldcore.measure.dihedral_deg`).
    """
    normals = np.array([_newell(positions[f]) for f in pattern.faces])
    out = np.full(pattern.n_edges, np.nan)
    crease = pattern.creases
    n_left = normals[pattern.edge_faces[crease, 0]]
    n_right = normals[pattern.edge_faces[crease, 1]]
    d = positions[pattern.edges[crease, 1]] - positions[pattern.edges[crease, 0]]
    out[crease] = dihedral_deg(n_left, n_right, d)
    return out


def _newell(loop: np.ndarray) -> np.ndarray:
    """(3,) unit normal of a planar polygon loop (n, 3)."""
    n = np.cross(loop, np.roll(loop, -1, axis=0)).sum(axis=0)
    return n / np.linalg.norm(n)


def isometry_error(pattern: CreasePattern, positions: np.ndarray) -> float:
    """Largest change (mm) of a distance between two vertices of one face, flat → folded."""
    worst = 0.0
    flat = np.column_stack([pattern.vertices, np.zeros(pattern.n_vertices)])
    for face in pattern.faces:
        a, b = flat[face], positions[face]
        da = np.linalg.norm(a[:, None] - a[None], axis=2)
        db = np.linalg.norm(b[:, None] - b[None], axis=2)
        worst = max(worst, float(np.abs(da - db).max()))
    return worst


def thin_capacity(side: float, height: float, bottom_deg: float = 90.0) -> float:
    """Convex-hull volume (mm³) of the zero-thickness tray at ``bottom_deg`` (its capacity:
    a thin sheet has no volume). At 90° it is (3√3/2)·side²·height."""
    from scipy.spatial import ConvexHull

    return float(ConvexHull(thin_tray(side, height, bottom_deg)).volume)


# --------------------------------------------------------------- measuring
def measure(pattern, mesh, result, thickness: float, seconds: float) -> dict:
    """JSON-ready quantities of one folded thickness (module docstring)."""
    angles = unwrapped_fold_angles(pattern, mesh, result)
    families = crease_families(pattern.n_edges)
    bottom = float(angles[families == "bottom"].mean())
    thin = thin_fold_angles(pattern, thin_tray(SIDE, HEIGHT, bottom))
    per_family = {}
    for family, target in TARGETS.items():
        chosen = families == family
        per_family[family] = {
            "target_deg": target, "achieved_mean_deg": round(float(angles[chosen].mean()), 4),
            "achieved_min_deg": round(float(angles[chosen].min()), 4),
            "achieved_max_deg": round(float(angles[chosen].max()), 4),
            "thin_path_at_achieved_bottom_deg": round(float(
                toward(thin[chosen], target).mean()), 4)}
    return {"thickness_mm": thickness,
            "hinge_width_mm": round(float(np.nanmax(mesh.hinge_width)), 4),
            "iterations": int(result.iterations), "converged": bool(result.converged),
            "seconds": round(seconds, 3), "fold_angles_deg": per_family,
            "wall_tilt_deg": round(90.0 - bottom, 4),
            "fin_inward_mm": round(fin_inward(pattern, mesh, result.positions), 4),
            "sheet_mm2": sheet_areas(mesh),
            "volume_mm3": volumes(mesh, result.positions, bottom)}


def unwrapped_fold_angles(pattern, mesh, result) -> np.ndarray:
    """(E,) panel-measured fold angles (degrees), each shifted by a multiple of 360° to
    the side of ±180° its hinge's own bend (Σ of its sub-strips' Eq. 9 angles) is on."""
    bends = np.degrees(estimated_strip_angles(mesh.groups["bending_hinge"], result.positions))
    return toward(result.fold_angles_deg, mesh.crease_bends(bends))


def toward(angles, reference) -> np.ndarray:
    """(n,) ``angles`` (degrees) + 360°·k, integer k per entry chosen to land nearest
    ``reference`` (n,) degrees (e.g. +179.9° read as −180.1° beside a −180° target)."""
    angles = np.asarray(angles, dtype=float)
    return angles + 360.0 * np.round((np.asarray(reference, dtype=float) - angles) / 360.0)


def fin_inward(pattern, mesh, positions: np.ndarray) -> float:
    """Mean distance (mm) by which the gusset panels' centroids lie inside the corners:
    SIDE minus their horizontal distance from the box axis (the bottom panel's normal
    through its centroid, which is the hexagon's centre). Positive: the fins protrude
    into the box; the thin box at 90° gives HEIGHT·tan 30°/3."""
    bottom = next(f for f, loop in enumerate(pattern.faces) if len(loop) == N_CORNERS)
    axis = panel_normal(mesh, positions, bottom)
    apexes = N_CORNERS + 1 + 3 * np.arange(N_CORNERS)
    gussets = [f for f, loop in enumerate(pattern.faces) if np.isin(loop, apexes).any()]
    offsets = np.array([_panel_centroid(mesh, positions, f) for f in gussets]) \
        - _panel_centroid(mesh, positions, bottom)
    radial = offsets - np.outer(offsets @ axis, axis)
    return float(SIDE - np.linalg.norm(radial, axis=1).mean())


def _panel_centroid(mesh, positions: np.ndarray, face: int) -> np.ndarray:
    """(3,) mean of the vertices (mm) of the panel of pattern face ``face``."""
    panels = mesh.groups[mesh.panel_group]
    return positions[panels.indices[panels.slots(int(mesh.panel_of_face[face]))]].mean(axis=0)


def sheet_areas(mesh) -> dict:
    """The thick 2D sheet (mm², mm): outer outline area, bounding size, and the areas of
    panels, hinge strips and residual holes (outline = panels + hinges + holes)."""
    import shapely

    outlines = sheet_outlines(mesh)
    cut = sorted((shapely.Polygon(p).area for p in outlines["CUT"]), reverse=True)
    area = {name: sum(shapely.Polygon(p).area for p in outlines[name])
            for name in ("PANEL", "HINGE")}
    return {"outline": round(float(cut[0]), 3), "holes": round(float(sum(cut[1:])), 3),
            "panels": round(float(area["PANEL"]), 3), "hinges": round(float(area["HINGE"]), 3),
            "bounding_mm": rounded(np.ptp(mesh.points, axis=0), 3)}


def volumes(mesh, positions: np.ndarray, bottom_deg: float) -> dict:
    """Material, convex hull, capacity (hull − material) of the folded solid and the thin
    tray at the same wall tilt, mm³ (module docstring)."""
    from scipy.spatial import ConvexHull

    material = enclosed_volume(positions, surface_triangles(mesh))
    hull = float(ConvexHull(positions).volume)
    thin = thin_capacity(SIDE, HEIGHT, bottom_deg)
    return {"material": round(material, 2), "material_rest": round(mesh.volume(), 2),
            "hinge_rest": round(float(mesh.groups["bending_hinge"].volumes.sum()), 2),
            "hull": round(hull, 2), "capacity": round(hull - material, 2),
            "thin_same_tilt": round(thin, 2),
            "capacity_vs_thin_same_tilt": round((hull - material) / thin, 5)}
