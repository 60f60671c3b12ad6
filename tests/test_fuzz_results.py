"""Property-based fuzzing of the result-file reader.

Real result files written by ``foldcore simulate -o`` (the hinge scene and a
degree-4 vertex) and one with an elastic panel (``write_result``) are
corrupted: keys deleted, types swapped, numbers replaced by NaN/inf/huge/
negative, lists emptied, nested or truncated, frames duplicated or dropped.

Property: :func:`foldcore.result_file.read_result` returns a valid
:class:`ResultFile` (whose STL and, if its footprint fits, SVG can be made or
are refused with an ExportError) or raises a :class:`FoldcoreError` whose
one-line message names the file. Any other exception is a bug, and so is a
case running longer than :data:`CASE_SECONDS` (a SIGALRM fails it).

Example counts as in ``tests/test_fuzz_readers.py``: 300 per test in CI
(derandomized), ``FOLDCORE_FUZZ=long`` 10 000, ``FOLDCORE_FUZZ=N`` N.
"""
from __future__ import annotations

import copy
import json
import math
import signal
import warnings
from contextlib import contextmanager

import numpy as np
import pytest
from hypothesis import event, given
from hypothesis import strategies as st

from foldcore import patterns
from foldcore.cli import main
from foldcore.errors import FoldcoreError
from foldcore.fabrication import ExportError, sheet_outlines
from foldcore.result_file import ResultFile, read_result
from foldcore.surface import stl_bytes
from foldcore.io import write_fold
from test_fuzz_readers import FUZZ, GARBAGE, NASTY_FLOATS, NASTY_INTS, NASTY_TEXT, \
    _json_bytes, fold_mutation

pytestmark = pytest.mark.filterwarnings("ignore::foldcore.errors.PatternWarning")

#: Longest a case may take, s (a read tries up to 18 rebuilt meshes: ~0.3 s measured).
CASE_SECONDS = 20


class Hang(Exception):
    """A case ran longer than CASE_SECONDS."""


@contextmanager
def time_limit(seconds: int):
    def alarm(signum, frame):
        raise Hang(f"longer than {seconds} s")
    old = signal.signal(signal.SIGALRM, alarm)
    signal.alarm(seconds)
    try:
        yield
    finally:
        signal.alarm(0)
        signal.signal(signal.SIGALRM, old)


# ----------------------------------------------------------------- base data
def _simulated(folder, name, pattern, *options) -> dict:
    """The result file of ``foldcore simulate -o`` on ``pattern`` (H = 1 mm)."""
    src, out = folder / f"{name}.fold", folder / f"{name}.result.fold"
    write_fold(src, pattern, thickness=1.0)
    assert main(["simulate", str(src), "-o", str(out), "--max-iterations", "30",
                 *options]) == 0
    return json.loads(out.read_text())


def _elastic(folder) -> dict:
    """A result with an elastic bar (foldcore:faces_cells), written by write_result."""
    from foldcore.outputs import write_result
    from foldcore.simulation import Simulation
    from foldcore.thickening import thicken

    pattern = patterns.single_hinge(panel_length=5.0, depth=2.0, angle=60.0, width=2.0)
    mesh = thicken(pattern, 1.0, subdivisions=2, elastic={0: 3})
    result = Simulation(mesh, pattern).run(max_iterations=30)
    out = folder / "elastic.result.fold"
    write_result(result, pattern, mesh, 1.0, {}, fold=out)
    return json.loads(out.read_text())


@pytest.fixture(scope="module")
def bases(tmp_path_factory):
    folder = tmp_path_factory.mktemp("results")
    hinge = patterns.single_hinge(panel_length=5.0, depth=2.0, angle=90.0, width=2.0)
    d4 = patterns.degree4_vertex(radius=20.0, widths=[2.0] * 4, mode="A", rho1=60.0)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return [_simulated(folder, "hinge", hinge, "--subdivisions", "4"),
                _simulated(folder, "d4", d4, "--subdivisions", "2"), _elastic(folder)]


# ---------------------------------------------------------------- strategies
FRAME_KEYS = ["frame_classes", "frame_unit", "vertices_coords", "faces_vertices",
              "frame_parent", "frame_inherit", "frame_attributes"]


@st.composite
def frame_mutation(draw, d: dict) -> None:
    """Apply one corruption to the folded frame (or to ``file_frames``) of ``d``."""
    frames = d.get("file_frames")
    how = draw(st.sampled_from(["drop", "set", "item", "subitem", "truncate", "extend",
                                "nan", "scale", "index", "frames", "classes", "unit",
                                "swap", "nest", "duplicate"]))
    if not isinstance(frames, list) or not frames or not isinstance(frames[-1], dict):
        d["file_frames"] = draw(GARBAGE | st.lists(GARBAGE | st.dictionaries(
            st.sampled_from(FRAME_KEYS), GARBAGE), max_size=3))
        return
    frame, key = frames[-1], draw(st.sampled_from(FRAME_KEYS))
    rows = frame.get(key)
    if how == "drop":
        frame.pop(key, None)
    elif how == "set":
        frame[key] = draw(GARBAGE)
    elif how == "frames":
        d["file_frames"] = draw(st.sampled_from([[], {}, None, "foldedForm", [None], [[]],
                                                 frames[:-1], frames + [frames[-1]]]))
    elif how == "duplicate":
        frames.append(copy.deepcopy(frame))
        draw(frame_mutation(d))         # the later copy differs: it is the one read
    elif how == "classes":
        frame["frame_classes"] = draw(st.sampled_from(
            [["foldedForm", "creasePattern"], ["creasePattern"], "foldedForm", [None],
             [["foldedForm"]], [], None, {"foldedForm": 1}, [1]]))
    elif how == "unit":
        frame["frame_unit"] = draw(NASTY_TEXT | GARBAGE)
    elif how == "swap":
        frame["vertices_coords"], frame["faces_vertices"] = \
            frame.get("faces_vertices"), frame.get("vertices_coords")
    elif not isinstance(rows, list) or not rows:
        frame[key] = draw(GARBAGE)
    elif how == "nest":
        frame[key] = [rows] if draw(st.booleans()) else [[r] for r in rows]
    elif how == "truncate":
        frame[key] = rows[:draw(st.integers(0, len(rows) - 1))]
    elif how == "extend":
        rows.extend(draw(st.lists(GARBAGE | st.just(rows[0]), min_size=1, max_size=3)))
    else:
        i = draw(st.integers(0, len(rows) - 1))
        if how == "item":
            rows[i] = draw(GARBAGE)
        elif not isinstance(rows[i], list) or not rows[i]:
            rows[i] = draw(NASTY_FLOATS | NASTY_INTS)
        else:
            j = draw(st.integers(0, len(rows[i]) - 1))
            if how == "nan":
                rows[i][j] = draw(NASTY_FLOATS)
            elif how == "index":
                rows[i][j] = draw(NASTY_INTS | st.integers(-3, 3000))
            elif how == "scale":
                factor = draw(st.sampled_from([1e-300, 1e-9, 1.001, 1e3, 1e9, 1e300, -1.0]))
                frame[key] = [[x * factor if isinstance(x, (int, float)) else x for x in r]
                              if isinstance(r, list) else r for r in rows]
            else:  # subitem
                rows[i][j] = draw(GARBAGE)


@st.composite
def corrupted_results(draw, bases) -> dict:
    d = copy.deepcopy(draw(st.sampled_from(bases)))
    for _ in range(draw(st.integers(1, 3))):
        if draw(st.integers(0, 2)):
            draw(frame_mutation(d))
        else:
            draw(fold_mutation(d))
    return d


OPTIONS = st.tuples(st.none() | st.sampled_from([2.0, 1.0, 1e-300, 1e300, 5e-324, 0.5]),
                    st.none() | st.sampled_from(["auto", 1, 2, 4, 16]))


# ------------------------------------------------------------------ property
def _event(name: str) -> None:
    """hypothesis' event, also outside a test (the base files' check)."""
    try:
        event(name)
    except Exception:  # InvalidArgument: not inside @given
        pass


def check_result(path, hinge_width=None, subdivisions=None) -> ResultFile | None:
    """read_result's outcome: the valid ResultFile, or None when refused properly."""
    source = str(path)
    with time_limit(CASE_SECONDS), warnings.catch_warnings():
        warnings.simplefilter("ignore")   # a PatternWarning or numpy's is not a failure
        try:
            res = read_result(path, hinge_width, subdivisions)
        except FoldcoreError as exc:
            message = str(exc)
            assert source in message and "\n" not in message, message
            assert "unexpected malformed" not in message, message
            message.encode("utf-8")
            _event("refused")
            return None
        assert isinstance(res, ResultFile)
        assert res.positions.shape == (res.mesh.n_vertices, 3)
        assert np.isfinite(res.positions).all() and 0 < res.thickness < math.inf
        assert math.isfinite(res.footprint_misfit_mm)
        try:  # a face a mutated width turned into a crossed polygon: no STL, said
            stl_bytes(res.mesh, res.positions)
            res.check_footprint()
            sheet_outlines(res.mesh)
        except ExportError as exc:
            assert source in str(exc) or "polygon" in str(exc), str(exc)
        except FoldcoreError as exc:
            assert source in str(exc) and "\n" not in str(exc), str(exc)
        _event("accepted")
        return res


def _write(tmp_path, d) -> str:
    path = tmp_path / "fuzz.result.fold"
    path.write_bytes(_json_bytes(d) or b"{}")
    return path


def test_base_results_read_back(bases, tmp_path):
    for d in bases:
        assert check_result(_write(tmp_path, d)) is not None


@FUZZ
@given(data=st.data(), options=OPTIONS)
def test_fuzz_result_files(bases, tmp_path_factory, data, options):
    d = data.draw(corrupted_results(bases))
    check_result(_write(tmp_path_factory.mktemp("r"), d), *options)


@FUZZ
@given(data=st.data())
def test_fuzz_result_frames(bases, tmp_path_factory, data):
    """Only the folded frame corrupted, one to three times."""
    d = copy.deepcopy(data.draw(st.sampled_from(bases)))
    for _ in range(data.draw(st.integers(1, 3))):
        data.draw(frame_mutation(d))
    check_result(_write(tmp_path_factory.mktemp("r"), d))


def _frame(change):
    """A change of the folded frame (the last of file_frames) of a base file."""
    def apply(d):
        change(d["file_frames"][-1])
    return apply


REGRESSIONS = {  # name: (base index, change of the dict, what the message must contain)
    # before: OverflowError (float() of the integer 10**400)
    "huge_int_coordinate": (0, _frame(lambda f: f["vertices_coords"][0].__setitem__(0, 10 ** 400)),
                            ["vertices_coords[0] must be 3 finite numbers"]),
    # before: accepted, 2.5 silently read as vertex 2 (and True as vertex 1)
    "float_face_id": (0, _frame(lambda f: f["faces_vertices"][1].__setitem__(0, 2.5)),
                      ["faces_vertices[1] must be vertex ids"]),
    "bool_face_id": (0, _frame(lambda f: f["faces_vertices"][1].__setitem__(0, True)),
                     ["faces_vertices[1] must be vertex ids"]),
}


@pytest.mark.parametrize("name", sorted(REGRESSIONS))
def test_result_regressions(name, bases, tmp_path):
    base, change, needles = REGRESSIONS[name]
    d = copy.deepcopy(bases[base])
    change(d)
    path = _write(tmp_path, d)
    with pytest.raises(FoldcoreError) as info:
        read_result(path)
    for needle in [str(path)] + needles:
        assert needle in str(info.value), str(info.value)
