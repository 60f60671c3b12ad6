"""A study's plots and HTML report (foldcore.study.report, ``foldcore sweep --plots
--report``): one PNG per figure × swept parameter, a self-contained page in which
no value of the table becomes markup, and pictures of the kept solids linking to
their view pages. Most tables are built by hand (no Dask); one tiny real sweep
runs in this process (``workers=0``)."""
from __future__ import annotations

import math
import re
from html.parser import HTMLParser
from pathlib import Path

import pytest

pd = pytest.importorskip("pandas")
pytest.importorskip("matplotlib")
Image = pytest.importorskip("PIL.Image")

from foldcore.study import report  # noqa: E402
from foldcore.study.sweep import FIGURES, TRAILING  # noqa: E402

HOSTILE = "<script>alert(1)</script>"
HOSTILE_ERROR = '<img src=x onerror="alert(2)">'


def frame_of(points: list[dict], metric: list[dict] | None = None,
             errors: list[str] | None = None):
    """A study table of ``points`` as :func:`foldcore.study.sweep` lays it out, with
    made-up figures (each a function of the row, so the plots have something)."""
    rows = []
    for i, point in enumerate(points):
        error = (errors or [""] * len(points))[i]
        figures = {name: math.nan for name in FIGURES}
        if not error:
            figures.update(converged=i % 3 != 2, reason="converged", iterations=10 + i,
                           wall_s=0.1 * (i + 1), miss_max_deg=0.5 * i,
                           largest_strain=0.01 * i, stack_height_mm=2.0 + i)
        trailing = {"start": "flat", "worker": "tcp://127.0.0.1:1", "cached": False,
                    "result_fold": "", "warnings": "", "error": error}
        rows.append({**point, **figures, **((metric or [{}] * len(points))[i]), **trailing})
    return pd.DataFrame(rows)


def grid_frame(errors=None, metric=True):
    """thickness × hinge-width × solver (2 × 3 × 2), n fixed; a metric with a number,
    a text and a flag column."""
    points = [{"n": 2, "thickness": t, "hinge-width": w, "solver": s}
              for t in (0.1, 0.2) for w in (0.3, 0.5, 0.7) for s in ("newton", "paper")]
    metric_rows = [{"span_mm": 10.0 + i, "tag": "x", "flat": True}
                   for i in range(len(points))] if metric else None
    return frame_of(points, metric_rows, errors)


def is_png(path: Path) -> tuple[int, int]:
    with Image.open(path) as im:
        im.verify()
    with Image.open(path) as im:
        return im.size


class Tags(HTMLParser):
    """Every start tag of a page with its attributes."""

    def __init__(self):
        super().__init__()
        self.tags = []

    def handle_starttag(self, tag, attrs):
        self.tags.append((tag, dict(attrs)))


def tags_of(text: str) -> list[tuple[str, dict]]:
    parser = Tags()
    parser.feed(text)
    return parser.tags


def assert_self_contained(text: str, page: Path) -> None:
    """No script, nothing fetched: every src a data URI, every href a fragment or a
    relative file beside the page that exists."""
    assert not re.search(r"(src|href)\s*=\s*[\"']?\s*(https?:)?//", text, re.I)
    for tag, attrs in tags_of(text):
        assert tag not in ("script", "link", "iframe", "object", "embed"), tag
        if "src" in attrs:
            assert attrs["src"].startswith("data:image/png;base64,"), attrs["src"][:40]
        if "href" in attrs and not attrs["href"].startswith("#"):
            assert ":" not in attrs["href"] and (page.parent / attrs["href"]).is_file()
        assert not any(name.startswith("on") for name in attrs), attrs


# ---------------------------------------------------------------- columns
def test_parameters_are_point_names_with_more_than_one_value():
    frame = grid_frame()
    assert report.point_names(frame) == ["n", "thickness", "hinge-width", "solver"]
    assert report.swept(frame) == ["thickness", "hinge-width", "solver"]
    assert report.swept(frame, names=["n", "thickness"]) == ["thickness"]


def test_plotted_are_the_named_figures_then_the_metrics_numbers():
    """Text and flag columns of the metric are not plotted; nor a parameter."""
    assert report.plotted(grid_frame()) == list(report.PLOTTED) + ["span_mm"]
    assert set(report.PLOTTED) >= {"miss_max_deg", "iterations", "wall_s", "largest_strain",
                                   "stack_height_mm"}


def test_labels_carry_units():
    assert "(°)" in report.label("miss_max_deg")
    assert "(mm)" in report.label("stack_height_mm")
    assert "(s)" in report.label("wall_s")
    assert report.label("thickness") == "thickness (mm)"
    assert report.label("span_mm") == "span_mm (mm)"
    assert report.label("tip_deg") == "tip_deg (°)"


# ---------------------------------------------------------------- plots
def test_one_valid_png_per_figure_and_swept_parameter(tmp_path):
    frame = grid_frame(errors=[""] * 11 + ["point failed"])
    paths = report.write_plots(frame, tmp_path / "plots")
    assert len(paths) == 6 * 3                  # 5 figures + span_mm, × 3 parameters
    assert len(set(paths)) == len(paths)
    assert sorted(p.name for p in (tmp_path / "plots").iterdir()) == sorted(p.name for p in paths)
    assert (tmp_path / "plots" / "miss_max_deg-vs-thickness.png") in paths
    assert (tmp_path / "plots" / "span_mm-vs-solver.png") in paths
    for path in paths:
        width, height = is_png(path)
        assert width > 300 and height > 200


def test_failed_rows_are_left_out_and_counted_in_the_title(tmp_path, monkeypatch):
    """The plotted points are the rows without an error; the title says how many were
    left out."""
    from matplotlib.axes import Axes

    titles, drawn = [], []
    real_title, real_plot = Axes.set_title, Axes.plot
    monkeypatch.setattr(Axes, "set_title",
                        lambda self, text, *a, **k: titles.append(text) or
                        real_title(self, text, *a, **k))
    monkeypatch.setattr(Axes, "plot", lambda self, *a, **k: drawn.append(a) or
                        real_plot(self, *a, **k))
    frame = frame_of([{"thickness": t} for t in (0.1, 0.2, 0.3, 0.4)],
                     errors=["", "boom", "", "boom"])
    paths = report.write_plots(frame, tmp_path)
    assert len(paths) == len(report.PLOTTED)
    assert all("2 failed points left out" in t for t in titles)
    xs = {x for args in drawn if len(args) >= 2 for x in args[0]}
    assert xs == {0.1, 0.3}


def test_nothing_to_plot_writes_nothing(tmp_path):
    single = frame_of([{"thickness": 0.1, "n": 2}])
    assert report.write_plots(single, tmp_path / "a") == []
    failed = frame_of([{"thickness": t} for t in (0.1, 0.2)], errors=["x", "y"])
    assert report.write_plots(failed, tmp_path / "b") == []


def test_many_series_fall_back_to_one_parameter_or_one_colour(tmp_path):
    """7 combinations of the other parameters are too many colours: the first other
    parameter with few values colours the points; with none, one colour."""
    points = [{"a": a, "b": b, "c": c} for a in (1, 2) for b in range(7) for c in (1, 2)]
    frame = frame_of(points)
    assert report._series_keys(frame, ["b", "c"])[0] == ["c"]
    assert report._series_keys(frame, ["b"]) == ([], {})
    assert len(report.write_plots(frame, tmp_path)) == 3 * len(report.PLOTTED)


def test_values_that_read_alike_are_still_distinct():
    frame = frame_of([{"thickness": t} for t in (0.100001, 0.100002)])
    assert report.swept(frame) == ["thickness"]


def test_values_with_dollars_and_lists_plot_as_text(tmp_path):
    """A categorical value is drawn as plain text (no mathtext), lists as JSON."""
    frame = frame_of([{"actuation": v, "sectors": s} for v in ("$x^$", "a$b")
                      for s in ([90, 90, 90, 90], [100, 80, 100, 80])])
    paths = report.write_plots(frame, tmp_path)
    assert len(paths) == 2 * len(report.PLOTTED)
    for path in paths:
        is_png(path)


def test_the_table_read_back_from_csv_plots_the_same(tmp_path):
    from foldcore.study import write_table

    frame = grid_frame(errors=[""] * 11 + ["point failed"])
    write_table(frame, tmp_path / "t.csv")
    back = pd.read_csv(tmp_path / "t.csv")
    assert report.swept(back) == report.swept(frame)
    assert report.plotted(back) == report.plotted(frame)
    assert len(report.write_plots(back, tmp_path / "plots")) == 18
    assert "8 converged" in report.summary_text(back)
    assert "1 failed" in report.summary_text(back)


# ---------------------------------------------------------------- report
def test_report_is_one_self_contained_page(tmp_path):
    frame = grid_frame(errors=[""] * 11 + ["point failed"])
    out = tmp_path / "study.html"
    report.write_report(frame, out, pattern_label="miura")
    text = out.read_text()
    assert_self_contained(text, out)
    images = [a["src"] for t, a in tags_of(text) if t == "img"]
    assert len(images) == 18                    # the plots, drawn for the page
    assert "12 points: 8 converged, 3 did not converge, 1 failed" in text
    assert "Folded on 1 worker, 0 from the cache" in text
    assert text.count("<tr") == 1 + 12          # header + a row per point
    assert text.count('<tr class="failed">') == 1
    assert not (tmp_path / "study_files").exists()  # no kept result, no view page


def test_report_shows_the_plots_it_is_given(tmp_path):
    frame = grid_frame()
    plots = report.write_plots(frame, tmp_path / "plots")
    report.write_report(frame, tmp_path / "a.html", pattern_label="p", plots=plots[:2])
    report.write_report(frame, tmp_path / "b.html", pattern_label="p", plots=[])
    assert (tmp_path / "a.html").read_text().count("<img") == 2
    b = (tmp_path / "b.html").read_text()
    assert "<img" not in b and "No plot" in b


def test_hostile_values_are_escaped_never_markup(tmp_path):
    """A parameter value, an error message, a metric column's name and the pattern's
    label reach the page as text."""
    points = [{"thickness": t, "solver": s} for t in (0.1, 0.2) for s in (HOSTILE, "newton")]
    frame = frame_of(points, [{"<b>m</b>": 1.0 * i} for i in range(4)],
                     errors=["", "", HOSTILE_ERROR, ""])
    out = tmp_path / "r.html"
    report.write_report(frame, out, pattern_label='</title><script>alert(3)</script>')
    text = out.read_text()
    assert "<script" not in text.lower()
    assert "<img src=x" not in text and "<b>m</b>" not in text
    assert "&lt;script&gt;alert(1)&lt;/script&gt;" in text
    assert "&lt;img src=x onerror=&quot;alert(2)&quot;&gt;" in text
    assert "&lt;/title&gt;&lt;script&gt;alert(3)" in text
    assert_self_contained(text, out)


def test_a_missing_result_file_is_a_note_not_a_lost_report(tmp_path):
    frame = frame_of([{"thickness": t} for t in (0.1, 0.2)])
    frame.loc[0, "result_fold"] = str(tmp_path / "gone.fold")
    out = tmp_path / "r.html"
    report.write_report(frame, out, pattern_label="p")
    text = out.read_text()
    assert "no view page" in text and "gone.fold" in text
    assert_self_contained(text, out)


# ---------------------------------------------------------------- a real sweep
def span(fold) -> dict:
    """A metric: the folded solid's extent along x, mm."""
    import numpy as np

    return {"span_mm": float(np.ptp(fold.result.positions[:, 0]))}


@pytest.fixture(scope="module")
def kept(tmp_path_factory):
    """A tiny Miura sweep over two thicknesses, folded in this process, results kept."""
    from foldcore import study

    folder = tmp_path_factory.mktemp("study")
    frame = study.sweep("miura", grid={"n": [2], "m": [2], "thickness": [0.1, 0.2],
                                       "hinge-width": [0.5]},
                        workers=0, cache=None, keep=folder / "keep", metric=span)
    return frame, folder


def test_a_real_sweep_gives_plots_and_a_report_linking_its_solids(kept, tmp_path):
    frame, _ = kept
    assert (frame["error"] == "").all() and (frame["result_fold"] != "").all()
    plots = report.write_plots(frame, tmp_path / "plots")
    assert sorted(p.name for p in plots) == sorted(
        f"{f}-vs-thickness.png" for f in (*report.PLOTTED, "span_mm"))
    for path in plots:
        is_png(path)
    out = tmp_path / "study.html"
    report.write_report(frame, out, pattern_label="miura", plots=plots)
    text = out.read_text()
    assert_self_contained(text, out)
    pages = sorted((tmp_path / "study_files").iterdir())
    assert [p.name for p in pages] == ["point-0000.html", "point-0001.html"]
    links = [a for t, a in tags_of(text) if t == "a"]
    assert {a["href"] for a in links} == {"study_files/point-0000.html",
                                         "study_files/point-0001.html"}
    assert all("three" in p.read_text()[:200_000] for p in pages)  # foldcore view's page
    try:
        import pyvista
    except ImportError:
        pyvista = None
    if pyvista is None:
        assert "No pictures of the folded solids" in text
        return
    thumbs = [a for t, a in tags_of(text) if t == "img" and a.get("width") == "240"]
    assert len(thumbs) == 2 and "No pictures" not in text


def test_without_a_renderer_the_report_links_the_view_pages(kept, tmp_path, monkeypatch):
    """Rendering that fails (here: no pyvista) loses no report: a note says so and
    the view pages are linked by text."""
    import foldcore.render
    from foldcore.render import RenderError

    def missing(*args, **kwargs):
        raise RenderError("rendering needs pyvista: pip install 'foldcore[render]'")

    monkeypatch.setattr(foldcore.render, "require_pyvista", missing)
    frame, _ = kept
    out = tmp_path / "r.html"
    report.write_report(frame, out, pattern_label="miura", plots=[])
    text = out.read_text()
    assert "No pictures of the folded solids: rendering needs pyvista" in text
    assert text.count(">view the folded solid</a>") == 2
    assert "<img" not in text
    assert_self_contained(text, out)


def test_thumbnails_off_writes_no_view_page(kept, tmp_path):
    frame, _ = kept
    report.write_report(frame, tmp_path / "r.html", pattern_label="m", plots=[],
                        thumbnails=False)
    assert not (tmp_path / "r_files").exists()
    assert "Folded solids" not in (tmp_path / "r.html").read_text()


# ---------------------------------------------------------------- command line
def test_sweep_writes_plots_and_report(tmp_path, capsys):
    from foldcore.cli import main

    code = main(["sweep", "miura", "--set", "n=2", "--set", "m=2", "--set",
                 "thickness=0.1,0.2", "--workers", "0", "--no-cache", "-q",
                 "-o", str(tmp_path / "t.csv"), "--plots", str(tmp_path / "plots"),
                 "--report", str(tmp_path / "r.html"), "--keep", str(tmp_path / "keep")])
    assert code == 0, capsys.readouterr().err
    assert len(list((tmp_path / "plots").glob("*.png"))) == len(report.PLOTTED)
    assert sorted(p.name for p in (tmp_path / "r_files").iterdir()) == [
        "point-0000.html", "point-0001.html"]
    assert_self_contained((tmp_path / "r.html").read_text(), tmp_path / "r.html")


@pytest.mark.parametrize("flags, message", [
    (["--report", "r.pdf"], "--report r.pdf: writes .html or .htm only"),
    (["--report", "t.csv"], "writes .html or .htm only"),
    (["--plots", "afile"], "--plots afile: is a file, not a folder"),
    (["--plots", "nope/plots"], "no such folder"),
    (["--report", "r.html", "--keep", "k"], "its view pages' folder r_files: is a file"),
])
def test_bad_destinations_are_refused_before_any_fold(tmp_path, monkeypatch, capsys, flags,
                                                      message):
    import importlib

    from foldcore.cli import main

    sweep_module = importlib.import_module("foldcore.study.sweep")  # not the function
    monkeypatch.chdir(tmp_path)
    (tmp_path / "afile").write_text("")
    (tmp_path / "r_files").write_text("")
    monkeypatch.setattr(sweep_module, "sweep", lambda *a, **k: pytest.fail("folded"))
    code = main(["sweep", "miura", "--set", "n=2", "-o", "t.csv", *flags])
    assert code == 2
    assert message in capsys.readouterr().err
    assert not (tmp_path / "t.csv").exists()


def test_importing_the_study_imports_no_plotting():
    import subprocess
    import sys

    code = ("import sys, foldcore, foldcore.study, foldcore.study.report, "
            "foldcore.study.commands; "
            "print(sorted(m for m in ('matplotlib', 'pyvista', 'vtk', 'dask', 'distributed', "
            "'pandas') if m in sys.modules))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         check=True, timeout=120).stdout
    assert out.strip() == "[]"


def test_trailing_and_figures_are_the_sweeps():
    """The report reads the table by the sweep's own column lists."""
    assert report.FIGURES is FIGURES and report.TRAILING is TRAILING
