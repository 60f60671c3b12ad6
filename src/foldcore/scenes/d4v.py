"""d4v — Pehrson's flat-foldable degree-4 vertex (paper §5.1).

Provenance: the paper's parameters for Pehrson et al.'s acrylic vertex —
Ø152.4 mm disc, sectors 135/90/45/90°, H = 3.175 mm, hinge widths ≈ 16, 4, 8,
4 mm (:func:`foldcore.patterns.degree4_vertex` defaults; the circular rim is
replaced by straight chords, which changes no crease). M/V of mode A
(V, V, V, M). Crease 1 is actuated to 90° (intermediate state) and then to
180° (flat); the other creases are passive. k = 4 sub-strips per hinge.

What comes out, with the default axis hinge: the intermediate state is the
closed form (90, 45, 90, −45)°, because every crease is below its pivot angle
2·atan(W/H) = 157/103/136/103° there and the thick vertex folds as a
rigid-origami one. Toward flat all four creases pass their pivot angles, the
panels turn about their touching inner edges and the vertex binds short of
flat; the report lists the pivoting creases, the strips' misfit and the
panels' overlap (docs/architecture.md#scene-d4v-results). Folding a thick vertex
fully flat needs offsets or material strain that rigid panels and these
hinges do not provide.

Quantities: the four fold angles at both states beside the zero-thickness
closed form of mode A (:func:`foldcore.kinematics.degree4_mode_a`) at the
target and at the achieved ρ1, and the stack height at the flat state (extent
of the folded solid along the normal of the panel left of crease 1; n stacked
layers of H give ≥ n·H).
"""
from __future__ import annotations

from ..kinematics import degree4_deg
from ..patterns import PEHRSON_SECTORS, degree4_vertex
from ..simulation import Simulation
from ..thickening import thicken
from . import SceneRun
from ._measure import extent_along, panel_normal, rounded

THICKNESS = 3.175  # mm (1/8 in acrylic)
SUBDIVISIONS = 4
STATES = {"intermediate": 90.0, "flat": 180.0}  # crease 1 target, degrees
TOLERANCE = 1e-10  # relative step at which a state counts as reached


def run(quick: bool = False, solver: str | None = None) -> SceneRun:
    """Fold the vertex to its intermediate and flat states (see module docstring)."""
    solver = solver or "rigid"
    budget = (100 if quick else 400) if solver == "rigid" else (2_000 if quick else 40_000)
    pattern = degree4_vertex(mode="A", rho1=STATES["intermediate"])
    mesh = thicken(pattern, THICKNESS, subdivisions=SUBDIVISIONS)
    sim = Simulation(mesh, pattern, solver=solver)
    alpha, beta = PEHRSON_SECTORS[0], PEHRSON_SECTORS[1]
    quantities = {}
    for state, rho1 in STATES.items():
        sim.set_fold_angles({0: rho1})
        result = sim.run(tolerance=TOLERANCE, max_iterations=budget)
        angles = result.fold_angles_deg[:4]
        quantities[state] = {
            "target_rho1_deg": rho1,
            "fold_angles_deg": rounded(angles),
            "closed_form_at_target_deg": rounded(degree4_deg(alpha, beta, rho1, "A")),
            "closed_form_at_achieved_rho1_deg": rounded(
                degree4_deg(alpha, beta, min(abs(angles[0]), 180.0), "A")),
            "iterations": int(result.iterations), "converged": bool(result.converged)}
    normal = panel_normal(mesh, result.positions, int(pattern.edge_faces[0, 0]))
    quantities["flat"]["stack_height_mm"] = round(extent_along(result.positions, normal), 4)
    quantities["flat"]["stack_height_in_H"] = round(
        quantities["flat"]["stack_height_mm"] / THICKNESS, 3)
    settings = {"solver": solver, "tolerance": TOLERANCE, "max_iterations": budget,
                "thickness_mm": THICKNESS, "subdivisions": SUBDIVISIONS}
    return SceneRun("d4v", sim.pattern, mesh, THICKNESS, result, quantities, settings)


def headline(quantities: dict) -> str:
    """One line for the demo: crease 1 at 90° and driven toward flat (180°)."""
    flat, mid = quantities["flat"], quantities["intermediate"]
    return (f"crease 1 driven to 90°: {mid['fold_angles_deg'][0]}°, to 180°: "
            f"{flat['fold_angles_deg'][0]}°")
