"""chain — an n-long linear chain of spherical mechanisms pushed at one end (paper §5.3).

Provenance: the paper's chain is built on Shafer's "Frog's Tongue": spherical
mechanisms coupled one after another with no loops, 44 hinge and 16 panel
elements, cardboard H = 3 mm, hinges deployed to ≈ 60° by assignment, then a
transverse push at one end; it reports transverse 4.5 → 3 cm and
longitudinal 13 → 4 cm, the motion stopping when hinges reach ≈ 180°. The
Frog's Tongue pattern itself is not available here. **This is a
reconstruction**: a Miura-ori strip of 2 × 8 parallelogram facets
(:func:`foldcore.patterns.miura`), whose seven interior vertices are degree-4
spherical mechanisms in a row, each sharing panels with its two neighbours
only — a linear chain without loops, and with the paper's element counts
(16 panels; 22 creases × 2 sub-strips = 44 hinge elements). Facets a = 29 mm
(across the chain), b = 22 mm (along it), γ = 60°, for a chain of about the
paper's size; hinge width W = πH/2 = 4.71 mm, the Eq. 7 minimum for a 180°
fold.

Not the paper's pattern in one respect, said plainly: in a Miura strip the
zig-zag and straight creases cannot both sit at 60°. Deploying to facet tilt
θ = 50° puts the straight creases at 61.6° and the zig-zag ones at 100°
(:func:`foldcore.kinematics.miura_angles`, every crease actuated).

Actuation: (1) deploy with every crease actuated to those angles; (2) make
every crease passive, hold the first row's left panel (all its vertices,
α = 1) and push the outer corner of the first row's right panel (its two
corner vertices, α = 1e-2, a soft push) toward the held panel by 0, 5, …,
60 mm along the transverse direction of the deployed state; each step starts
from the last. The thick chain is not an exact zero-strain mechanism in the
strained-joint model (hinge axes sit O(W) off the crease lines), so the
corner does not reach every commanded push: the achieved lengths are what is
reported. The zig-zag hinges stop at flat (the rigid-body model's M/V side
rows hold their panels at 180°), and with them the shortening along the
chain; pushes after that still shorten it a little across
(docs/architecture.md#scene-chain-results).

Hinge model: the paper's constant-length arc (``HINGE``), not foldcore's
default axis hinge (:mod:`foldcore.hinges`), because this scene reproduces
the paper's strained-joint experiment, and because the push carries the
zig-zag creases past the axis hinge's pivot angle θ* = 2·atan(W/H) = 115°,
where every vertex binds and each step becomes a slow large-residual problem
for the strategies.

Quantities: per push, the transverse length (distance between the two
first-row panels' centroids), the longitudinal length (distance between the
midpoints of the first and last rows' panel centroids), the largest zig-zag
and straight fold magnitudes, the corner's distance from its commanded
position, iterations and convergence; ``before``/``after`` lengths and the
zero-thickness rigid-fold lengths at the deployed tilt
(:func:`foldcore.kinematics.miura_cell`: transverse L, longitudinal
(m − 1)·S; the thick hinges add ≈ W per crease).
"""
from __future__ import annotations

import numpy as np

from ..kinematics import miura_cell
from ..patterns import miura, miura_edge_kinds, miura_fold_angles
from ..simulation import Simulation
from ..thickening import thicken
from . import SceneRun

N, M = 2, 8  # facets across (x) and along (y) the chain
A, B, GAMMA = 29.0, 22.0, 60.0  # mm, mm, degrees
THICKNESS = 3.0  # mm, cardboard
WIDTH = np.pi * THICKNESS / 2.0  # mm, Eq. 7 minimum for a 180° fold
SUBDIVISIONS = 2
TILT = 50.0  # degrees, deployed facet tilt θ
PUSH_STEP, PUSH_MAX = 5.0, 60.0  # mm
PUSH_ALPHA = 1e-2
TOLERANCE = 1e-10
HINGE = "arc"  # the paper's strained joint; why not the default axis hinge: module docstring


def run(quick: bool = False, solver: str | None = None,
        contact="auto") -> SceneRun:
    """Deploy the chain, then push one end across it (see module docstring)."""
    solver = solver or "rigid"
    budget = 400 if solver == "rigid" else (5_000 if quick else 40_000)
    pattern, expected = _deployed_pattern()
    mesh = thicken(pattern, THICKNESS, subdivisions=SUBDIVISIONS, hinge=HINGE)
    sim = Simulation(mesh, pattern, solver=solver, contact=contact)
    deployed = sim.run(tolerance=TOLERANCE, max_iterations=budget)
    sim.set_fold_angles({int(e): None for e in pattern.creases})
    held, pushed = _panel_vertices(mesh, 0), _corner_vertices(pattern, mesh)
    sim.add_position_target(held, name="held")
    start = sim.positions[pushed].copy()
    across = _unit(_centroid(mesh, sim.positions, 0) - _centroid(mesh, sim.positions, 1))
    sim.add_position_target(pushed, alpha=PUSH_ALPHA, name="push")
    kinds = miura_edge_kinds(N, M)
    rows, done = [], int(deployed.iterations)
    step = 2 * PUSH_STEP if quick else PUSH_STEP
    for push in np.arange(0.0, PUSH_MAX + step / 2, step):
        sim.move_position_target("push", start + push * across)
        result = sim.run(tolerance=TOLERANCE, max_iterations=budget)
        rows.append(_row(push, result, mesh, kinds, start + push * across, pushed, done))
        done = int(result.iterations)
    quantities = {"deployed": _deployed_quantities(deployed, pattern, expected, kinds),
                  "before": _lengths(rows[0]), "after": _lengths(rows[-1]),
                  "rigid_fold_lengths_mm": _rigid_fold_lengths(), "pushes": rows}
    settings = {"solver": solver, "contact": sim.model.contact is not None, "tolerance": TOLERANCE,
                "max_iterations": budget,
                "thickness_mm": THICKNESS, "hinge_width_mm": round(WIDTH, 4),
                "subdivisions": SUBDIVISIONS, "n": N, "m": M, "a_mm": A, "b_mm": B,
                "gamma_deg": GAMMA, "tilt_deg": TILT, "push_alpha": PUSH_ALPHA}
    return SceneRun("chain", pattern, mesh, THICKNESS, result, quantities, settings)


def headline(quantities: dict) -> str:
    """One line for the demo: lengths before and after the push (mm)."""
    before, after = quantities["before"], quantities["after"]
    return (f"transverse {before['transverse_mm']} → {after['transverse_mm']} mm, "
            f"longitudinal {before['longitudinal_mm']} → {after['longitudinal_mm']} mm")


def _deployed_pattern():
    """The strip with every crease's target at its rigid-fold angle (degrees, signed)."""
    expected = miura_fold_angles(N, M, GAMMA, TILT)
    return miura(N, M, a=A, b=B, gamma=GAMMA, width=WIDTH).replace(fold_angles=expected), expected


def _panel_vertices(mesh, face: int) -> np.ndarray:
    """Vertex ids of the panel prism of pattern face ``face``."""
    panels = mesh.groups[mesh.panel_group]
    return panels.indices[panels.slots(int(mesh.panel_of_face[face]))]


def _corner_vertices(pattern, mesh) -> np.ndarray:
    """The first-row right panel's vertices at the sheet corner (x = N·a, y = 0): its
    top and bottom corner (2,) ids."""
    ids = _panel_vertices(mesh, N - 1)
    gap = np.linalg.norm(mesh.rest_positions[ids, :2] - pattern.vertices[N], axis=1)
    return ids[gap <= gap.min() + 1e-9 * (A + B)]


def _centroid(mesh, positions: np.ndarray, face: int) -> np.ndarray:
    return positions[_panel_vertices(mesh, face)].mean(axis=0)


def _unit(v: np.ndarray) -> np.ndarray:
    return v / np.linalg.norm(v)


def _row(push, result, mesh, kinds, target, pushed, done) -> dict:
    """One push step's measurements (mm, degrees)."""
    x = result.positions
    first = [_centroid(mesh, x, f) for f in range(N)]
    last = [_centroid(mesh, x, (M - 1) * N + f) for f in range(N)]
    angles = np.abs(result.fold_angles_deg)
    return {"push_mm": float(push),
            "transverse_mm": round(float(np.linalg.norm(first[1] - first[0])), 4),
            "longitudinal_mm": round(float(np.linalg.norm(np.mean(last, axis=0)
                                                          - np.mean(first, axis=0))), 4),
            "max_zigzag_deg": round(float(angles[kinds == "zigzag"].max()), 4),
            "max_straight_deg": round(float(angles[kinds == "straight"].max()), 4),
            "corner_gap_mm": round(float(np.linalg.norm(x[pushed] - target, axis=1).max()), 4),
            "iterations": int(result.iterations) - done,
            "converged": bool(result.converged)}


def _lengths(row: dict) -> dict:
    return {k: row[k] for k in ("push_mm", "transverse_mm", "longitudinal_mm")}


def _deployed_quantities(result, pattern, expected, kinds) -> dict:
    """Stage 1: rigid-fold targets against the achieved angles (degrees)."""
    out = {"iterations": int(result.iterations), "converged": bool(result.converged)}
    for family in ("zigzag", "straight"):
        chosen = kinds == family
        achieved = np.abs(result.fold_angles_deg[chosen])
        out[family] = {"target_deg": round(float(np.abs(expected[chosen]).max()), 4),
                       "achieved_mean_deg": round(float(achieved.mean()), 4)}
    return out


def _rigid_fold_lengths() -> dict:
    """Zero-thickness lengths of the deployed strip (mm): panel-centroid distances
    L across and (m − 1)·S along (kinematics.miura_cell at the deployed tilt)."""
    _, width, length, _ = miura_cell(A, B, np.radians(GAMMA), np.radians(TILT))
    return {"transverse_mm": round(float(length), 4),
            "longitudinal_mm": round(float((M - 1) * width), 4)}
