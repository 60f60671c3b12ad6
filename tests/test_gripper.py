"""The gripper: its pattern's closed form, the thin-limit jaw geometry, and the scene
with contact (jaws stop on each other and on a ball) and without (they pass)."""
from itertools import combinations

import numpy as np
import pytest

from foldcore import kinematics, patterns, scenes
from foldcore.errors import PatternError
from foldcore.scenes import gripper as scene
from foldcore.simulation import Simulation
from foldcore.thickening import thicken

from solids import crossing_parts

pytest.importorskip("ipctk")
manifold3d = pytest.importorskip("manifold3d")


def test_the_deployed_targets_close_both_vertices_exactly():
    pattern = patterns.gripper()
    rho = np.radians(np.nan_to_num(pattern.fold_angles))
    residuals = kinematics.vertex_closure_residuals(pattern, rho)
    assert max(residuals[0], residuals[1]) < 1e-12
    creases = pattern.assignments[pattern.creases]
    assert list(creases) == ["V", "V", "M", "M", "M", "M", "M"]
    assert np.allclose(pattern.vertices[pattern.edges[:2]][:, :, 0], 0.0)  # spines on the centre line
    assert pattern.fold_angles[3] == pytest.approx(-patterns.GRIPPER_LEG_DEG, abs=1e-9)


def test_legs_that_miss_the_sides_are_refused():
    with pytest.raises(PatternError, match="half_length"):
        patterns.gripper(half_width=12.0, half_length=10.0, offset=8.0)


@pytest.mark.parametrize("spine", [40.0, 50.0, 60.0])
def test_thin_jaw_tips_follow_the_closed_form(spine):
    """H, W → 0: the tips' distance is 2|b + (L − b)(cos²γ + sin²γ cos ρ_leg)|; the
    thick mesh's tip points sit W/2 off the spine's end, so the tolerance is a few W."""
    h, w = 0.01, 0.02
    pattern = patterns.gripper(scene.HALF_WIDTH, scene.HALF_LENGTH, scene.OFFSET,
                               spine_angle=spine, width=w)
    mesh = thicken(pattern, h, subdivisions=2)
    result = Simulation(mesh, pattern, solver="rigid").run(tolerance=1e-12, max_iterations=400)
    leg = float(np.mean(result.fold_angles_deg[3:7]))
    assert leg == pytest.approx(pattern.fold_angles[3], abs=0.01)
    tips = scene._Parts(mesh).tip_distance(result.positions)
    assert tips == pytest.approx(scene._thin_tip_distance(leg), abs=5 * w)


@pytest.fixture(scope="module")
def with_contact():
    return scenes.run("gripper", quick=True)


def _overlaps(run, positions, extra=None, joined=True):
    """Largest intersection volume of two panels' (or a panel's and the extra solid's)
    convex hulls, as a share of the smaller; ``joined`` False: only panels no crease
    joins (those contact keeps apart at any fold)."""
    g = run.mesh.groups[run.mesh.panel_group]
    hulls = [manifold3d.Manifold.hull_points(np.ascontiguousarray(positions[g.indices[g.slots(p)]]))
             for p in range(len(g))]
    slot = run.mesh.panel_of_face
    joins = {frozenset(int(slot[f]) for f in faces) for faces in run.pattern.edge_faces
             if min(faces) >= 0}
    pairs = [(hulls[a], hulls[b]) for a, b in combinations(range(len(hulls)), 2)
             if joined or frozenset((a, b)) not in joins]
    if extra is not None:
        pairs += [(h, extra) for h in hulls]
    return max((a ^ b).volume() / min(a.volume(), b.volume()) for a, b in pairs)


def test_deployed_at_the_closed_form_and_squeezing_closes_the_jaws(with_contact):
    q = with_contact.quantities
    assert q["deployed"]["largest_miss_deg"] < 0.01
    steps = q["squeeze"]["steps"]
    free = [s for s in steps if "smallest_gap_mm" not in s["contact"] or
            s["contact"]["smallest_gap_mm"] is None]
    tips = [s["jaw_tip_distance_mm"] for s in free]
    assert len(free) >= 3 and np.all(np.diff(tips) < 0)
    for s in free:  # mirror-symmetric jaws: the four legs alike until the jaws touch
        assert np.ptp(s["legs_deg"]) < 0.5


def _apart_crossings(run, positions):
    """Pairs of parts (panels, hinge strips) that meet at no vertex of the pattern and
    cross each other in the folded solid (tests/solids.py's own check)."""
    from foldcore.outputs import folded_frame

    fold = {"faces_vertices": [list(map(int, f)) for f in run.pattern.faces],
            "edges_vertices": run.pattern.edges.tolist()}
    return crossing_parts(folded_frame(run.mesh, positions), fold)


def _jaw_parts(contact: dict, faces, spine) -> bool:
    """Whether a jaw (its two panels ``faces``, its spine's strip) is among the
    touching parts of a contact entry."""
    return bool(set(contact["touching_faces"]) & set(faces)
                or spine in contact.get("touching_creases", []))


def test_the_jaws_stop_on_each_other(with_contact):
    steps = with_contact.quantities["squeeze"]["steps"]
    touched = [s for s in steps if s["contact"]["smallest_gap_mm"] is not None]
    assert touched, "the squeeze never brought the jaws together"
    first = touched[0]["contact"]
    assert _jaw_parts(first, scene.UPPER_JAW, scene.TOP_SPINE)
    assert _jaw_parts(first, scene.LOWER_JAW, scene.BOTTOM_SPINE)
    assert min(s["jaw_tip_distance_mm"] for s in steps) >= scene.THICKNESS
    assert first["upper_jaw_force"] > 0
    assert first["upper_jaw_force"] == pytest.approx(first["lower_jaw_force"], rel=0.1)
    assert _overlaps(with_contact, with_contact.result.positions, joined=False) <= 1e-4
    # no two parts that meet at no vertex of the pattern pass through each other
    assert _apart_crossings(with_contact, with_contact.result.positions) == set()
    assert all(s["handles_stopped_by"] == [] for s in steps if s["handle_miss_mm"] < 0.01)


def test_the_jaws_stop_on_the_ball_and_press_it_harder_as_the_push_goes_on(with_contact):
    grasp = with_contact.quantities["grasp"]
    on_ball = [s for s in grasp["steps"] if s["contact"]["obstacles"][0]["touching_faces"]
               or s["contact"]["obstacles"][0]["touching_creases"]]
    assert on_ball, "the jaws never reached the ball"
    last = on_ball[-1]["contact"]["obstacles"][0]
    assert _jaw_parts(last, scene.UPPER_JAW, scene.TOP_SPINE)
    assert _jaw_parts(last, scene.LOWER_JAW, scene.BOTTOM_SPINE)
    assert min(s["jaw_tip_distance_mm"] for s in on_ball) > 2 * scene.BALL_RADIUS - 2.0
    assert on_ball[-1]["contact"]["obstacles"][0]["force"] > on_ball[0]["contact"]["obstacles"][0]["force"]
    from foldcore.contact import Obstacle

    ball = Obstacle.ball(grasp["ball_centre_mm"], scene.BALL_RADIUS)
    ball = manifold3d.Manifold.hull_points(np.ascontiguousarray(ball.vertices))
    positions = with_contact.gallery[-1][3]
    # pressed on past the touch, the handles strain the hinges: joined panels are
    # left to them (docs/architecture.md#scene-gripper-results)
    assert _overlaps(with_contact, positions, ball, joined=False) <= 1e-4
    assert _apart_crossings(with_contact, positions) == set()


def test_without_contact_the_jaws_pass_through_each_other():
    run = scenes.run("gripper", quick=True, contact=False)
    steps = run.quantities["squeeze"]["steps"]
    assert "grasp" not in run.quantities
    tips = [s["jaw_tip_distance_mm"] for s in steps]
    assert tips[-1] > min(tips) + 1.0  # the tips crossed and part again
    assert _overlaps(run, run.result.positions, joined=False) > 1e-3
    assert _apart_crossings(run, run.result.positions)  # the check can fail
