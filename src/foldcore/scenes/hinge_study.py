"""hinge-study — one hinge folded 180°: bend radius and angle error vs k (paper §6.1).

Provenance: the paper's hinge study — H = 0.5 mm, folded 180°, hinge width
W = 0.8 mm (Eq. 7 with r ≈ 0: the inner face's vertices coalesce) against
W = 1 mm, each with k = 2, 4, 8 sub-strips. Panels 5 mm × 5 mm (the paper's
panel size is not needed: the hinge alone sets the radius).

Each (W, k) is folded with each hinge model (:mod:`foldcore.hinges`):
Eq. 8's trapezoid targets (the paper's; a sub-strip of width W/k reaches at
most 2·atan(W/(kH)), so small k falls short), the constant-length arc (the
paper's Eq. 7 hinge: a flat fold keeps the inner faces 2r apart) and the
axis hinge (foldcore's default: past θ* = 2·atan(W/H), 116° at W = 0.8 mm,
the strip pivots about its inner surface, so a flat fold closes the inner
gap and the panels stack face to face, inner radius 0).

Quantities per (hinge model, W, k): the achieved fold angle and its error against 180°;
the inner bend radius measured from the folded hinge (circle through the
k + 1 inner-face vertices at one end of the crease, in the plane normal to
the crease) beside Eq. 7's r = W/θ − H/2; and the gap between the two
panels' inner faces (2r for a flat fold).
"""
from __future__ import annotations

import itertools

import numpy as np

from ..measure import wrapped_deg
from ..patterns import single_hinge
from ..simulation import Simulation
from ..thickening import thicken
from . import SceneRun
from ._measure import panel_normal

THICKNESS = 0.5  # mm
WIDTHS = (0.8, 1.0)  # mm
SUBDIVISIONS = (2, 4, 8)
MODELS = ("eq8", "arc", "axis")  # foldcore.hinges.HINGE_MODELS
PANEL, DEPTH = 5.0, 5.0  # mm
ANGLE = 180.0  # degrees
TOLERANCE = 1e-11
DEGENERATE_RADIUS = 100.0  # fitted radius / span of the inner points beyond which: no circle


def run(quick: bool = False, solver: str | None = None,
        contact="auto") -> SceneRun:
    """Fold the hinge for every (hinge model, W, k) (module docstring); the last is the result."""
    solver = solver or "rigid"
    budget = (100 if quick else 400) if solver == "rigid" else (5_000 if quick else 60_000)
    rows, gallery = [], []
    for model, width, k in itertools.product(MODELS, WIDTHS, SUBDIVISIONS):
        pattern = single_hinge(panel_length=PANEL, depth=DEPTH, angle=ANGLE, width=width)
        mesh = thicken(pattern, THICKNESS, subdivisions=k, hinge=model)
        result = Simulation(mesh, pattern, solver=solver, contact=contact).run(tolerance=TOLERANCE,
                                                             max_iterations=budget)
        achieved = float(result.fold_angles_deg[0])
        rows.append({
            "hinge": model, "width_mm": width,
            "subdivisions": k, "fold_angle_deg": round(achieved, 5),
            "angle_error_deg": round(abs(float(wrapped_deg(achieved - ANGLE))), 5),
            "inner_radius_mm": _rounded(inner_radius(mesh, result.positions)),
            "eq7_inner_radius_mm": round(float(width / np.radians(ANGLE)) - 0.5 * THICKNESS,
                                         5),
            "inner_gap_mm": round(inner_gap(pattern, mesh, result.positions), 5),
            "iterations": int(result.iterations), "converged": bool(result.converged)})
        gallery.append((f"{model} W {width:g} k {k}: {achieved:.2f}°", pattern, mesh,
                        result.positions))
    settings = {"solver": solver, "contact": result.contact is not None, "tolerance": TOLERANCE,
                "max_iterations": budget,
                "thickness_mm": THICKNESS, "panel_mm": PANEL, "depth_mm": DEPTH}
    return SceneRun("hinge-study", pattern, mesh, THICKNESS, result, {"runs": rows}, settings,
                    gallery)



def headline(quantities: dict) -> str:
    """One line for the demo: how many hinges, the largest angle error."""
    worst = max(r["angle_error_deg"] for r in quantities["runs"])
    return f"{len(quantities['runs'])} hinges, largest angle error {worst}°"


def _rounded(value, digits: int = 5):
    return None if value is None else round(value, digits)


def inner_points(mesh, positions: np.ndarray) -> np.ndarray:
    """(k+1, 3) inner-face (top, valley side) vertices at end a of crease 0, left to right."""
    hinges = mesh.groups["bending_hinge"]
    ids = [hinges.indices[hinges.slots(int(s))] for s in mesh.strips_of_crease[0]]
    order = [strip[0] for strip in ids] + [ids[-1][1]]  # top-left of each, then last top-right
    return positions[order]


def inner_radius(mesh, positions: np.ndarray) -> float | None:
    """Radius (mm) of the least-squares circle through :func:`inner_points`, in the plane
    normal to the crease (Kåsa fit; exact for points on a circle); None when the
    points are (nearly) collinear or coincide — an Eq. 8 inner face collapsed to a
    line has no radius (fitted radius > ``DEGENERATE_RADIUS`` × the points' span)."""
    hinges = mesh.groups["bending_hinge"]
    first = hinges.indices[hinges.slots(int(mesh.strips_of_crease[0][0]))]
    axis = positions[first[3]] - positions[first[0]]
    axis /= np.linalg.norm(axis)
    points = inner_points(mesh, positions)
    u = np.cross(axis, [1.0, 0.0, 0.0] if abs(axis[0]) < 0.9 else [0.0, 1.0, 0.0])
    u /= np.linalg.norm(u)
    v = np.cross(axis, u)
    xy = np.column_stack([points @ u, points @ v])
    lhs = np.column_stack([2 * xy, np.ones(len(xy))])
    (cx, cy, c), *_ = np.linalg.lstsq(lhs, (xy ** 2).sum(axis=1), rcond=None)
    radius = float(np.sqrt(max(c + cx * cx + cy * cy, 0.0)))
    span = float(np.ptp(xy, axis=0).max())
    return radius if radius <= DEGENERATE_RADIUS * span else None


def inner_gap(pattern, mesh, positions: np.ndarray) -> float:
    """Distance (mm) between the two panels' inner (top) faces, along the left panel's normal."""
    panels = mesh.groups[mesh.panel_group]
    tops = []
    for face in pattern.edge_faces[0]:
        ids = panels.indices[panels.slots(int(mesh.panel_of_face[face]))]
        tops.append(positions[ids[: len(ids) // 2]].mean(axis=0))
    normal = panel_normal(mesh, positions, int(pattern.edge_faces[0, 0]))
    return float(abs((tops[1] - tops[0]) @ normal))
