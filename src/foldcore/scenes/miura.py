"""miura — a Miura-ori sheet on its rigid-folding path (paper §5).

Provenance: the standard Miura-ori (parallelogram facets a × b, acute angle
γ; :func:`foldcore.patterns.miura`); the paper uses it at any size as its
1-DOF example and scaling scene. Here: 4 × 4 facets, a = b = 20 mm, γ = 60°,
H = 1 mm, hinge width W = 2 mm (k = 2).

Actuation: every crease to its zero-thickness rigid-fold angle at facet
tilt θ = 30° (:func:`foldcore.kinematics.miura_angles`: zig-zag |ρ| = 2θ,
straight tan(|ρ|/2) = cos γ tan θ), signed by its M/V. With the default axis
hinge (:mod:`foldcore.hinges`) these angles are exactly compatible at any
thickness, so the sheet reaches them; with ``hinge="arc"`` (the paper's,
whose hinge axes sit off the crease lines) it misses them
(docs/architecture.md#scene-miura-results). One crease driven alone folds the
whole sheet too (``tests/test_accuracy.py``, ``bench/accuracy.py``).

Quantities: per crease family (zig-zag, straight) the closed-form angle, the
achieved mean, and the largest deviation; the folded sheet's extents along
x and y (centroids of the corner facets, whose distance is (n − 1)·L along x
and (m − 1)·S along y in the zero-thickness closed form,
:func:`foldcore.kinematics.miura_cell`:
L = a√(1 − sin²θ sin²γ), S = b cosθ tanγ/√(1 + cos²θ tan²γ)).
"""
from __future__ import annotations

import numpy as np

from ..kinematics import miura_angles_deg, miura_cell
from ..patterns import miura, miura_edge_kinds, miura_fold_angles
from ..simulation import Simulation
from ..thickening import thicken
from . import SceneRun

N, M = 4, 4  # facets along x and y
A, B, GAMMA = 20.0, 20.0, 60.0  # mm, mm, degrees
THICKNESS, WIDTH, SUBDIVISIONS = 1.0, 2.0, 2
TILT = 30.0  # facet tilt θ, degrees
TOLERANCE = 1e-10


def run(quick: bool = False, solver: str | None = None,
        contact="auto") -> SceneRun:
    """Fold the sheet to tilt θ with every crease actuated (see module docstring)."""
    solver = solver or "rigid"
    budget = (100 if quick else 400) if solver == "rigid" else (2_000 if quick else 40_000)
    expected = miura_fold_angles(N, M, GAMMA, TILT)
    pattern = miura(N, M, a=A, b=B, gamma=GAMMA, width=WIDTH).replace(fold_angles=expected)
    kinds = miura_edge_kinds(N, M)
    zigzag, straight = miura_angles_deg(GAMMA, TILT)
    mesh = thicken(pattern, THICKNESS, subdivisions=SUBDIVISIONS)
    result = Simulation(mesh, pattern, solver=solver, contact=contact).run(tolerance=TOLERANCE,
                                                         max_iterations=budget)
    quantities = {"tilt_deg": TILT, "iterations": int(result.iterations),
                  "converged": bool(result.converged)}
    for family, closed in (("zigzag", zigzag), ("straight", straight)):
        chosen = kinds == family
        achieved = np.abs(result.fold_angles_deg[chosen])
        quantities[family] = {"closed_form_deg": round(float(closed), 4),
                              "achieved_mean_deg": round(float(achieved.mean()), 4),
                              "max_deviation_deg": round(float(np.abs(achieved - closed).max()), 4)}
    quantities["extent_mm"] = _extents(pattern, mesh, result.positions)
    settings = {"solver": solver, "contact": result.contact is not None, "tolerance": TOLERANCE,
                "max_iterations": budget,
                "thickness_mm": THICKNESS, "hinge_width_mm": WIDTH,
                "subdivisions": SUBDIVISIONS, "n": N, "m": M, "a_mm": A, "b_mm": B,
                "gamma_deg": GAMMA}
    return SceneRun("miura", pattern, mesh, THICKNESS, result, quantities, settings)



def headline(quantities: dict) -> str:
    """One line for the demo: the largest deviation from the rigid-fold angles."""
    worst = max(quantities[k]["max_deviation_deg"] for k in ("zigzag", "straight"))
    return f"largest deviation from the rigid-fold angles {worst}°"


def _extents(pattern, mesh, positions) -> dict:
    """Distances between corner facets' centroids along the two lattice directions,
    folded, beside the zero-thickness closed form (mm)."""
    _, width, length, _ = miura_cell(A, B, np.radians(GAMMA), np.radians(TILT))
    panels = mesh.groups[mesh.panel_group]
    centroid = [positions[panels.indices[panels.slots(int(mesh.panel_of_face[f]))]].mean(axis=0)
                for f in range(len(pattern.faces))]
    first_row, last_in_row = 0, N - 1  # faces are row by row, i fastest (patterns.miura)
    along_x = float(np.linalg.norm(centroid[last_in_row] - centroid[first_row]))
    along_y = float(np.linalg.norm(centroid[(M - 1) * N] - centroid[first_row]))
    return {"corner_panels_x": round(along_x, 4), "closed_form_x": round((N - 1) * length, 4),
            "corner_panels_y": round(along_y, 4), "closed_form_y": round((M - 1) * width, 4)}
