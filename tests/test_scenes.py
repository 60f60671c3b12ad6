"""The paper's scenes at reduced budgets, checked against physics.

Tolerances and why:

* M/V: a passive crease may not fold against its assignment; the panels'
  measured angle may cross 0 by no more than 0.1° (rounding of a state the
  strips hold at their bound).
* d4v: in mode A of a flat-foldable vertex ρ1 = ρ3 and ρ2 = −ρ4 exactly at
  zero thickness; the hinge widths (4, 16, 4, 8 mm on R = 76.2 mm) break the
  symmetry at first order in ΔW/R, so the pairs may differ by at most
  degrees(8/76.2) = 6.0°. Flat, the state is compatible: every crease within
  0.01° of 180°, four layers whose mid-planes are ≥ H apart and a stack ≥ 4H,
  to the positions' rounding at the run's tolerance (1e-4 mm).
* waterbomb: the symmetric base is compatible (every hinge axis meets the
  symmetry axis), so the passive family follows the closed form to the
  solver's accuracy, 0.01°.
* miura: all creases driven to the zero-thickness angles; the hinge axes sit
  O(W) off the crease lines, so the angles may differ at first order in
  W/a: degrees(2/20) = 5.7°, and the corner distances by ≤ (n−1)·W.
* chain: in the zero-thickness strip the first row's panel centroids are L
  apart and the first and last rows (m − 1)·S (kinematics.miura_cell); each
  hinge strip between them adds at most its width W, so the deployed lengths
  may exceed those by ≤ W across (one zig-zag hinge) and ≤ (m − 1)·W along.
  A stop holds: once a hinge is at its 180° limit (± 0.5°) further pushes
  change the lengths by < 1e-3 mm (rounding of the converged stop).
* hinge-study: an exact-arc target is compatible, so its inner face is the
  Eq. 7 circle to rounding (1e-6 mm); Eq. 8's polygonal inner face
  approaches it as k grows.
"""
from __future__ import annotations

import json

import numpy as np
import pytest

from foldcore import scenes
from foldcore.errors import FoldcoreError

SIGN_SLACK_DEG = 0.1


def respects_assignment(pattern, angles) -> bool:
    kinds = pattern.assignments[: len(angles)]
    return bool(np.all(angles[kinds == "V"] >= -SIGN_SLACK_DEG)
                and np.all(angles[kinds == "M"] <= SIGN_SLACK_DEG))


def test_d4v_folds_further_and_keeps_mode_a(runs):
    q = runs["d4v"].quantities
    pattern = runs["d4v"].pattern
    for state in ("intermediate", "flat"):
        angles = np.array(q[state]["fold_angles_deg"])
        assert respects_assignment(pattern, angles)
        assert abs(angles[0] - angles[2]) <= np.degrees(8.0 / 76.2)
        assert abs(angles[1] + angles[3]) <= np.degrees(8.0 / 76.2)
    # 90° is below every crease's pivot angle 2·atan(W/H) (≥ 103°): the slack hinge
    # folds the thick vertex on the axis hinge's rigid-origami path, to the closed form
    closed = np.array(q["intermediate"]["closed_form_at_target_deg"])
    assert np.abs(np.array(q["intermediate"]["fold_angles_deg"]) - closed).max() < 0.01
    # flat: compatible with slack hinges (tests/test_flat_fold.py), four layers
    flat = q["flat"]
    assert np.abs(np.abs(flat["fold_angles_deg"]) - 180.0).max() < 0.01
    h = runs["d4v"].thickness
    assert flat["layers"] == 4 and flat["smallest_layer_gap_mm"] >= h - 1e-4
    assert flat["stack_height_mm"] >= 4 * h - 1e-4


def test_waterbomb_swaps_major_and_minor_and_follows_the_closed_form(runs):
    q = runs["waterbomb"].quantities
    one, two = q["position_1"], q["position_2"]
    assert one["theta_m_deg"] < 0 < one["theta_v_deg"]
    assert two["theta_m_deg"] < 0 < two["theta_v_deg"]
    assert abs(one["theta_m_deg"]) > abs(one["theta_v_deg"])
    assert abs(two["theta_v_deg"]) > abs(two["theta_m_deg"])
    assert abs(one["theta_v_deg"] - one["closed_form_minor_deg"]) < 0.01
    assert abs(-two["theta_m_deg"] - two["closed_form_minor_deg"]) < 0.01


def test_miura_follows_its_rigid_folding_path(runs):
    run = runs["miura"]
    q = run.quantities
    assert respects_assignment(run.pattern, run.result.fold_angles_deg)
    for family in ("zigzag", "straight"):  # the axis hinge: compatible at any thickness
        assert q[family]["max_deviation_deg"] < 0.01
    extent = q["extent_mm"]
    slack = (4 - 1) * 2.0
    assert abs(extent["corner_panels_x"] - extent["closed_form_x"]) <= slack
    assert abs(extent["corner_panels_y"] - extent["closed_form_y"]) <= slack


def test_chain_shortens_along_as_it_is_pushed_across_then_stops(runs):
    from foldcore.scenes import chain

    run = runs["chain"]
    q, rows = run.quantities, run.quantities["pushes"]
    assert respects_assignment(run.pattern, run.result.fold_angles_deg)
    assert q["deployed"]["converged"] and all(r["converged"] for r in rows)
    closed = q["rigid_fold_lengths_mm"]
    assert 0 <= q["before"]["transverse_mm"] - closed["transverse_mm"] <= chain.WIDTH
    assert 0 <= q["before"]["longitudinal_mm"] - closed["longitudinal_mm"] <= (chain.M - 1) * chain.WIDTH
    moving = [r for r in rows if r["max_zigzag_deg"] < 180.0 - 0.5]
    stopped = [r for r in rows if r["max_zigzag_deg"] >= 180.0 - 0.5]
    assert len(moving) >= 3 and len(stopped) >= 2
    for a, b in zip(moving, moving[1:] + stopped[:1]):
        assert b["transverse_mm"] < a["transverse_mm"]
        assert b["longitudinal_mm"] < a["longitudinal_mm"]
    # the zig-zag hinges stop at flat (their panels do not fold past it: 0.01°), and
    # with them the chain's shortening along (less than a quarter of its smallest
    # step while moving); across it still gives (module docstring)
    along = min(a["longitudinal_mm"] - b["longitudinal_mm"] for a, b in zip(moving, moving[1:]))
    for a, b in zip(stopped, stopped[1:]):
        assert b["max_zigzag_deg"] <= 180.0 + 0.01
        assert abs(b["longitudinal_mm"] - a["longitudinal_mm"]) < 0.25 * along
        assert b["transverse_mm"] <= a["transverse_mm"] + 1e-3
    shrink_along = q["before"]["longitudinal_mm"] - q["after"]["longitudinal_mm"]
    shrink_across = q["before"]["transverse_mm"] - q["after"]["transverse_mm"]
    assert shrink_along > shrink_across > 0


def test_hinge_study_radius(runs):
    rows = runs["hinge-study"].quantities["runs"]
    for row in rows:
        if row["hinge"] == "arc":
            assert row["angle_error_deg"] < 0.01
            assert abs(row["inner_radius_mm"] - row["eq7_inner_radius_mm"]) < 1e-6
        if row["hinge"] == "axis":  # past θ* = 2·atan(W/H): pivots, inner faces meet
            assert row["angle_error_deg"] < 0.01 and row["inner_gap_mm"] < 1e-6
    eq8 = {row["subdivisions"]: row for row in rows
           if row["hinge"] == "eq8" and row["width_mm"] == 1.0}
    gap = {k: abs(r["inner_radius_mm"] - r["eq7_inner_radius_mm"])
           for k, r in eq8.items() if r["inner_radius_mm"] is not None}
    assert gap[8] < gap[4]


def test_groove_bar_hinge_stops_at_its_limit_then_the_panels_bend(runs):
    """Up to 90° the pull is exactly reachable by the hinge (its model's kinematics), so
    the panels stay rigid (deviation ≤ 1e-6 of their length) and
    the hinge follows the pull; beyond it the hinge's stop holds it at 90° ± 0.5°
    (its weight ×1000, finite) and the panels' bend grows with every step."""
    steps = runs["groove-bar"].quantities["steps"]
    before = [s for s in steps if s["pull_deg"] <= 90]
    after = [s for s in steps if s["pull_deg"] > 90]
    for s in before:
        assert s["panel_deviation"] <= 1e-6
        assert abs(s["hinge_angle_deg"] - s["pull_deg"]) < 0.05
    assert all(abs(s["hinge_angle_deg"] - 90.0) <= 0.5 for s in after)
    bends = [s["panel_bend_deg"] for s in after]
    assert bends[0] > 0 and all(b > a for a, b in zip(bends, bends[1:]))


def test_scene_outputs_hold_the_quantities(runs, tmp_path):
    written = scenes.write(runs["waterbomb"], tmp_path, png=False)
    assert {p.suffix for p in written} == {".fold", ".json"}
    report = json.loads((tmp_path / "waterbomb.json").read_text())
    assert report["quantities"]["position_1"]["table_1"]["prototype"] == [-82.0, 32.0]
    assert report["settings"]["scene"] == "waterbomb"


def test_unknown_scene_is_refused_with_the_list():
    with pytest.raises(FoldcoreError, match="unknown scene 'teapot'.*d4v"):
        scenes.run("teapot")


def test_demo_main_job_writes_each_scene(tmp_path, capsys):
    from foldcore.demo import main

    assert main(["--out", str(tmp_path), "--scene", "waterbomb"]) == 0
    assert {p.name for p in tmp_path.iterdir()} == {"waterbomb.fold", "waterbomb.json",
                                                     "waterbomb.png"}
    assert "θm/θv -82.0/22.9" in capsys.readouterr().out


def test_cli_scene_writes_outputs_and_refuses_bad_input(tmp_path, capsys):
    from foldcore.cli import main

    assert main(["scene", "miura", "--out", str(tmp_path), "--quick"]) == 0
    assert {p.name for p in tmp_path.iterdir()} == {"miura.fold", "miura.json"}
    report = json.loads((tmp_path / "miura.json").read_text())
    assert report["quantities"]["zigzag"]["closed_form_deg"] == pytest.approx(60.0)
    assert main(["scene", "miura", "--out", str(tmp_path / "missing")]) == 2
    assert main(["scene", "teapot"]) == 2
    err = capsys.readouterr().err
    assert "missing: output folder does not exist" in err and "invalid choice: 'teapot'" in err


def test_the_hinge_study_picture_shows_every_run(runs, tmp_path):
    """A tile per (hinge model, W, k) run, each titled with its achieved angle."""
    import imageio.v3 as iio

    scene = runs["hinge-study"]
    assert len(scene.gallery) == len(scene.quantities["runs"]) == 18
    written = scenes.write(scene, tmp_path, png=True)
    image = iio.imread([p for p in written if str(p).endswith(".png")][0])
    tile_w, tile_h = scenes.TILE
    assert image.shape[:2] == (3 * tile_h, scenes.TILES_PER_ROW * tile_w)
    tiles = [image[r * tile_h:(r + 1) * tile_h, c * tile_w:(c + 1) * tile_w, :3]
             for r in range(3) for c in range(scenes.TILES_PER_ROW)]
    assert all((t.astype(int).sum(axis=2) < 600).mean() > 0.05 for t in tiles)  # each drawn
