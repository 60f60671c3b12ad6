"""Contact: panels that no crease joins never pass through each other, nor hinge
strips through the parts they meet at no vertex of the pattern, joined panels
overlap by at most the shrink their contact geometry allows, a contact that never
engages changes nothing, and every surface says what contact did.

The letter fold: three panels 6 | 10 | 6 mm wide in a row, both creases valleys
driven to 180°. Folded flat, the two outer panels land on the middle one from the
same side and would share the strip 10 … 12 mm: one of them must stop on the
other. The overlap volumes are measured by tests/solids.py (manifold3d), not by
foldcore."""
from __future__ import annotations

import json
import subprocess
import sys
from itertools import combinations

import numpy as np
import pytest

pytest.importorskip("ipctk")

from foldcore.contact import ContactSettings, PartSolids  # noqa: E402
from foldcore.contact.barrier import JOINED_SHARE  # noqa: E402
from foldcore.errors import SimulationError  # noqa: E402
from foldcore.options import OptionError, Solving  # noqa: E402
from foldcore.pattern import CreasePattern  # noqa: E402
from foldcore.simulation import Simulation  # noqa: E402
from foldcore.strategies.rigid import RigidOptions  # noqa: E402
from foldcore.thickening import thicken  # noqa: E402
from foldcore import patterns  # noqa: E402

from solids import hull  # noqa: E402

H = 1.0  # mm
#: the acceptance bound: two panels' hulls may share at most this share of a panel
OVERLAP_SHARE = 1e-4

LETTER = {"file_spec": 1.1, "frame_classes": ["creasePattern"],
          "vertices_coords": [[0, 0], [6, 0], [16, 0], [22, 0],
                              [0, 10], [6, 10], [16, 10], [22, 10]],
          "edges_vertices": [[1, 5], [2, 6], [0, 1], [1, 2], [2, 3], [4, 5], [5, 6], [6, 7],
                             [0, 4], [3, 7]],
          "edges_assignment": ["V", "V"] + ["B"] * 8,
          "edges_foldAngle": [180, 180] + [0] * 8}


def letter_pattern() -> CreasePattern:
    v = np.array(LETTER["vertices_coords"], dtype=float)
    return CreasePattern(v, np.array(LETTER["edges_vertices"]),
                         np.array(LETTER["edges_assignment"]), source="letter")


def overlap_shares(mesh, positions) -> dict:
    """{(face a, face b): overlap volume / the smaller panel's volume} of every
    pair of panel hulls that overlap."""
    g = mesh.groups[mesh.panel_group]
    hulls = {int(g.source[p]): hull(positions[g.indices[g.slots(p)]]) for p in range(len(g))}
    out = {}
    for a, b in combinations(sorted(hulls), 2):
        volume = (hulls[a] ^ hulls[b]).volume()
        if volume > 0:
            out[(a, b)] = volume / min(hulls[a].volume(), hulls[b].volume())
    return out


def fold_letter(contact, solver="rigid"):
    pattern = letter_pattern()
    mesh = thicken(pattern, H)
    sim = Simulation(mesh, pattern, solver=solver, contact=contact)
    sim.set_fold_angles({0: 180.0, 1: 180.0})
    return mesh, sim, sim.run(tolerance=1e-8, max_iterations=2_000)


@pytest.fixture(scope="module")
def letter_runs():
    return {contact: fold_letter(contact) for contact in (False, True)}


def test_the_default_strategy_keeps_panels_apart_too():
    """hybrid: rigid steps, then newton (whose panels are not exactly rigid: joined
    pairs are left to their hinge, unjoined ones keep the barrier and CCD)."""
    mesh, _, result = fold_letter(True, solver="hybrid")
    shares = overlap_shares(mesh, result.positions)
    assert not shares or max(shares.values()) <= OVERLAP_SHARE, shares
    assert result.converged and abs(result.fold_angles_deg[1] - 180.0) < 0.01
    assert 90.0 < result.fold_angles_deg[0] < 179.0


def test_without_contact_the_outer_panels_pass_through_each_other(letter_runs):
    mesh, _, result = letter_runs[False]
    assert overlap_shares(mesh, result.positions)[(0, 2)] > 0.1  # the check can fail


def test_with_contact_no_two_panels_overlap(letter_runs):
    mesh, _, result = letter_runs[True]
    shares = overlap_shares(mesh, result.positions)
    assert not shares or max(shares.values()) <= OVERLAP_SHARE, shares
    # joined panels (1, 2) touch face to face: at most the contact geometry's shrink
    assert (0, 2) not in shares


def test_contact_stops_one_crease_and_lets_the_other_fold_flat(letter_runs):
    _, _, result = letter_runs[True]
    assert result.converged
    assert abs(result.fold_angles_deg[1] - 180.0) < 0.01
    # panel 0 rests on panel 2's edge: well short of flat (> 1°), on its valley side
    assert 90.0 < result.fold_angles_deg[0] < 179.0
    c = result.contact
    assert c["active_pairs"] and [0, 2] in c["active_pairs"]
    assert 0.0 <= c["smallest_gap_mm"] < c["activation_mm"]
    forces = np.array([f["force"] for f in c["panel_forces"]])
    # contact forces are internal: action and reaction sum to zero over the panels
    assert np.linalg.norm(forces.sum(axis=0)) <= 1e-6 * np.abs(forces).max()


def test_a_contact_that_never_engages_changes_nothing():
    pattern = patterns.miura_one_crease(6, 6, tilt=45.0)
    mesh = thicken(pattern, H)
    runs = [Simulation(mesh, pattern, solver="rigid", contact=c,
                       options=RigidOptions(coarse_start=False)).run(tolerance=1e-8)
            for c in (False, True)]
    assert runs[0].iterations == runs[1].iterations
    assert np.array_equal(runs[0].positions, runs[1].positions)
    assert runs[1].contact["active_pairs"] == []


def test_panels_sharing_points_with_their_strips_do_not_read_as_touching():
    """A Miura's panels share points with their hinge strips along straight runs of
    their outlines; those points are left out of the contact solids (their
    zero-area triangles read as intersections, which stopped every step). Driven
    to facet tilt 60°, no unjoined panels come near, and the zig-zag creases'
    panels meet only at their axis hinges' pivot (119°, below the 150° from which
    joined panels are checked): the fold is the one without contact, within the
    run's tolerance (1e-8 × 67 mm over 20 mm panels: 2e-6°)."""
    pattern = patterns.miura(3, 3, a=20.0, b=20.0, gamma=60.0)
    pattern = pattern.replace(fold_angles=patterns.miura_fold_angles(3, 3, 60.0, 60.0))
    mesh = thicken(pattern, H)
    runs = [Simulation(mesh, pattern, contact=c).run(tolerance=1e-8) for c in (False, True)]
    assert all(r.converged for r in runs)
    np.testing.assert_allclose(runs[1].fold_angles_deg, runs[0].fold_angles_deg, atol=2e-6)
    assert runs[1].contact["active_pairs"] == []


def test_a_thick_miura_driven_flat_stops_where_its_panels_meet_and_says_so():
    """Equal axis hinges give a thick Miura no flat state (they bind); with contact
    its panels meet before that (joined panels past 150° whose faces would cross),
    and the report names the creases contact stopped. Without contact the same
    run ends with two panels through each other by more than 1 % of a panel."""
    from foldcore.outputs import actuation_entries, run_summary

    pattern = patterns.miura(3, 3, a=20.0, b=20.0, gamma=60.0)
    pattern = pattern.replace(fold_angles=patterns.miura_fold_angles(3, 3, 60.0, 90.0))
    mesh = thicken(pattern, H)
    free, held = (Simulation(mesh, pattern, contact=c).run(tolerance=1e-8) for c in (False, True))
    assert max(overlap_shares(mesh, free.positions).values()) > 0.01
    entries = actuation_entries(held, pattern)
    assert entries["contact_blocked"] and held.contact["blocking_pairs"]
    _, warnings = run_summary(held, pattern, "miura", 100.0)  # no pair within d̂: no gap
    assert any("contact stops" in w for w in warnings)
    source = mesh.groups[mesh.panel_group].source
    joined = {tuple(sorted(int(source[p]) for p in pair))
              for pair in PartSolids(mesh, pattern).joined_pairs}
    unjoined = {k: v for k, v in overlap_shares(mesh, held.positions).items() if k not in joined}
    assert not unjoined or max(unjoined.values()) <= OVERLAP_SHARE, unjoined


def test_the_chain_scene_with_contact_keeps_unjoined_panels_apart():
    """``scenes.run(..., contact=True)`` (``foldcore scene NAME --contact on``): the
    chain pushed across its end stops where its panels meet; no two panels no crease
    joins overlap (their barrier holds them), and the scene records the setting."""
    from foldcore import scenes

    run = scenes.run("chain", quick=True, contact=True)
    assert run.settings["contact"] is True and run.result.contact is not None
    mesh = run.mesh
    source = mesh.groups[mesh.panel_group].source
    joined = {tuple(sorted(int(source[p]) for p in pair))
              for pair in PartSolids(mesh, run.pattern).joined_pairs}
    shares = overlap_shares(mesh, run.result.positions)
    unjoined = {k: v for k, v in shares.items() if k not in joined}
    assert not unjoined or max(unjoined.values()) <= OVERLAP_SHARE, unjoined


def test_a_step_through_a_panel_is_cut_short_of_it(letter_runs):
    mesh, sim, result = letter_runs[True]
    contact = sim.model.contact
    x0 = result.positions
    g = mesh.groups[mesh.panel_group]
    outer = g.indices[g.slots(0)]
    normal = np.cross(*(x0[outer[1:3]] - x0[outer[0]]))
    normal /= np.linalg.norm(normal)
    fractions = []
    # 3H along the normal: one way right through panel 2 (both ends free of overlap:
    # only a continuous check sees the crossing), the other way clear of it
    for sign in (1.0, -1.0):
        x1 = x0.copy()
        x1[outer] += sign * 3 * H * normal
        t = contact.free_fraction(x0, x1)
        assert len(contact.overlapping(x0 + t * (x1 - x0))) == 0
        fractions.append(t)
    assert min(fractions) < 1.0 and max(fractions) == 1.0


def test_a_step_through_a_panel_far_from_it_at_both_ends_is_cut_short():
    """A panel 3 mm above another moved 6 mm down in one step: apart at both ends, so
    only a bound that holds along the whole motion sends the pair to the continuous
    check (the broad phase's bound once took the smaller of the two ends' gaps, 2 mm,
    and let the step through)."""
    from foldcore.contact import ContactModel

    pattern = patterns.miura_one_crease(3, 3, tilt=45.0)
    mesh = thicken(pattern, H)
    contact = ContactModel(mesh, pattern, 1.0)
    s = contact.solids
    joined = {tuple(p) for p in s.joined_pairs}
    a, b = next((a, b) for a in range(s.n_panels) for b in range(a + 1, s.n_panels)
                if (a, b) not in joined)
    x0 = mesh.rest_positions.copy()
    below, above = (s.vertices[s.ptr[p]:s.ptr[p + 1]] for p in (a, b))
    x0[above] += x0[below].mean(axis=0) - x0[above].mean(axis=0) + [0.0, 0.0, 3 * H]
    x1 = x0.copy()
    x1[above] -= [0.0, 0.0, 6 * H]
    assert len(contact.overlapping(x0)) == 0 and len(contact.overlapping(x1)) == 0
    t = contact.free_fraction(x0, x1, joined=False)
    assert t < 0.5 and len(contact.overlapping(x0 + t * (x1 - x0))) == 0


def test_hinge_strips_are_parts_left_to_their_hinges_where_they_meet_a_part():
    """Every crease's strip is a part; a strip and a panel or strip it meets at a vertex
    of the pattern are left out (the hinges place them there), every other pair is
    checked, and none of those is within d̂ in the flat sheet (IPC needs a start
    without contact)."""
    from foldcore.contact import ContactModel

    pattern = patterns.miura_one_crease(3, 3, tilt=45.0)
    mesh = thicken(pattern, H)
    contact = ContactModel(mesh, pattern, 1.0)
    s = contact.solids
    assert s.n_parts == s.n_panels + len(mesh.strips_of_crease)
    assert sorted(s.part_crease[s.n_panels:]) == sorted(mesh.strips_of_crease)
    left_out = set(s.left_out.tolist())
    ends = [set(pattern.faces[f].tolist()) for f in range(len(pattern.faces))]
    ends = [ends[int(np.flatnonzero(mesh.panel_of_face == p)[0])] for p in range(s.n_panels)]
    ends += [set(pattern.edges[e].tolist()) for e in s.part_crease[s.n_panels:]]
    for a, b in combinations(range(s.n_parts), 2):
        if b < s.n_panels:
            continue  # panel pairs: as before (joined ones trimmed, the rest checked)
        assert (a * s.n_parts + b in left_out) == bool(ends[a] & ends[b]), (a, b)
    assert not contact.state(mesh.rest_positions).active


def test_a_panel_moved_through_a_hinge_strip_it_does_not_meet_is_cut_short():
    """A panel 3 mm above a crease's strip it meets at no vertex of the pattern, moved
    6 mm down in one step: the step stops short of the strip (only panels were parts
    once, and the gripper's spines passed through each other and through the jaws)."""
    from foldcore.contact import ContactModel

    pattern = patterns.miura_one_crease(3, 3, tilt=45.0)
    mesh = thicken(pattern, H)
    contact = ContactModel(mesh, pattern, 1.0)
    s = contact.solids
    left_out = set(s.left_out.tolist())
    strip, panel = next((a, b) for a in range(s.n_panels, s.n_parts) for b in range(s.n_panels)
                        if b * s.n_parts + a not in left_out)
    x0 = mesh.rest_positions.copy()
    under, above = s.part_vertices(strip), s.part_vertices(panel)
    x0[above] += x0[under].mean(axis=0) - x0[above].mean(axis=0) + [0.0, 0.0, 3 * H]
    x1 = x0.copy()
    x1[above] -= [0.0, 0.0, 6 * H]
    assert len(contact.overlapping(x0)) == 0 and len(contact.overlapping(x1)) == 0
    assert [panel, strip] in contact.overlapping(0.5 * (x0 + x1)).tolist()
    t = contact.free_fraction(x0, x1, joined=False)
    assert t < 0.5 and len(contact.overlapping(x0 + t * (x1 - x0))) == 0


def test_joined_panels_keep_their_shrunk_faces_apart():
    assert 0 < JOINED_SHARE <= OVERLAP_SHARE


def test_contact_settings_and_solvers_are_checked():
    with pytest.raises(ValueError, match="contact.activation"):
        ContactSettings(activation=0.0)
    with pytest.raises(OptionError, match="solving.contact"):
        Solving(contact="maybe")
    pattern = letter_pattern()
    with pytest.raises(SimulationError, match="does not keep panels apart"):
        Simulation(thicken(pattern, H), pattern, solver="paper", contact=True)


def test_command_line_contact(tmp_path):
    path = tmp_path / "letter.fold"
    path.write_text(json.dumps(LETTER))
    cli = [sys.executable, "-m", "foldcore", "simulate", str(path), "--thickness", "1",
           "--contact", "on"]
    refused = subprocess.run(cli + ["--solver", "anderson"], capture_output=True, text=True)
    assert refused.returncode == 2 and "Traceback" not in refused.stderr
    assert "--solver" in refused.stderr or "solver" in refused.stderr
    done = subprocess.run(cli + ["--solver", "rigid", "--report", str(tmp_path / "r.json"),
                                 "-o", str(tmp_path / "out.fold")],
                          capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
    assert "contact stops 1 of 2 driven creases" in done.stderr
    report = json.loads((tmp_path / "r.json").read_text())
    assert report["settings"]["contact"] == "on"
    assert report["actuation"]["contact_blocked"] == [0]
    assert [c["stopped_by"] for c in report["actuation"]["creases"]] == ["contact", None]


def test_contact_refuses_faces_split_into_cells(tmp_path):
    """Contact's solids are whole rigid panels: with a face split into elastic cells,
    neighbouring cells (and cells on both sides of a crease) would touch by
    construction, which crashed ipctk's Hessian projection; refused in one line."""
    from foldcore.cli import main
    from foldcore.io import write_fold

    pattern = patterns.single_hinge(panel_length=10.0, depth=5.0, angle=60.0, width=2.0)
    mesh = thicken(pattern, H, elastic="facets", cell_size=1.0)
    with pytest.raises(SimulationError, match="one rigid panel per face"):
        Simulation(mesh, pattern, contact=True)
    path = tmp_path / "crease.fold"
    write_fold(path, pattern, thickness=H)
    assert main(["simulate", str(path), "--contact", "on", "--elastic-cells", "1"]) == 2
    assert main(["simulate", str(path), "--elastic-cells", "1"]) == 0


def test_joined_panels_are_trimmed_of_their_hinge_zone():
    """Contact sees two joined panels without the band along their crease that their
    hinge decides (one hinge width deep, at most a quarter of the panel across) and
    with their faces JOINED_SHARE × H closer: the letter fold's middle panel loses
    W = πH/2 next to crease 1, its 6 mm neighbour a quarter of its 5.2 mm."""
    from foldcore.contact.barrier import HINGE_ZONE
    from foldcore.contact.solids import JoinedZones

    pattern = letter_pattern()
    mesh = thicken(pattern, H)
    solids = PartSolids(mesh, pattern)
    width = mesh.hinge_width[solids.joined_crease]
    zones = JoinedZones(solids, mesh, pattern, HINGE_ZONE * width, JOINED_SHARE)
    assert np.allclose(zones.matrix.sum(axis=1), 1.0)  # convex combinations
    (k,) = np.flatnonzero((zones.pairs == [0, 1]).all(axis=1))
    ids, _ = zones.pair(k)
    rest, trimmed = mesh.rest_positions[ids], zones.rest[zones.rows(k)]
    n = len(ids) // 2  # panel 0 (x ≤ 5.2 mm), then panel 1 (x ≥ 6.8 mm)
    side_0, side_1 = rest[:n, 0].max(), rest[n:, 0].min()
    assert trimmed[:n, 0].max() == pytest.approx(side_0 - min(width[k], 0.25 * side_0))
    assert trimmed[n:, 0].min() == pytest.approx(side_1 + width[k])
    assert np.abs(trimmed[:, 2]).max() == pytest.approx(0.5 * H * (1 - JOINED_SHARE))


def test_the_chain_and_the_box_keep_joined_panels_apart_beyond_their_hinge_zones():
    """Joined panels are checked at every angle: at the end of the chain's push and of
    the box's fold no two joined panels' trimmed solids intersect (what overlap
    they have is inside their hinge zones), and the box's diagonal creases fold
    on past the −150° at which checking them only from 150° on stopped them."""
    import ipctk
    from foldcore import scenes
    from foldcore.contact.barrier import ContactModel

    for name in ("chain", "box"):
        run = scenes.run(name, quick=True, contact=True)
        contact = ContactModel(run.mesh, run.pattern, 1.0)
        y = contact.zones.positions(run.result.positions)
        for k in range(len(contact.zones.pairs)):
            mesh, _, _ = contact._zone_mesh(k)
            assert not ipctk.has_intersections(mesh, np.asfortranarray(y[contact.zones.rows(k)]))
        if name == "box":
            for row in run.quantities["runs"]:  # H = 1 and 4 mm
                assert row["fold_angles_deg"]["diagonal"]["achieved_mean_deg"] < -160.0


def test_under_the_defaults_a_contact_that_never_engages_changes_nothing():
    """``hybrid``'s rigid phase starts on the coarse twin, which keeps contact on its
    own panels (the same prisms): where nothing touches, the run takes the same
    steps to bit-identical positions (without contact on the twin, every step
    would be the fine mesh's, another path)."""
    pattern = patterns.miura_one_crease(6, 6, tilt=45.0)
    mesh = thicken(pattern, H)
    runs = [Simulation(mesh, pattern, contact=c).run(tolerance=1e-8) for c in (False, True)]
    assert runs[0].iterations == runs[1].iterations
    assert np.array_equal(runs[0].positions, runs[1].positions)
    assert runs[1].contact["active_pairs"] == []


def test_contact_is_on_by_default_for_a_thick_sheet_and_off_where_it_cannot_be():
    """``contact="auto"`` (the default): the letter fold's outer panels stop on each
    other; ``"off"`` lets them through; where a run cannot keep panels apart the
    default is off and ``model.contact_off`` says why."""
    pattern = letter_pattern()
    mesh = thicken(pattern, H)
    for contact, apart in (("auto", True), ("off", False)):
        sim = Simulation(mesh, pattern, solver="rigid", contact=contact)
        sim.set_fold_angles({0: 180.0, 1: 180.0})
        shares = overlap_shares(mesh, sim.run(tolerance=1e-8, max_iterations=2_000).positions)
        assert (max(shares.values(), default=0.0) <= OVERLAP_SHARE) is apart, shares
    assert Simulation(mesh, pattern).model.contact_off is None
    off = {"paper": Simulation(mesh, pattern, solver="paper").model,
           "arc": Simulation(thicken(pattern, H, hinge="arc"), pattern).model}
    assert off["paper"].contact is None and "'paper'" in off["paper"].contact_off
    assert off["arc"].contact is None and "arc" in off["arc"].contact_off


def test_lbfgs_keeps_panels_apart_and_changes_nothing_where_they_do_not_meet():
    mesh, _, result = fold_letter(True, solver="lbfgs")
    shares = overlap_shares(mesh, result.positions)
    assert not shares or max(shares.values()) <= OVERLAP_SHARE, shares
    pattern = patterns.miura_one_crease(4, 4, tilt=30.0)
    mesh = thicken(pattern, H)
    runs = [Simulation(mesh, pattern, solver="lbfgs", contact=c).run(tolerance=1e-8)
            for c in ("off", "on")]
    assert runs[0].iterations == runs[1].iterations
    assert np.array_equal(runs[0].positions, runs[1].positions)
