"""waterbomb — the 6-crease waterbomb base and its two stable positions (paper §5.4, Table 1).

Provenance: the paper's bistable waterbomb: 6 creases of equal length,
alternating M/V. Its exact dimensions are not given in the text available
here; this reconstruction uses R = 50 mm creases, H = 1 mm, hinge width
W = 2 mm (k = 4), which keeps H/R at the paper's order (a thin sheet).

Actuation (a stand-in for the paper's, said plainly): each position is
folded from the flat sheet by hinge actuation — position 1: the three
mountain creases to −82° (the prototype's θm), valleys passive; position 2:
the three valleys to 55° (the prototype's θv), mountains passive. The paper
reaches position 2 from position 1 by position actuation (popping the centre
through); that pop-through is not reproduced
(docs/architecture.md#scene-waterbomb-results). The final result (FOLD/PNG) is
position 2.

Quantities: θm, θv (mean over each family) at both positions beside Table 1
(prototype −82/32 and −20/55; paper's simulation −82/24 and −17/58) and the
zero-thickness closed form of the symmetric base
(:func:`foldcore.kinematics.waterbomb_minor`: the minor magnitude for the
actuated major one).
"""
from __future__ import annotations

from ..kinematics import waterbomb_minor_deg
from ..patterns import waterbomb
from ..simulation import Simulation
from ..thickening import thicken
from . import SceneRun
from ._measure import rounded

N_CREASES = 6
RADIUS, THICKNESS, WIDTH, SUBDIVISIONS = 50.0, 1.0, 2.0, 4  # mm, mm, mm, count
TABLE_1 = {"position_1": {"prototype": (-82.0, 32.0), "paper_simulation": (-82.0, 24.0)},
           "position_2": {"prototype": (-20.0, 55.0), "paper_simulation": (-17.0, 58.0)}}
TOLERANCE = 1e-10


def run(quick: bool = False, solver: str | None = None,
        contact="auto") -> SceneRun:
    """Fold position 1 and position 2 from the flat sheet (see module docstring)."""
    solver = solver or "rigid"
    budget = (100 if quick else 400) if solver == "rigid" else (2_000 if quick else 40_000)
    quantities = {}
    schedule = (("position_1", "M", TABLE_1["position_1"]["prototype"][0]),
                ("position_2", "V", TABLE_1["position_2"]["prototype"][1]))
    for position, major, major_angle in schedule:
        pattern = waterbomb(N_CREASES, radius=RADIUS, major=major, width=WIDTH,
                            major_angle=abs(major_angle))
        mesh = thicken(pattern, THICKNESS, subdivisions=SUBDIVISIONS)
        result = Simulation(mesh, pattern, solver=solver, contact=contact).run(tolerance=TOLERANCE,
                                                             max_iterations=budget)
        angles = result.fold_angles_deg[:N_CREASES]
        kinds = pattern.assignments[:N_CREASES]
        theta_m, theta_v = float(angles[kinds == "M"].mean()), float(angles[kinds == "V"].mean())
        quantities[position] = {
            "actuated": f"{major} creases to {major_angle:g}°",
            "theta_m_deg": round(theta_m, 3), "theta_v_deg": round(theta_v, 3),
            "fold_angles_deg": rounded(angles),
            "closed_form_minor_deg": round(float(waterbomb_minor_deg(N_CREASES,
                                                                     abs(major_angle))), 3),
            "table_1": TABLE_1[position],
            "iterations": int(result.iterations), "converged": bool(result.converged)}
    settings = {"solver": solver, "contact": result.contact is not None, "tolerance": TOLERANCE,
                "max_iterations": budget,
                "thickness_mm": THICKNESS, "hinge_width_mm": WIDTH,
                "subdivisions": SUBDIVISIONS, "radius_mm": RADIUS}
    return SceneRun("waterbomb", pattern, mesh, THICKNESS, result, quantities, settings)


def headline(quantities: dict) -> str:
    """One line for the demo: θm/θv at both positions."""
    one, two = quantities["position_1"], quantities["position_2"]
    return (f"θm/θv {one['theta_m_deg']:.1f}/{one['theta_v_deg']:.1f} and "
            f"{two['theta_m_deg']:.1f}/{two['theta_v_deg']:.1f}")
