"""``foldcore view`` on hostile result files: text from the file is shown as text and
never runs, and every malformed value is refused in one line before a page is written.

Base: the single hinge swept to 90 % in 4 frames (``simulate --series``). Pages
are loaded in headless Chromium (as in ``tests/test_view.py``); an injected
script would mark the page (``document.title = 'PWNED'``, a ``data-pwned``
attribute on the body), which the dumped DOM must not show.

The generated files of :func:`hostile_results` each carry one value the viewer
must not take (huge integers, NaN/inf, 1e308, wrong shapes and types, missing
coordinates, a frame of another vertex count, non-list values) and must be
refused; those of :func:`corrupted_series` (the mutations of
``tests/test_fuzz_results.py``, in any frame) must give a page whose values are
in range or be refused. 300 of each per run in CI (derandomized),
``FOLDCORE_FUZZ=long`` 10 000, ``FOLDCORE_FUZZ=N`` N.
"""
from __future__ import annotations

import base64
import copy
import html
import json
import math
import subprocess
import sys

import numpy as np
import pytest
from hypothesis import event, given
from hypothesis import strategies as st

from foldcore import patterns
from foldcore.cli import main
from foldcore.io import write_fold
from foldcore.result_file import MAX_FRAME_COORDINATE_MM, MAX_TITLE_CHARS
from test_fuzz_readers import FUZZ, _json_bytes, fold_mutation
from test_fuzz_results import frame_mutation
from test_view import chromium

pytestmark = pytest.mark.filterwarnings("ignore::foldcore.errors.PatternWarning")

#: Each would mark the page if it ran: as HTML after a closed script, as an attribute,
#: as JavaScript in a string or template literal, or by opening an HTML comment
#: that swallows the rest of the script block.
PAYLOADS = [
    "</script></title><script>document.title='PWNED';"
    "document.body.dataset.pwned='script'</script>",
    "\"><img src=x onerror=\"document.body.dataset.pwned='img'\">",
    "'-(document.body.dataset.pwned='quote')-'\u2028\u2029"
    "`${document.body.dataset.pwned='template'}`",
    "<!--<script>document.body.dataset.pwned='comment'//",
]
#: String-valued keys of a result file that the viewer does not show.
OTHER_TEXT = {"file": ["file_title", "file_author", "file_description", "x:note"],
              "frame": ["frame_description", "foldcore:reason", "x:note"]}


@pytest.fixture(scope="module")
def series(tmp_path_factory) -> dict:
    """The single hinge (5 × 2 mm panels, W = 2 mm, H = 1 mm) in 4 frames to 90 %."""
    folder = tmp_path_factory.mktemp("hostile")
    pattern = patterns.single_hinge(panel_length=5.0, depth=2.0, angle=90.0, width=2.0)
    write_fold(folder / "hinge.fold", pattern, thickness=1.0)
    out = folder / "series.fold"
    assert main(["simulate", str(folder / "hinge.fold"), "--fold-percent", "90",
                 "--frames", "4", "--series", str(out), "--max-iterations", "30",
                 "-q"]) == 0
    return json.loads(out.read_text())


def dump(page, tmp_path, fragment: str = "") -> str:
    """The page's DOM after its script ran (headless Chromium)."""
    url = page.as_uri() + (f"#{fragment}" if fragment else "")
    return chromium(url, f"--user-data-dir={tmp_path / 'profile'}", "--dump-dom").stdout


def assert_nothing_ran(dom: str) -> None:
    assert "data-pwned" not in dom and "<title>PWNED</title>" not in dom, dom[-800:]
    assert 'data-ready="yes"' in dom, dom[-800:]        # the page's own script ran to the end


def test_text_from_the_file_is_shown_as_text_and_never_runs(series, tmp_path):
    d = copy.deepcopy(series)
    for i, frame in enumerate(d["file_frames"]):
        frame["frame_title"] = PAYLOADS[i % len(PAYLOADS)]
        frame.update({key: "".join(PAYLOADS) for key in OTHER_TEXT["frame"]})
    d.update({key: "".join(PAYLOADS) for key in OTHER_TEXT["file"]})
    # the file's name is shown in the page's title, and holds a placeholder of the template
    source = tmp_path / "__DATA__ __TITLE__ <img src=x onerror=\"document.title='PWNED'\">.fold"
    source.write_text(json.dumps(d))
    page = tmp_path / "view.html"
    assert main(["view", str(source), "-o", str(page)]) == 0
    for k, frame in enumerate(d["file_frames"]):
        dom = dump(page, tmp_path, f"frame={k}")
        assert_nothing_ran(dom)
        assert f'<span id="label">{html.escape(frame["frame_title"], quote=False)}</span>' \
            in dom, dom[-800:]
        assert f"<title>foldcore: {html.escape(source.name, quote=False)}</title>" in dom


def _set_angle(key: str, value, frame: int | None = 0):
    def change(d):
        if frame is None:  # the key frame's angles, shown where a frame has none of its own
            for f in d["file_frames"]:
                f.pop(key, None)
            d["edges_foldAngle"][0] = value
        else:
            d["file_frames"][frame][key][0] = value
    return change


def _set_frame(key: str, value, frame: int = 0):
    def change(d):
        d["file_frames"][frame][key] = value
    return change


def _set_coordinate(value, frame: int = 0):
    def change(d):
        d["file_frames"][frame]["vertices_coords"][0][0] = value
    return change


SCRIPT = PAYLOADS[0]
#: Script where the file must hold a number, a title or a list: refused, no page.
NOT_TEXT = {
    "a crease angle of a frame": _set_angle("foldcore:pattern_foldAngle", SCRIPT),
    "a crease angle of the key frame": _set_angle("edges_foldAngle", SCRIPT, frame=None),
    "the angles of a frame": _set_frame("foldcore:pattern_foldAngle", SCRIPT),
    "a coordinate": _set_coordinate(SCRIPT),
    "a title in a list": _set_frame("frame_title", [SCRIPT]),
    "a title in an object": _set_frame("frame_title", {"t": SCRIPT}),
}


@pytest.mark.parametrize("where", sorted(NOT_TEXT))
def test_text_where_a_number_or_title_belongs_is_refused(where, series, tmp_path, capsys):
    d = copy.deepcopy(series)
    NOT_TEXT[where](d)
    assert_refused(d, tmp_path, capsys)


def assert_refused(d: dict, folder, capsys, what: str = "") -> str:
    """``foldcore view`` on ``d`` exits 2 with one line naming the file and writes
    nothing; the line."""
    source, page = folder / "hostile.fold", folder / "view.html"
    source.write_text(json.dumps(d))
    before = set(folder.iterdir())
    code = main(["view", str(source), "-o", str(page)])
    err = capsys.readouterr().err
    assert code == 2, (what, err)
    assert err.count("\n") == 1 and err.startswith(f"foldcore: error: {source}: "), (what, err)
    assert "Traceback" not in err and set(folder.iterdir()) == before, (what, err)
    return err


def _drop_vertex(frame: int):
    def change(d):
        d["file_frames"][frame]["vertices_coords"].pop()
    return change


NAMED = {  # what: (change, what the line must say)
    # before: OverflowError (int too large to convert to float) at view._frames
    "a huge integer in an earlier frame": (_set_coordinate(10 ** 400, frame=1), [
        "file_frames[1], vertex 0: vertices_coords[0] must be 3 finite numbers"]),
    # before: written into the page as inf (float32)
    "1e308 in an earlier frame": (_set_coordinate(1e308, frame=1), [
        "file_frames[1], vertex 0:", "beyond"]),
    "an earlier frame one vertex short": (_drop_vertex(0), [
        "file_frames[0] has 27 vertices, file_frames[3] (the last folded frame) 28"]),
    "an angle past flat": (_set_angle("foldcore:pattern_foldAngle", 180.5, frame=2), [
        "file_frames[2].foldcore:pattern_foldAngle[0] (edge 0)", "[-180, 180]"]),
}


@pytest.mark.parametrize("what", sorted(NAMED))
def test_refusals_name_the_frame_and_the_item(what, series, tmp_path, capsys):
    d = copy.deepcopy(series)
    change, needles = NAMED[what]
    change(d)
    line = assert_refused(d, tmp_path, capsys)
    assert all(needle in line for needle in needles), line


def test_the_command_refuses_without_a_traceback(series, tmp_path):
    """The installed entry point (a new process): exit code 2 and one line."""
    d = copy.deepcopy(series)
    _set_coordinate(10 ** 400, frame=0)(d)
    source = tmp_path / "huge.fold"
    source.write_text(json.dumps(d))
    proc = subprocess.run([sys.executable, "-m", "foldcore", "view", str(source), "-o",
                           str(tmp_path / "v.html")], capture_output=True, text=True,
                          timeout=300)
    assert proc.returncode == 2 and proc.stderr.count("\n") == 1, proc.stderr
    assert "Traceback" not in proc.stderr and not (tmp_path / "v.html").exists()


# ------------------------------------------------------------ generated hostile files
BAD_NUMBERS = st.sampled_from([10 ** 400, -(10 ** 400), 2 ** 1024, 1e308, -1e308,
                               1.7976931348623157e308, 1e200, math.nan, math.inf, -math.inf,
                               True, None, "1", "", [], [1.0], {}, {"x": 1}])
BAD_ANGLES = st.sampled_from([10 ** 400, 1e308, -1e308, 180.5, -181.0, 360.0, math.nan,
                              math.inf, True, "90", [], [90.0], {}])
BAD_TITLES = st.sampled_from([1, 1.5, True, [], ["t"], {}, {"t": "t"},
                              "t" * (MAX_TITLE_CHARS + 1)])
NOT_A_LIST = st.sampled_from([None, 0, 1.5, True, "[]", {}, {"0": [0, 0, 0]}])


@st.composite
def hostile_results(draw, base: dict) -> tuple[str, dict]:
    """``base`` with one value the viewer must refuse, in one of its folded frames
    (or in the key frame's angles); (what was changed, the dict)."""
    d = copy.deepcopy(base)
    frames = d["file_frames"]
    k = draw(st.integers(0, len(frames) - 1))
    frame = frames[k]
    coords, angles = frame["vertices_coords"], frame["foldcore:pattern_foldAngle"]
    how = draw(st.sampled_from(["coordinate", "row", "rows", "shift", "missing", "count",
                                "angle", "angles", "angle count", "key angles", "title"]))
    v = draw(st.integers(0, len(coords) - 1))
    if how == "coordinate":
        coords[v][draw(st.integers(0, 2))] = draw(BAD_NUMBERS)
    elif how == "row":
        coords[v] = draw(st.sampled_from([[], [0.0], [0.0, 0.0], [0.0] * 4, [[0.0, 0.0, 0.0]],
                                          None, 0.0, "0 0 0", {"x": 0.0}]))
    elif how == "rows":
        frame["vertices_coords"] = draw(NOT_A_LIST | st.just([]))
    elif how == "shift":  # the whole frame moved far off (every vertex, not one)
        offset = draw(st.sampled_from([1e16, -1e20, 1e300]))
        frame["vertices_coords"] = [[x + offset for x in row] for row in coords]
    elif how == "missing":
        del frame["vertices_coords"]
    elif how == "count":  # a frame with another vertex count than the others
        frame["vertices_coords"] = coords[:v] if draw(st.booleans()) else coords + coords[:v + 1]
    elif how == "angle":
        angles[draw(st.integers(0, len(angles) - 1))] = draw(BAD_ANGLES)
    elif how == "angles":
        frame["foldcore:pattern_foldAngle"] = draw(NOT_A_LIST.filter(lambda x: x is not None))
    elif how == "angle count":
        frame["foldcore:pattern_foldAngle"] = angles + [0.0] if draw(st.booleans()) \
            else angles[:-1]
    elif how == "key angles":  # a file whose frames show the key frame's angles
        for f in frames:
            f.pop("foldcore:pattern_foldAngle")
        d["edges_foldAngle"][0] = draw(BAD_ANGLES)
    else:
        frame["frame_title"] = draw(BAD_TITLES)
    return f"{how} in file_frames[{k}]", d


@FUZZ
@given(data=st.data())
def test_hostile_result_files_are_refused_in_one_line(series, tmp_path_factory, capsys, data):
    what, d = data.draw(hostile_results(series))
    assert_refused(d, tmp_path_factory.mktemp("h"), capsys, what)


def page_data(page) -> dict:
    """The data block of a view page, checked to be inert JSON: no ``<`` in it, so it
    cannot end its ``<script>`` element."""
    text = page.read_text()
    start = text.index(DATA_OPEN) + len(DATA_OPEN)
    block = text[start:text.index("</script>", start)]
    assert "<" not in block and "\u2028" not in block and "\u2029" not in block
    return json.loads(block)


DATA_OPEN = '<script type="application/json" id="data">'


def assert_sound_page(page) -> None:
    """What a page shows is in range: titles short text, positions and strains finite
    float32 within the coordinate bound, angles null or within ±180°."""
    for frame in page_data(page)["frames"]:
        assert isinstance(frame["title"], str) and len(frame["title"]) <= MAX_TITLE_CHARS
        xyz = np.frombuffer(base64.b64decode(frame["xyz"]), "<f4")
        assert len(xyz) and (np.abs(xyz) <= MAX_FRAME_COORDINATE_MM).all()
        assert np.isfinite(np.frombuffer(base64.b64decode(frame["strain"]), "<f4")).all()
        assert all(a is None or abs(a) <= 180.0 for a in frame["angles"])


@st.composite
def corrupted_series(draw, bases: list) -> dict:
    """A result file corrupted as in ``tests/test_fuzz_results.py``, one to three
    times, each time in the key frame, the last folded frame or an earlier one."""
    d = copy.deepcopy(draw(st.sampled_from(bases)))
    for _ in range(draw(st.integers(1, 3))):
        frames = d.get("file_frames")
        where = draw(st.sampled_from(["key", "last", "earlier"]))
        if where == "key":
            draw(fold_mutation(d))
        elif where == "earlier" and isinstance(frames, list) and len(frames) > 1:
            k = draw(st.integers(0, len(frames) - 2))
            frames.append(frames.pop(k))   # frame_mutation changes the last frame
            draw(frame_mutation(d))
            if d.get("file_frames") is frames and len(frames) > k:
                frames.insert(k, frames.pop())
        else:
            draw(frame_mutation(d))
    return d


@FUZZ
@given(data=st.data())
def test_corrupted_results_give_a_sound_page_or_one_line(series, tmp_path_factory, capsys,
                                                         data):
    """Any outcome but a page whose values are in range or a one-line refusal without a
    page is a bug (an exception escaping ``main`` fails the test as it is)."""
    d = data.draw(corrupted_series([series, _single_frame(series)]))
    folder = tmp_path_factory.mktemp("c")
    source, page = folder / "corrupted.fold", folder / "view.html"
    source.write_bytes(_json_bytes(d) or b"{}")
    code = main(["view", str(source), "-o", str(page)])
    err = capsys.readouterr().err
    event("page" if code == 0 else "refused")
    if code == 0:
        assert page.exists() and "foldcore: error" not in err, err
        assert_sound_page(page)
    else:
        assert code == 2 and err.count("\n") == 1, err
        assert err.startswith(f"foldcore: error: {source}: ") and not page.exists(), err


def _single_frame(series: dict) -> dict:
    """The series as a ``simulate -o`` result: its last frame only, without per-frame
    angles (the key frame's ``edges_foldAngle`` are shown)."""
    d = copy.deepcopy(series)
    frame = d["file_frames"][-1]
    frame.pop("foldcore:pattern_foldAngle")
    d["file_frames"] = [frame]
    return d
