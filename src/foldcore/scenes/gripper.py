"""gripper — a pair of jaws made of two coupled spherical mechanisms, closed by a push (paper §5.2).

Provenance: the paper folds an oriceps (Edmondson et al.; the pattern of
Butler et al.): two spherical mechanisms coupled together, H = 0.43 mm,
hinge width 1.52 mm, "the two hinges in the middle" valleys and every other
hinge a mountain, deployed with targets "around 50°" except "those at the top
and bottom of the pattern (at the back of the folded forceps)" at "around
110°", then closed by position actuation (160 iterations). That pattern is
not available here. **This is a reconstruction** from that description
(:func:`foldcore.patterns.gripper`): two bird's-foot degree-4 vertices A and B
on a 24 × 60 mm sheet's centre line, 22 mm apart, sharing their mountain
crease A–B (the *back*). Each vertex's valley *spine* runs along the centre
line to the top (bottom) edge — the two middle creases, valleys — and its two
mountain *legs* leave at ±γ from the spine for the sides — the creases at the
top and bottom of the pattern. Folded, the quadrilaterals beyond the legs
close on the spines into an upper and a lower jaw, mirror images of each
other, and the two *covers* between the legs turn about the back like a
book's: squeezing the covers (the handles) closes the jaws.

Why these numbers: each vertex is flat-foldable, mode B of
:func:`foldcore.kinematics.degree4_mode_b`, so tan(ρ_spine/2) =
cos γ · tan(ρ_leg/2); γ = 70.94° makes the paper's 50° spines and 110° legs
one compatible state (the deployed targets are exact, not a compromise). In
the cover's frame a jaw tip sits at height y = b + (L − b)(cos²γ + sin²γ
cos ρ_leg) above the back's midpoint (b = 11 mm: half the back; L = 30 mm:
half the sheet), its mirror image at −y: the thin jaws' tips meet at
ρ_leg = 140.2°. A back shorter than 2b = 22 mm would have the tips meet
before the 110° deployed state. Element count: 7 creases × 2 sub-strips + 6
panels = 20 elements, not the paper's 23.

Actuation: (1) deploy: every crease to its closed-form angle (spines +50°,
back −50°, legs −110°), the left cover held where it lies flat; (2)
*squeeze*: every crease passive, both covers' outer edges (the handles, α =
1) turned toward each other about the back's axis, each by half the turn,
in steps of ``TURN_STEP`` up to ``TURN_MAX``, each step starting from the
last — a position actuation the mechanism can follow, which keeps the jaws'
mirror plane in place (a straight-line push of one handle is not on the
mechanism's path and left the strategies a slow compromise, 400–20 000
iterations a step); with contact the jaws stop on each other: the spines'
hinge strips, which end at the tips, meet first, and pushed on past the
touch they give (a hinge strip is as soft across as in bending), so the two
vertices fold apart and the tips open again; (3) *grasp*: the same squeeze
with a ball of radius ``BALL_RADIUS`` fixed in the mouth, ``BALL_AT`` of the
way from the back to the deployed tips on the mirror plane (an
:class:`foldcore.contact.Obstacle`): the jaws stop on the ball.
Contact is on by default in this scene (``contact=False``: the jaws pass
through each other, which is what the quantities then say).

Quantities per step: the handles' turn (degrees), travel (mm, both outer
edges' midpoints from where they started, summed), miss (mm, the largest
distance of a handle vertex from its target) and what stopped them
(``Result.position_targets``: ``contact`` once they miss by more than
10⁻³ of the sheet's size while panels touch), the jaw tip distance (mm, between
the two jaws' mid-surface points at their spine ends), the thin-limit tip
distance at the achieved leg angle (the formula above), the back, spine and
leg angles, the smallest contact gap (mm) and the contact force on each jaw
(its two panels and its spine's strip) and on the ball (mm⁴, the barrier's
gradient), the touching panels and strips, iterations and convergence. The
headline adds the closest the jaws came and at which turn.
"""
from __future__ import annotations

import numpy as np

from ..kinematics import rotation
from ..patterns import gripper, gripper_leg_sector
from ..simulation import Simulation
from ..thickening import thicken
from . import SceneRun
from ._measure import rounded

HALF_WIDTH, HALF_LENGTH, OFFSET = 12.0, 30.0, 11.0  # mm
THICKNESS, WIDTH, SUBDIVISIONS = 0.43, 1.52, 2  # mm, mm, sub-strips
TURN_STEP, TURN_MAX = 5.0, 60.0  # degrees of the handle about the back
BALL_RADIUS, BALL_AT = 3.5, 0.9  # mm; share of the way from the back to the jaw tips
TOLERANCE = 1e-10
CONTACT = True  # the scene's default: its point is where the jaws stop
# Pattern faces (patterns.gripper): jaws' halves, covers.
UPPER_JAW, LOWER_JAW = (0, 4), (1, 5)
RIGHT_COVER, LEFT_COVER = 2, 3
TOP_SPINE, BOTTOM_SPINE, BACK, LEG = 0, 1, 2, 3  # crease ids (legs 3..6 fold alike)


def run(quick: bool = False, solver: str | None = None,
        contact: bool | None = None) -> SceneRun:
    """Deploy the gripper, squeeze it shut, then squeeze it on a ball (module docstring)."""
    solver = solver or "rigid"
    contact = CONTACT if contact in (None, "auto") else contact not in (False, "off")
    budget = 400 if solver == "rigid" else (5_000 if quick else 40_000)
    pattern = gripper(HALF_WIDTH, HALF_LENGTH, OFFSET, width=WIDTH)
    mesh = thicken(pattern, THICKNESS, subdivisions=SUBDIVISIONS)
    parts = _Parts(mesh)
    step = 2 * TURN_STEP if quick else TURN_STEP
    turns = np.arange(0.0, TURN_MAX + step / 2, step)
    deployed, squeeze, result = _squeeze(pattern, mesh, parts, solver, contact, budget, turns)
    quantities = {"deployed": _deployed(deployed, pattern, parts), "squeeze": squeeze,
                  "thin_tips_meet_at_leg_deg": round(_thin_meeting_leg_deg(), 3)}
    gallery = [("deployed", pattern, mesh, deployed.positions),
               (f"squeezed {turns[-1]:g}°", pattern, mesh, result.positions)]
    if contact:
        ball = _ball(deployed.positions, parts)
        _, grasp, held = _squeeze(pattern, mesh, parts, solver, contact, budget, turns, ball)
        quantities["grasp"] = {"ball_centre_mm": rounded(ball.vertices.mean(axis=0), 4),
                               "ball_radius_mm": BALL_RADIUS, **grasp}
        gallery.append((f"on a {2 * BALL_RADIUS:g} mm ball (not drawn)", pattern, mesh,
                        held.positions))
    settings = {"solver": solver, "contact": contact, "tolerance": TOLERANCE,
                "max_iterations": budget, "thickness_mm": THICKNESS, "hinge_width_mm": WIDTH,
                "subdivisions": SUBDIVISIONS, "sheet_mm": [2 * HALF_WIDTH, 2 * HALF_LENGTH],
                "back_mm": 2 * OFFSET, "leg_sector_deg": round(gripper_leg_sector(), 4),
                "turn_step_deg": step}
    return SceneRun("gripper", pattern, mesh, THICKNESS, result, quantities, settings, gallery)


def headline(quantities: dict) -> str:
    """One line for the demo: the jaw tip distance deployed, the closest the squeeze
    brought them (and at which turn) and where the squeezes end."""
    steps = quantities["squeeze"]["steps"]
    closest = min(steps, key=lambda s: s["jaw_tip_distance_mm"])
    line = (f"jaw tips {quantities['deployed']['jaw_tip_distance_mm']} → "
            f"{closest['jaw_tip_distance_mm']} mm at {closest['turn_deg']:g}°")
    if closest is not steps[-1]:
        line += f", {steps[-1]['jaw_tip_distance_mm']} mm at {steps[-1]['turn_deg']:g}°"
    if "grasp" in quantities:
        line += f", on the ball {quantities['grasp']['steps'][-1]['jaw_tip_distance_mm']} mm"
    return line


def _squeeze(pattern, mesh, parts, solver, contact, budget, turns, ball=None):
    """Deploy with the left cover held where it lies flat, then turn both covers'
    handles about the back's axis toward each other, each by half of ``turns``
    (degrees), each step from the last: the jaws' mirror plane stays where it was.

    Returns (deployed Result, {"steps": one row per turn}, last Result)."""
    sim = Simulation(mesh, pattern, solver=solver, contact=contact,
                     obstacles=[ball] if ball is not None else ())
    sim.add_position_target(parts.panel(LEFT_COVER), name="held")
    deployed = sim.run(tolerance=TOLERANCE, max_iterations=budget)
    x = deployed.positions
    sim.set_fold_angles({int(e): None for e in pattern.creases})
    sim.remove_position_target("held")
    origin, axis = parts.back_axis(x)
    starts = {side: x[ids].copy() for side, ids in parts.handles.items()}
    for side, ids in parts.handles.items():
        sim.add_position_target(ids, name=side)
    rows, done, result = [], int(deployed.iterations), deployed
    for turn in turns:
        targets = {}
        for side, sign in (("right", 1.0), ("left", -1.0)):
            turned = rotation(axis, sign * np.radians(turn) / 2.0)
            targets[side] = (starts[side] - origin) @ turned.T + origin
            sim.move_position_target(side, targets[side])
        result = sim.run(tolerance=TOLERANCE, max_iterations=budget)
        rows.append(_row(turn, result, parts, starts, targets, done))
        done = int(result.iterations)
    return deployed, {"steps": rows}, result


def _ball(x: np.ndarray, parts):
    """The grasped ball: on the jaws' mirror plane, ``BALL_AT`` of the way from the
    back's midpoint to the midpoint of the deployed jaw tips (positions x, mm)."""
    from ..contact import Obstacle

    tips = 0.5 * (x[parts.tip_upper].mean(axis=0) + x[parts.tip_lower].mean(axis=0))
    back = x[parts.back_mid].mean(axis=0)
    return Obstacle.ball(back + BALL_AT * (tips - back), BALL_RADIUS, name="ball")


def _row(turn, result, parts, starts, targets, done) -> dict:
    """One squeeze step's quantities (angles degrees, lengths mm): the handles' travel
    (both edges' midpoints from where they started, summed) and miss (the largest
    distance of a handle vertex from its target)."""
    x = result.positions
    angles = result.fold_angles_deg
    leg = float(np.mean(angles[LEG:LEG + 4]))
    travel = sum(float(np.linalg.norm(x[ids].mean(axis=0) - starts[side].mean(axis=0)))
                 for side, ids in parts.handles.items())
    miss = max(float(np.linalg.norm(x[ids] - targets[side], axis=1).max())
               for side, ids in parts.handles.items())
    row = {"turn_deg": float(turn), "handle_travel_mm": round(travel, 4),
           "handle_miss_mm": round(miss, 4),
           "jaw_tip_distance_mm": round(parts.tip_distance(x), 4),
           "thin_tip_distance_mm": round(_thin_tip_distance(leg), 4),
           "back_deg": round(float(angles[BACK]), 3),
           "spine_deg": round(float(angles[TOP_SPINE]), 3),
           "legs_deg": rounded(angles[LEG:LEG + 4], 3),
           "handles_stopped_by": sorted({t["stopped_by"] for t in result.position_targets
                                         if t["stopped_by"]}),
           "iterations": int(result.iterations) - done, "reason": result.reason}
    if result.contact is not None:
        row["contact"] = _contact(result.contact)
    return row


def _contact(report: dict) -> dict:
    """What contact did at a step: smallest gap, force magnitude per jaw (its two
    panels and its spine's hinge strip) and on obstacles, the touching panels and
    strips."""
    panels = {f["face"]: f["magnitude"] for f in report.get("panel_forces", [])}
    strips = {f["crease"]: f["magnitude"] for f in report.get("strip_forces", [])}
    jaw = lambda faces, spine: round(sum(panels.get(f, 0.0) for f in faces)  # noqa: E731
                                     + strips.get(spine, 0.0), 6)
    return {"smallest_gap_mm": report.get("smallest_gap_mm"),
            "upper_jaw_force": jaw(UPPER_JAW, TOP_SPINE),
            "lower_jaw_force": jaw(LOWER_JAW, BOTTOM_SPINE),
            "obstacles": [{"name": o["name"], "touching_faces": o["touching_faces"],
                           "touching_creases": o.get("touching_creases", []),
                           "force": round(float(np.linalg.norm(o["force"])), 6)}
                          for o in report.get("obstacles", [])],
            "touching_faces": report.get("touching_faces", []),
            "touching_creases": report.get("touching_creases", [])}


def _deployed(result, pattern, parts) -> dict:
    """The deployed state beside its targets (degrees) and its jaw tip distance (mm)."""
    n = len(pattern.creases)
    angles, target = result.fold_angles_deg[:n], pattern.fold_angles[:n]
    return {"iterations": int(result.iterations), "reason": result.reason,
            "fold_angles_deg": rounded(angles, 4), "target_deg": rounded(target, 4),
            "largest_miss_deg": round(float(np.max(np.abs(angles - target))), 6),
            "jaw_tip_distance_mm": round(parts.tip_distance(result.positions), 4)}


class _Parts:
    """Vertex ids of the scene's parts in the thick mesh."""

    def __init__(self, mesh):
        self.mesh = mesh
        rest = mesh.rest_positions
        right, left = self.panel(RIGHT_COVER), self.panel(LEFT_COVER)
        self.handles = {"right": right[np.abs(rest[right, 0] - rest[right, 0].max()) < 1e-9],
                        "left": left[np.abs(rest[left, 0] - rest[left, 0].min()) < 1e-9]}
        self.tip_upper = self._nearest(UPPER_JAW[0], (0.0, HALF_LENGTH))
        self.tip_lower = self._nearest(LOWER_JAW[0], (0.0, -HALF_LENGTH))
        self.back_ends = [self._nearest(LEFT_COVER, (0.0, OFFSET)),
                          self._nearest(LEFT_COVER, (0.0, -OFFSET))]
        self.back_mid = np.concatenate(self.back_ends)

    def panel(self, face: int) -> np.ndarray:
        panels = self.mesh.groups[self.mesh.panel_group]
        return panels.indices[panels.slots(int(self.mesh.panel_of_face[face]))]

    def _nearest(self, face: int, point) -> np.ndarray:
        """The panel's vertices (top and bottom) nearest a pattern point (2,)."""
        ids = self.panel(face)
        d = np.linalg.norm(self.mesh.rest_positions[ids, :2] - np.asarray(point), axis=1)
        return ids[d <= d.min() + 1e-9]

    def tip_distance(self, x) -> float:
        return float(np.linalg.norm(x[self.tip_upper].mean(axis=0) - x[self.tip_lower].mean(axis=0)))

    def back_axis(self, x):
        """(point, unit direction) of the back's line on the held cover's edge, mm."""
        a, b = (x[e].mean(axis=0) for e in self.back_ends)
        return b, (a - b) / np.linalg.norm(a - b)


def _thin_tip_distance(leg_deg: float) -> float:
    """Tip distance (mm) of the zero-thickness gripper at leg fold ``leg_deg``:
    2 |b + (L − b)(cos²γ + sin²γ cos ρ_leg)| (module docstring)."""
    g, rho = np.radians(gripper_leg_sector()), np.radians(leg_deg)
    y = OFFSET + (HALF_LENGTH - OFFSET) * (np.cos(g) ** 2 + np.sin(g) ** 2 * np.cos(rho))
    return float(2.0 * abs(y))


def _thin_meeting_leg_deg() -> float:
    """Leg fold (degrees) at which the zero-thickness jaws' tips meet."""
    g = np.radians(gripper_leg_sector())
    c = -(OFFSET / (HALF_LENGTH - OFFSET) + np.cos(g) ** 2) / np.sin(g) ** 2
    return float(np.degrees(np.arccos(c)))
