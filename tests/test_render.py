"""Offscreen renders, the ``render`` command and animations (foldcore.render, foldcore.animate).

Scenes (folded with the rigid strategy: converged in ≤ 15 iterations):

* ``hinge``: single valley hinge at 90°, panels 5 mm, depth 4 mm, W = 2 mm,
  H = 1 mm, 4 sub-strips;
* ``d4``: degree-4 vertex (Pehrson's sectors, radius 20 mm, widths 4/1/2/1 mm,
  H = 1 mm), crease 1 actuated to 90°; V, V, V, M.

Image regression: each scene rendered at 400×300 px (iso view) is compared
with ``tests/data/render_<scene>.png``. Metric: the fraction of pixels whose
largest channel difference exceeds ``PIXEL_TOLERANCE`` (24 of 255) must stay
≤ ``MAX_CHANGED`` (0.5 %, 600 pixels). Why: anti-aliasing and rasteriser
rounding move a few edge pixels by small amounts, which passes; a camera
shift of one pixel (≈ 1–2 % of pixels on these edge-rich pictures), a
mountain/valley colour swap or a missing strip changes far more, which fails.
Regenerate the references after an intended change with
``FOLDCORE_UPDATE_REFERENCES=1 pytest tests/test_render.py`` and look at them.
"""
from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import folded
from folded import scene
from foldcore import patterns
from foldcore.cli import main

pytest.importorskip("pyvista")
iio = pytest.importorskip("imageio.v3")

from foldcore.render import (RenderError, colour_limits, hinge_values,  # noqa: E402
                             parse_size, per_strip, render_image, render_png,
                             strip_bend_angles)
from foldcore.thickening import thicken  # noqa: E402

DATA = Path(__file__).parent / "data"
SIZE = (400, 300)
PIXEL_TOLERANCE = 24      # of 255, largest channel difference still "the same"
MAX_CHANGED = 0.005       # fraction of pixels allowed to differ by more


def _changed_fraction(a: np.ndarray, b: np.ndarray) -> float:
    assert a.shape == b.shape, (a.shape, b.shape)
    diff = np.abs(a[..., :3].astype(int) - b[..., :3].astype(int)).max(axis=-1)
    return float((diff > PIXEL_TOLERANCE).mean())


def _blue(img):   # valley strips under any shading: blue well above red and green
    r, g, b = (img[..., i].astype(int) for i in range(3))
    return (b > r + 50) & (b > g + 25)


def _red(img):    # mountain strips
    r, g, b = (img[..., i].astype(int) for i in range(3))
    return (r > g + 50) & (r > b + 50)


def _white(img):
    return (img[..., :3] >= 250).all(axis=-1)


# ------------------------------------------------------------- image regression
@pytest.mark.parametrize("name", ["hinge", "d4"])
def test_render_matches_reference_image(name):
    pattern, mesh, result = scene(name)
    image = render_image(pattern, mesh, result.positions, size=SIZE, view="iso")
    reference = DATA / f"render_{name}.png"
    if os.environ.get("FOLDCORE_UPDATE_REFERENCES"):
        iio.imwrite(reference, image)
    expected = iio.imread(reference)
    changed = _changed_fraction(image, expected)
    assert changed <= MAX_CHANGED, f"{changed:.2%} of pixels differ from {reference.name}"


def test_reference_metric_catches_a_one_pixel_shift_and_a_colour_swap():
    expected = iio.imread(DATA / "render_d4.png")[..., :3]
    shifted = np.roll(expected, 1, axis=1)
    assert _changed_fraction(shifted, expected) > MAX_CHANGED
    swapped = expected[..., ::-1]      # red ↔ blue
    assert _changed_fraction(swapped, expected) > MAX_CHANGED


def test_render_is_not_blank_and_shows_both_mountain_and_valley():
    pattern, mesh, result = scene("d4")
    image = render_image(pattern, mesh, result.positions, size=SIZE, legend=False)
    assert image.shape == (SIZE[1], SIZE[0], 3)
    assert _white(image[0, 0]) and _white(image[-1, -1])      # white background
    assert 0.1 < 1 - _white(image).mean() < 0.9
    assert _blue(image).sum() > 100      # three valleys
    assert _red(image).sum() > 20        # one (narrow, 1 mm) mountain


def test_valley_only_scene_has_no_mountain_colour():
    pattern, mesh, result = scene("hinge")
    image = render_image(pattern, mesh, result.positions, size=SIZE, legend=False)
    assert _blue(image).sum() > 100
    assert _red(image).sum() == 0


def test_scalar_colouring_with_colour_bar(tmp_path):
    pattern, mesh, result = scene("d4")
    # the front view: the mountain crease (−45°, its strips −11.25°) faces the camera
    coloured = render_image(pattern, mesh, result.positions, size=SIZE, view="front",
                            scalars=result.strip_angles_deg, scalar_name="strip bend (deg)")
    bar = coloured[int(0.8 * SIZE[1]):]           # bottom strip: the colour bar, alone
    assert _red(bar).sum() > 300 and _blue(bar).sum() > 300     # the map's two ends
    assert (bar < 80).all(axis=-1).sum() > 30                   # its dark label text
    # signed angles, diverging map: valleys blue, the mountain red
    solid = coloured[: int(0.8 * SIZE[1])].astype(int)
    assert _blue(solid).sum() > 100
    assert ((solid[..., 0] > solid[..., 2] + 30) & (solid[..., 0] > solid[..., 1] + 15)).sum() > 10
    spread = per_strip(mesh, result.fold_angles_deg)
    np.testing.assert_array_equal(spread, result.fold_angles_deg[mesh.groups["bending_hinge"].source])


def test_per_crease_values_are_spread_even_when_strips_equal_edges():
    """7 sub-strips on a 7-edge pattern: a length test cannot tell per-crease from
    per-strip values, so per_strip() does it explicitly (each strip its crease's)."""
    pattern = patterns.single_hinge(angle=90.0, width=4.0)
    mesh = thicken(pattern, 1.0, subdivisions=pattern.n_edges)
    angles = np.full(pattern.n_edges, np.nan)
    angles[0] = 90.0
    np.testing.assert_array_equal(per_strip(mesh, angles), np.full(pattern.n_edges, 90.0))


def test_top_view_of_the_flat_sheet_is_fitted_and_true_to_scale():
    pattern, mesh, _ = scene("hinge")          # flat sheet 10 × 4 mm
    image = render_image(pattern, mesh, mesh.rest_positions, size=SIZE, view="top",
                         legend=False, padding=0.05)
    rows, cols = np.nonzero(~_white(image))
    width, height = np.ptp(cols) + 1, np.ptp(rows) + 1
    assert width / height == pytest.approx(10.0 / 4.0, rel=0.03)   # orthographic, no skew
    assert width >= 0.85 * SIZE[0]                                   # auto-fit fills the width
    assert abs((cols.min() + cols.max()) / 2 - SIZE[0] / 2) < 3       # centred


def test_views_differ_and_bad_options_are_refused(tmp_path):
    pattern, mesh, result = scene("hinge")
    images = {v: render_image(pattern, mesh, result.positions, size=(160, 120), view=v)
              for v in ("iso", "top", "side", "front")}
    for a in images:
        for b in images:
            if a < b:
                assert _changed_fraction(images[a], images[b]) > 0.02, (a, b)
    with pytest.raises(RenderError, match="unknown view"):
        render_image(pattern, mesh, result.positions, view="bottom")
    with pytest.raises(RenderError, match="pixels"):
        render_image(pattern, mesh, result.positions, size=(0, 100))
    with pytest.raises(RenderError, match="per hinge sub-strip"):
        render_image(pattern, mesh, result.positions, scalars=[1.0, 2.0])
    out = tmp_path / "x.png"
    with pytest.raises(RenderError, match="positions"):
        render_png(pattern, mesh, result.positions[:5], out)
    assert list(tmp_path.iterdir()) == []            # refused before anything is written


def test_render_png_keeps_its_positional_signature(tmp_path):
    pattern, mesh, result = scene("hinge")
    out = tmp_path / "hinge.png"
    render_png(pattern, mesh, result.positions, out, (320, 240), "side")
    assert iio.imread(out).shape[:2] == (240, 320)
    assert [p.name for p in tmp_path.iterdir()] == ["hinge.png"]


# ------------------------------------------------------------- helpers
def test_parse_size_and_colour_limits():
    assert parse_size("1200x900") == (1200, 900)
    assert parse_size("64X48") == (64, 48)
    for bad in ("1200", "x", "12x", "0x10", "10x99999", "1.5x2", "axb"):
        with pytest.raises(RenderError):
            parse_size(bad)
    assert colour_limits([-3.0, 1.0]) == (-3.0, 3.0)
    assert colour_limits([22.5, 22.5 + 1e-12]) == (0.0, 22.5 + 1e-12)
    assert colour_limits([10.0, 40.0], signed=True) == (-40.0, 40.0)


def test_strip_bend_angles_add_up_to_the_fold_angle():
    pattern, mesh, result = scene("hinge")
    bends = strip_bend_angles(mesh, result.positions)
    assert bends == pytest.approx([22.5] * 4, abs=1e-6)
    assert strip_bend_angles(mesh, mesh.rest_positions) == pytest.approx([0.0] * 4, abs=1e-9)
    pattern, mesh, result = scene("d4")
    bends = strip_bend_angles(mesh, result.positions)
    hinges = mesh.groups["bending_hinge"]
    for e, strips in mesh.strips_of_crease.items():
        assert bends[strips].sum() == pytest.approx(result.fold_angles_deg[e], abs=0.5)
    assert (bends[hinges.source == 3] < 0).all()          # crease 4 is the mountain


def test_hinge_values_takes_per_strip_values_only():
    pattern, mesh, result = scene("d4")
    assert hinge_values(pattern, mesh, result.strip_angles_deg) == \
        pytest.approx(result.strip_angles_deg)
    with pytest.raises(RenderError, match="per_strip"):
        hinge_values(pattern, mesh, result.fold_angles_deg)    # E ≠ S here: refused


def test_import_foldcore_stays_light():
    code = ("import sys, foldcore, foldcore.render, foldcore.animate, foldcore.fabrication, "
            "foldcore.cli; heavy = [m for m in ('pyvista', 'vtk', 'imageio', 'ezdxf', 'tqdm') "
            "if m in sys.modules]; print(heavy); assert not heavy")
    proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                          timeout=60)
    assert proc.returncode == 0, proc.stdout + proc.stderr


# ------------------------------------------------------------- foldcore render
@pytest.fixture
def result_fold(tmp_path):
    return folded.result_fold(tmp_path)


@pytest.mark.parametrize("extra", [[], ["--view", "top", "--color-by", "angle"],
                                   ["--view", "front", "--color-by", "strip-angle"]])
def test_cli_render_writes_the_png(result_fold, tmp_path, extra):
    out = tmp_path / "out.png"
    assert main(["render", str(result_fold), "-o", str(out), "--size", "320x240", *extra]) == 0
    image = iio.imread(out)
    assert image.shape[:2] == (240, 320)
    assert _blue(image[..., :3]).sum() > 50


def test_cli_render_matches_the_library_render(result_fold, tmp_path):
    pattern, mesh, result = scene("d4")
    out = tmp_path / "out.png"
    assert main(["render", str(result_fold), "-o", str(out), "--size", "400x300"]) == 0
    expected = render_image(pattern, mesh, result.positions, size=SIZE)
    assert _changed_fraction(iio.imread(out), expected) <= MAX_CHANGED


def _bad_render_inputs(result_fold, tmp_path):
    plain = tmp_path / "plain.fold"
    from foldcore.io import write_fold
    write_fold(plain, scene("d4")[0], thickness=1.0)        # a pattern, no folded frame
    out = str(tmp_path / "out.png")
    return {
        "missing file": (["render", str(tmp_path / "nope.fold"), "-o", out], "nope.fold"),
        "no folded frame": (["render", str(plain), "-o", out], "no folded frame"),
        "bad size": (["render", str(result_fold), "-o", out, "--size", "12x"], "--size"),
        "zero size": (["render", str(result_fold), "-o", out, "--size", "0x100"], "--size"),
        "bad view": (["render", str(result_fold), "-o", out, "--view", "under"], "--view"),
        "no folder": (["render", str(result_fold), "-o", str(tmp_path / "no" / "x.png")],
                      "no such folder"),
        "wrong subdivisions": (["render", str(result_fold), "-o", out, "--subdivisions", "2"],
                               "d4.fold"),
    }


def test_cli_render_bad_input_exits_2_with_one_line(result_fold, tmp_path, capsys):
    for what, (argv, needle) in _bad_render_inputs(result_fold, tmp_path).items():
        before = set(tmp_path.iterdir())
        assert main(argv) == 2, what
        err = capsys.readouterr().err
        assert err.count("\n") == 1 and err.startswith("foldcore: error: "), (what, err)
        assert needle in err and "Traceback" not in err, (what, err)
        assert set(tmp_path.iterdir()) == before, what              # nothing written


# ------------------------------------------------------------- animations
def test_simulate_animate_writes_a_gif_with_one_frame_per_step(tmp_path):
    from foldcore.io import write_fold

    pattern = patterns.single_hinge(panel_length=5.0, depth=4.0, angle=90.0, width=2.0)
    path = tmp_path / "hinge.fold"
    write_fold(path, pattern, thickness=1.0)
    gif, out = tmp_path / "fold.gif", tmp_path / "out.fold"
    assert main(["simulate", str(path), "--solver", "rigid", "--subdivisions", "4",
                 "--animate", str(gif), "--frames", "3", "--fps", "5", "-o", str(out)]) == 0
    frames = iio.imread(gif, index=None)
    assert frames.shape[0] == 3 and frames.shape[-1] in (3, 4)
    assert _changed_fraction(frames[0], frames[-1]) > 0.02           # flat vs folded
    import json
    assert json.loads(out.read_text())["edges_foldAngle"][0] == pytest.approx(90.0, abs=1e-3)


@pytest.mark.parametrize("extra, needle", [
    (["--animate", "fold.avi"], ".gif or .mp4"),
    (["--animate", "no/fold.gif"], "no such folder"),
    (["--animate", "fold.gif", "--frames", "1"], "--frames"),
    (["--animate", "fold.gif", "--fps", "0"], "--fps"),
    (["--animate", "fold.gif", "--fps", "500"], "--fps")])
def test_simulate_animate_bad_options_exit_2_before_simulating(tmp_path, capsys, extra,
                                                               needle, monkeypatch):
    from foldcore.io import write_fold

    pattern = patterns.single_hinge(panel_length=5.0, depth=4.0, angle=90.0, width=2.0)
    write_fold(tmp_path / "hinge.fold", pattern, thickness=1.0)
    monkeypatch.chdir(tmp_path)
    assert main(["simulate", "hinge.fold", "-o", "out.fold", *extra]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and needle in err and "Traceback" not in err, err
    assert [p.name for p in tmp_path.iterdir()] == ["hinge.fold"]


def test_animate_library_takes_its_own_schedule(tmp_path):
    from foldcore.animate import animate
    from foldcore.simulation import Simulation

    pattern, mesh, _ = scene("hinge")
    sim = Simulation(mesh, pattern, solver="rigid")
    anim = animate(sim, [0.0, 50.0, 100.0, 50.0], size=(160, 120), color_by="angle",
                   progress=False)
    assert len(anim.frames) == 4 and anim.frames[0].shape == (120, 160, 3)
    angles = [r.fold_angles_deg[0] for r in anim.results]
    assert angles == pytest.approx([0.0, 45.0, 90.0, 45.0], abs=1e-3)
    assert _changed_fraction(anim.frames[1], anim.frames[3]) <= MAX_CHANGED  # same state


def test_mp4_needs_imageio_ffmpeg_and_says_so(tmp_path, monkeypatch):
    from foldcore.animate import check_output, write_animation

    frames = [np.full((31, 41, 3), 255, np.uint8), np.zeros((31, 41, 3), np.uint8)]
    if _has("imageio_ffmpeg"):
        out = tmp_path / "a.mp4"
        write_animation(out, frames, fps=4)
        assert out.read_bytes()[4:8] == b"ftyp"                      # an MP4 container
    monkeypatch.setitem(sys.modules, "imageio_ffmpeg", None)        # as if not installed
    with pytest.raises(RenderError, match="imageio-ffmpeg"):
        check_output(tmp_path / "b.mp4")
    with pytest.raises(RenderError, match=".gif or .mp4"):
        check_output(tmp_path / "b.avi")


def _has(module: str) -> bool:
    try:
        __import__(module)
    except ImportError:
        return False
    return True



def test_render_without_a_writable_home_prints_only_its_own_line(tmp_path):
    """Without a writable home matplotlib (imported by pyvista) and Mesa each printed
    lines about their caches; the render gives them a temporary folder / no cache,
    so ``simulate --render`` prints its one summary line."""
    from foldcore.io import write_fold

    path = tmp_path / "crease.fold"
    write_fold(path, patterns.single_hinge(panel_length=10.0, depth=5.0, angle=60.0,
                                           width=2.0), thickness=1.0)
    env = dict(os.environ, HOME="/proc/none", XDG_CONFIG_HOME="/proc/none",
               XDG_CACHE_HOME="/proc/none")
    env.pop("MPLCONFIGDIR", None)
    run = subprocess.run([sys.executable, "-m", "foldcore", "simulate", str(path),
                          "--render", str(tmp_path / "x.png")],
                         capture_output=True, text=True, env=env, timeout=300)
    assert run.returncode == 0, run.stderr
    lines = [line for line in run.stderr.splitlines() if line.strip()]
    assert len(lines) == 1 and lines[0].startswith("foldcore:"), run.stderr
    assert (tmp_path / "x.png").stat().st_size > 0
