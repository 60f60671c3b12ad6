"""d4v — Pehrson's flat-foldable degree-4 vertex (paper §5.1).

Provenance: the paper's parameters for Pehrson et al.'s acrylic vertex —
Ø152.4 mm disc, sectors 135/90/45/90°, H = 3.175 mm, hinge widths ≈ 16, 4, 8,
4 mm (:func:`foldcore.patterns.degree4_vertex` defaults; the circular rim is
replaced by straight chords, which changes no crease). M/V of mode A
(V, V, V, M). Crease 1 is actuated to 90° (intermediate state); then every
crease is driven to ±180° (flat). k = 4 sub-strips per hinge.

Which crease gets which width: folded flat, a degree-4 vertex stacks its four
panels in four layers, and the crease opposite the one whose M/V differs
(crease 2 here) wraps around the other two panels: its panels are three
layers apart, the others' one. The paper's rule "the largest hinge at least
as wide as the other three together" puts 16 mm there and 8 mm opposite it
(:func:`foldcore.patterns.wrapping_crease`).

Which hinge the prototype's joints are: ``slack`` (:mod:`foldcore.hinges`).
Flat, the wrapping crease must hold its panels 3H = 9.5 mm apart, which a
strip 16 mm wide does (an arc of that length spans up to 2W/π = 10.2 mm); the
axis hinge would hold them H apart whatever its width, so the vertex binds
(``bench/flat_vertex.py`` measures all three models). The arc hinge folds flat too (its
widths close the loop: 16 = 4 + 8 + 4), but holds the 4 mm creases' panels
2W/π = 2.5 mm apart, less than H: they would interpenetrate, and its axes
drift off the creases on the way. A slack strip, like the prototype's
compliant joints, bends on an arc of any length from the axis hinge's (its
panels turn about the crease) to its width W (H·|θ|/2 where that is longer:
the 4 mm joints stretch to 5 mm flat): the intermediate state is the
rigid-origami one and the flat state stacks the layers at least H apart.

Quantities: the four fold angles at both states beside the zero-thickness
closed form of mode A (:func:`foldcore.kinematics.degree4_mode_a`) at the
target and at the achieved ρ1; flat: the stack height (extent of the folded
solid along the normal of the panel left of crease 1; four layers of H give
≥ 4H), the panels' layers (mid-planes closer than H/2 are one layer) and the
smallest distance between the mid-planes of consecutive layers (≥ H: no two
panels interpenetrate).
"""
from __future__ import annotations

import numpy as np

from ..kinematics import degree4_deg
from ..patterns import PEHRSON_SECTORS, degree4_vertex
from ..simulation import Simulation
from ..thickening import thicken
from . import SceneRun
from ._measure import extent_along, panel_normal, rounded

THICKNESS = 3.175  # mm (1/8 in acrylic)
SUBDIVISIONS = 4
HINGE = "slack"
INTERMEDIATE = 90.0  # crease 1 target, degrees
TOLERANCE = 1e-10  # relative step at which a state counts as reached


def run(quick: bool = False, solver: str | None = None,
        contact="auto") -> SceneRun:
    """Fold the vertex to its intermediate and flat states (see module docstring)."""
    budget = 1_000 if quick else 2_000
    pattern = degree4_vertex(mode="A", rho1=INTERMEDIATE)
    mesh = thicken(pattern, THICKNESS, subdivisions=SUBDIVISIONS, hinge=HINGE)
    sim = Simulation(mesh, pattern, contact=contact, **({"solver": solver} if solver else {}))
    sign = np.where(pattern.assignments[:4] == "M", -1.0, 1.0)
    targets = {"intermediate": {0: INTERMEDIATE},
               "flat": {i: 180.0 * sign[i] for i in range(4)}}
    alpha, beta = PEHRSON_SECTORS[0], PEHRSON_SECTORS[1]
    quantities = {}
    for state, target in targets.items():
        sim.set_fold_angles(target)
        before = sim.iterations
        result = sim.run(tolerance=TOLERANCE, max_iterations=budget)
        angles = result.fold_angles_deg[:4]
        quantities[state] = {
            "targets_deg": rounded([target.get(i, np.nan) for i in range(4)]),
            "fold_angles_deg": rounded(angles),
            "closed_form_at_target_deg": rounded(degree4_deg(alpha, beta, target[0], "A")),
            "closed_form_at_achieved_rho1_deg": rounded(
                degree4_deg(alpha, beta, min(abs(angles[0]), 180.0), "A")),
            "iterations": int(result.iterations - before), "converged": bool(result.converged)}
    quantities["flat"].update(stack(mesh, pattern, result.positions))
    settings = {"solver": sim.solver, "contact": sim.model.contact is not None, "hinge": HINGE,
                "tolerance": TOLERANCE, "max_iterations": budget, "thickness_mm": THICKNESS,
                "subdivisions": SUBDIVISIONS}
    return SceneRun("d4v", sim.pattern, mesh, THICKNESS, result, quantities, settings)


def stack(mesh, pattern, positions: np.ndarray) -> dict:
    """Stack height (mm and × H), layers and smallest gap between consecutive layers'
    mid-planes (mm) of the folded vertex, along the normal of the panel left of
    crease 1."""
    normal = panel_normal(mesh, positions, int(pattern.edge_faces[0, 0]))
    height = extent_along(positions, normal)
    panels = mesh.groups[mesh.panel_group]
    levels = np.sort([positions[panels.indices[panels.slots(p)]].mean(axis=0) @ normal
                      for p in range(len(panels))])
    gaps = np.diff(levels)
    layers = 1 + int(np.sum(gaps > 0.5 * THICKNESS))
    return {"stack_height_mm": round(height, 4),
            "stack_height_in_H": round(height / THICKNESS, 3),
            "layers": layers,
            "smallest_layer_gap_mm": round(float(gaps.min()), 4) if len(gaps) else None}


def headline(quantities: dict) -> str:
    """One line for the demo: crease 1 at 90°, then the four creases driven flat."""
    flat, mid = quantities["flat"], quantities["intermediate"]
    return (f"crease 1 driven to 90°: {mid['fold_angles_deg'][0]}°; all driven flat: "
            f"{'/'.join(str(a) for a in flat['fold_angles_deg'])}°, {flat['layers']} "
            f"layers, stack {flat['stack_height_in_H']} H")
