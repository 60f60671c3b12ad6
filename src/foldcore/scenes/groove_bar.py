"""groove-bar — an elastic bar with a V-groove joint folded past its limit (paper §5.5).

Provenance: the paper's groove bar — an elastic bar with a valley hinge in the
middle whose largest angle is 90° (the groove closes), panels made of
elastic elements, bent by position actuation past 90°. The paper's exact
dimensions are not in the text available here; this reconstruction: two
panels 40 × 10 mm, H = 2 mm, hinge width W = 3 mm (k = 4, the default axis
hinge), each panel split into 8 elastic cells (``thicken(..., elastic=...)``).

Actuation: the left panel's far end is held; the right panel's far end is
pulled to where a perfectly rigid panel would be if the hinge bent by ψ
(the hinge model's kinematics, :func:`hinge_pose`: below θ* = 2·atan(W/H)
= 112.6° a rotation about the crease's mid-line), for ψ = 0 … 150° in steps; each step continues from
the last. Up to 90° the hinge can follow exactly, so the panels should not
deform; beyond it the passive hinge hits its limit (a stop) and the panels
must bend to reach the pull.

Quantities per step: the hinge angle (Σ of its sub-strips' Eq. 9 bends, from
the current shape), the angle between the two cells next to the hinge (it
adds the cells' own bending), the right panel's bend (rotation between its
first and last cell, degrees) and the panels' deviation from rigid cells
(RMS of the cells' fit residuals over all their vertices, relative to the
panel length).
"""
from __future__ import annotations

import numpy as np

from ..hinges import DEFAULT_HINGE, neutral_length
from ..measure import element_rotations
from ..strain import estimated_strip_angles
from ..patterns import single_hinge
from ..simulation import Simulation
from ..thickening import thicken
from . import SceneRun

PANEL, DEPTH, THICKNESS, WIDTH = 40.0, 10.0, 2.0, 3.0  # mm
SUBDIVISIONS, CELLS = 4, 8
MAX_ANGLE = 90.0  # degrees, the groove's limit
PULLS = tuple(range(0, 151, 10))  # ψ, degrees
TOLERANCE = 1e-12  # 1e-10 stopped the 70° step 0.05° short (a stall on the axis hinge, measured)


def hinge_pose(points: np.ndarray, psi_deg: float, model: str = DEFAULT_HINGE) -> np.ndarray:
    """Where points of the right panel (N, 3) mm go if the hinge bends by ψ as its
    model bends it (:mod:`foldcore.hinges`: an arc of the model's neutral-axis
    length) and the panel stays rigid (left panel fixed; crease along y through
    x = 0). ``axis`` below θ* = 2·atan(W/H): a rotation by ψ about the crease's
    mid-line."""
    phi = np.radians(psi_deg)
    if phi == 0.0:
        return points.copy()
    radius = float(neutral_length(model, WIDTH, THICKNESS, phi)) / phi
    end = np.array([-WIDTH / 2 + radius * np.sin(phi), radius * (1.0 - np.cos(phi))])
    along, normal = np.array([np.cos(phi), np.sin(phi)]), np.array([-np.sin(phi), np.cos(phi)])
    u, v = points[:, 0] - WIDTH / 2, points[:, 2]
    xz = end + u[:, None] * along + v[:, None] * normal
    return np.column_stack([xz[:, 0], points[:, 1], xz[:, 1]])


def run(quick: bool = False, solver: str | None = None,
        contact="auto") -> SceneRun:
    """Pull the bar past its groove's limit (see module docstring)."""
    solver = solver or "lbfgs"
    budget = 10_000 if quick else 40_000
    pattern = single_hinge(panel_length=PANEL, depth=DEPTH, width=WIDTH, max_angle=MAX_ANGLE)
    mesh = thicken(pattern, THICKNESS, subdivisions=SUBDIVISIONS,
                   elastic={0: CELLS, 1: CELLS})
    rest = mesh.rest_positions
    held = np.flatnonzero(np.isclose(rest[:, 0], -PANEL))
    pulled = np.flatnonzero(np.isclose(rest[:, 0], PANEL))
    sim = Simulation(mesh, pattern, solver=solver, contact=contact)
    sim.add_position_target(held, name="held")
    sim.add_position_target(pulled, name="pull")
    panels, hinges = mesh.groups[mesh.panel_group], mesh.groups["bending_hinge"]
    right = np.flatnonzero(panels.source == 1)
    n_panel = len(panels.indices)
    rows, done = [], 0
    for psi in PULLS:
        sim.move_position_target("pull", hinge_pose(rest[pulled], psi))
        result = sim.run(tolerance=TOLERANCE, max_iterations=budget)
        rot = element_rotations(panels, sim.positions)
        turn = rot[right[0]].T @ rot[right[-1]]
        bend = np.degrees(np.arccos(np.clip((np.trace(turn) - 1.0) / 2.0, -1.0, 1.0)))
        hinge = np.degrees(estimated_strip_angles(hinges, sim.positions).sum())
        rows.append({"pull_deg": psi, "hinge_angle_deg": round(float(hinge), 4),
                     "cells_angle_deg": round(float(result.fold_angles_deg[0]), 4),
                     "panel_bend_deg": round(float(bend), 4),
                     "panel_deviation": float(np.sqrt(panel_energy(sim) / n_panel) / PANEL),
                     "iterations": int(result.iterations) - done,
                     "converged": bool(result.converged)})
        done = int(result.iterations)
    settings = {"solver": solver, "contact": sim.model.contact is not None, "tolerance": TOLERANCE,
                "max_iterations": budget,
                "thickness_mm": THICKNESS, "hinge_width_mm": WIDTH, "cells": CELLS}
    return SceneRun("groove-bar", pattern, mesh, THICKNESS, result, {"steps": rows}, settings)



def headline(quantities: dict) -> str:
    """One line for the demo: hinge and panel at the last pull."""
    last = quantities["steps"][-1]
    return (f"pulled to {last['pull_deg']}°: hinge {last['hinge_angle_deg']}°, "
            f"panel bent {last['panel_bend_deg']}°")


def panel_energy(sim) -> float:
    """Σ over panel cells of ‖C x − R·rest‖² at the current positions (mm²)."""
    from elements.rigid_panel import batch

    g = sim.mesh.groups[sim.mesh.panel_group]
    out, energy = np.zeros((len(g.indices), 3)), np.zeros(len(g))
    batch(sim.positions, g.indptr, g.indices, g.rest, np.zeros((len(g), 0)), out, energy,
          np.zeros((len(g), 0)))
    return float(energy.sum())
