"""``simulate --series`` and ``foldcore view``: the fold-percent
sweep as one FOLD file, and a self-contained page that shows it, loaded in headless
Chromium (Debian's, installed by ``make test``) and checked on its screenshots."""
from __future__ import annotations

import json
import subprocess

import numpy as np
import pytest

from foldcore.cli import main
from foldcore.result_file import read_result

CHROMIUM = "/usr/bin/chromium"
FLAGS = ["--headless", "--no-sandbox", "--disable-gpu", "--enable-unsafe-swiftshader",
         "--use-angle=swiftshader", "--disable-background-networking",
         "--disable-component-update", "--disable-sync", "--no-first-run",
         "--window-size=640,480", "--virtual-time-budget=10000"]


@pytest.fixture(scope="module")
def series(tmp_path_factory):
    """Origami Simulator's waterbomb base swept to 90 % in 4 frames."""
    path = tmp_path_factory.mktemp("series") / "wb.fold"
    assert main(["simulate", "tests/data/real/waterbombBase.svg", "--thickness", "0.5",
                 "--sheet-size", "100", "--fold-percent", "90", "--frames", "4",
                 "--series", str(path), "-q"]) == 0
    return path


def test_the_series_has_a_frame_per_fold_percent_with_its_angles(series):
    d = json.loads(series.read_text())
    frames = d["file_frames"]
    assert [f["foldcore:fold_percent"] for f in frames] == [0.0, 30.0, 60.0, 90.0]
    edges = len(d["edges_vertices"])
    largest = []
    for f in frames:
        assert "foldedForm" in f["frame_classes"] and len(f["foldcore:pattern_foldAngle"]) == edges
        targets = [t for t in f["foldcore:pattern_targetAngle"] if t is not None]
        assert max(map(abs, targets)) == pytest.approx(180.0 * f["foldcore:fold_percent"] / 100)
        largest.append(max(abs(a) for a in f["foldcore:pattern_foldAngle"] if a is not None))
    assert largest[0] < 1e-6 and np.all(np.diff(largest) > 10.0)  # folding further each frame
    res = read_result(series)  # render/export take the last frame
    assert res.positions == pytest.approx(np.array(frames[-1]["vertices_coords"]))


def chromium(url: str, *extra) -> subprocess.CompletedProcess:
    return subprocess.run([CHROMIUM, *FLAGS, *extra, url], capture_output=True, text=True,
                          timeout=120)


def screenshot(page, tmp_path, fragment: str) -> np.ndarray:
    import imageio.v3 as iio

    shot = tmp_path / f"shot-{fragment.replace('&', '-').replace('=', '')}.png"
    chromium(f"file://{page}#{fragment}", f"--user-data-dir={tmp_path / 'profile'}",
             f"--screenshot={shot}")
    return iio.imread(shot)[..., :3].astype(int)


def count(image, hue: str) -> int:
    """Reddish or bluish pixels (one channel ≥ 60 above the other two; the thin hinges
    are shaded and antialiased) below the controls (the top 80 rows)."""
    r, g, b = np.moveaxis(image[80:], 2, 0)
    main, others = (r, (g, b)) if hue == "red" else (b, (r, g))
    return int(((main - others[0] >= 60) & (main - others[1] >= 60)).sum())


def test_the_page_is_self_contained_and_shows_each_frame(series, tmp_path):
    page = tmp_path / "view.html"
    assert main(["view", str(series), "-o", str(page)]) == 0
    text = page.read_text()
    assert "<script src" not in text and "@import" not in text  # nothing fetched
    dom = chromium(f"file://{page}", f"--user-data-dir={tmp_path / 'profile'}",
                   "--dump-dom").stdout
    assert 'data-ready="yes"' in dom and 'data-frames="4"' in dom, dom[-500:]
    flat, folded = (screenshot(page, tmp_path, f"frame={k}") for k in (0, 3))
    ink = lambda im: int((im.sum(axis=2) < 740).sum())  # noqa: E731  non-white pixels
    assert ink(flat) > 1000 and ink(folded) > 1000
    assert np.abs(flat - folded).sum(axis=2).astype(bool).mean() > 0.01  # it moved
    assert count(folded, "red") > 0 and count(folded, "blue") > 0  # M/V colours by default
    assert count(flat, "red") > 0  # the flat sheet's hinges show their M/V colours ...
    flat_angles = screenshot(page, tmp_path, "frame=0&colour=angle")  # ... not their angles
    assert count(flat_angles, "red") == count(flat_angles, "blue") == 0  # flat: angles ~0
    strained, unstrained = (screenshot(page, tmp_path, f"frame={k}&colour=strain")
                            for k in (3, 0))
    yellow = lambda im: int(((im[80:, :, :2].min(axis=2) - im[80:, :, 2]) >= 60).sum())  # noqa: E731
    assert yellow(strained) > 0 and yellow(unstrained) == 0  # the largest strain: folded


@pytest.mark.parametrize("colour, words", [
    ("mv", ["mountain", "valley", "facet (F)", "undriven (U)", "panel"]),
    ("angle", ["fold angle: mountain \u2212{a}\u00b0", "+{a}\u00b0 valley"]),
    ("strain", ["largest surface strain of each hinge sub-strip: 0"])])
def test_each_colouring_has_its_legend_with_the_scale_it_shows(series, tmp_path, colour,
                                                               words):
    """The angle legend's ends are the largest |angle| over the frames' creases."""
    d = json.loads(series.read_text())
    largest = max(abs(a) for f in d["file_frames"] for a in f["foldcore:pattern_foldAngle"]
                  if a is not None)
    page = tmp_path / "view.html"
    assert main(["view", str(series), "-o", str(page)]) == 0
    dom = chromium(f"file://{page}#colour={colour}", f"--user-data-dir={tmp_path / 'p'}",
                   "--dump-dom").stdout
    legend = dom[dom.index('id="legend"'):]
    legend = legend[:legend.index("</div>")]
    for w in words:
        assert w.format(a=float(f"{largest:.3g}")).replace(".0\u00b0", "\u00b0") in legend


def test_a_thin_sheets_series_shows_a_frame_per_fold_percent(tmp_path):
    series, page = tmp_path / "wb.fold", tmp_path / "wb.html"
    assert main(["simulate", "tests/data/real/waterbombBase.svg", "--fold-percent", "90",
                 "--frames", "3", "--series", str(series), "-q"]) == 0
    assert main(["view", str(series), "-o", str(page)]) == 0
    dom = chromium(f"file://{page}", f"--user-data-dir={tmp_path / 'p'}", "--dump-dom").stdout
    assert 'data-ready="yes"' in dom and 'data-frames="3"' in dom, dom[-500:]
    flat, folded = (screenshot(page, tmp_path, f"frame={k}") for k in (0, 2))
    assert np.abs(flat - folded).sum(axis=2).astype(bool).mean() > 0.01  # it moved
    strained = chromium(f"file://{page}#colour=strain", f"--user-data-dir={tmp_path / 'q'}",
                        "--dump-dom").stdout
    assert "largest side strain of each facet: 0" in strained


def test_a_facets_strain_is_its_largest_side_strain_against_the_flat_sheet():
    """A right triangle (legs 10 mm) stretched 1 % along x and pressed 2 % along y:
    the legs strain by 0.01 and 0.02, the hypotenuse by less; a degenerate facet's
    strain is bounded, not infinite."""
    from foldcore.pattern import CreasePattern
    from foldcore.measure import MAX_SHOWN_STRAIN, facet_strains

    pattern = CreasePattern([(0, 0), (10, 0), (0, 10)], [(0, 1), (1, 2), (2, 0)], "BBB")
    moved = np.array([[0, 0, 0], [10.1, 0, 0], [0, 9.8, 0]])
    assert facet_strains(pattern, np.array([[0, 1, 2]]), moved) == pytest.approx([0.02])
    assert facet_strains(pattern, np.array([[0, 0, 2]]), moved)[0] <= MAX_SHOWN_STRAIN


def test_view_refuses_what_it_cannot_show_in_one_line(tmp_path, capsys):
    pattern = tmp_path / "p.svg"
    pattern.write_text("<svg/>")
    assert main(["view", str(pattern), "-o", str(tmp_path / "v.html")]) == 2
    assert main(["view", str(pattern), "-o", str(tmp_path / "v.png")]) == 2
    lines = capsys.readouterr().err.splitlines()
    assert len(lines) == 2 and all(line.startswith("foldcore: error: ") for line in lines)
    assert not (tmp_path / "v.html").exists()


def test_a_thin_sheets_result_shows_its_folded_triangles(tmp_path):
    """A result folded with no thickness (the thin sheet) has no thick mesh to rebuild:
    ``view`` shows its folded triangles (grey facets, the creases drawn over them in
    their M/V colours) and ``render`` draws them with the creases in their colours,
    instead of refusing it; ``render --color-by angle`` colours the creases (valley
    blue, mountain red), ``strain`` the facets with a colour bar, and ``strip-angle``
    (a thick sheet's sub-strips) is refused."""
    result, page = tmp_path / "wb.fold", tmp_path / "wb.html"
    assert main(["simulate", "tests/data/real/waterbombBase.svg", "--fold-percent", "80",
                 "-o", str(result), "-q"]) == 0
    assert main(["view", str(result), "-o", str(page)]) == 0
    dom = chromium(f"file://{page}", f"--user-data-dir={tmp_path / 'profile'}",
                   "--dump-dom").stdout
    assert 'data-ready="yes"' in dom and 'data-frames="1"' in dom, dom[-500:]
    image = screenshot(page, tmp_path, "frame=0")
    assert int((image.sum(axis=2) < 740).sum()) > 1000  # the sheet is drawn
    assert count(image, "red") > 0 and count(image, "blue") > 0  # the M/V crease lines
    picture = tmp_path / "wb.png"
    assert main(["render", str(result), "-o", str(picture), "--size", "320x240"]) == 0
    drawn = screenshot_of(picture)
    assert count(drawn, "red") > 0 and count(drawn, "blue") > 0  # the M/V creases
    angles, strains = tmp_path / "angle.png", tmp_path / "strain.png"
    assert main(["render", str(result), "-o", str(angles), "--color-by", "angle"]) == 0
    drawn = screenshot_of(angles)
    assert count(drawn, "red") > 0 and count(drawn, "blue") > 0  # mountains, valleys
    assert main(["render", str(result), "-o", str(strains), "--color-by", "strain"]) == 0
    drawn = screenshot_of(strains)
    viridis_top = (drawn[..., 0] > 200) & (drawn[..., 1] > 200) & (drawn[..., 2] < 80)
    assert viridis_top.sum() > 0  # the colour bar's (and the most strained facet's) yellow
    assert main(["render", str(result), "-o", str(tmp_path / "no.png"),
                 "--color-by", "strip-angle"]) == 2
    assert not (tmp_path / "no.png").exists()


def screenshot_of(path) -> np.ndarray:
    import imageio.v3 as iio

    return iio.imread(path)[..., :3].astype(int)
