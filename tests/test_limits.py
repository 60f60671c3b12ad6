"""Range limits: numbers outside :mod:`foldcore.limits` are refused with one line
naming the file and the item; the corners inside the window fold.

``REPRODUCERS`` are inputs that would otherwise end in a traceback (SVD did not
converge, CHOLMOD not positive definite) or a message naming no file.
"""
from __future__ import annotations

import json

import numpy as np
import pytest

from foldcore import limits, patterns
from foldcore.cli import main
from foldcore.errors import PatternError
from foldcore.io import write_fold, write_hinges, write_obj
from foldcore.simulation import Simulation
from foldcore.thickening import thicken


@pytest.fixture
def scene(tmp_path):
    """The hinge scene of tests/test_cli.py as FOLD and as OBJ + hinge file."""
    pattern = patterns.single_hinge(panel_length=5.0, depth=2.0, angle=90.0, width=2.0)
    write_fold(tmp_path / "hinge.fold", pattern, thickness=1.0)
    write_obj(tmp_path / "hinge.obj", pattern)
    write_hinges(tmp_path / "hinge.hinges", pattern)
    return tmp_path


def _fold_with(scene, name, change):
    d = json.loads((scene / "hinge.fold").read_text())
    change(d)
    (scene / name).write_text(json.dumps(d))
    return str(scene / name)


def _widths(value):
    def change(d):
        d["foldcore:edges_width"] = [None if w is None else value
                                     for w in d["foldcore:edges_width"]]
    return change


REPRODUCERS = {  # name: (how to make the pattern argument, extra options, needles)
    "thickness_option": (lambda s: str(s / "hinge.fold"), ["--thickness", "1e300"],
                         ["hinge.fold: --thickness = 1e+300 mm", "accepted"]),
    "thickness_option_tiny": (lambda s: str(s / "hinge.fold"), ["--thickness", "1e-9"],
                              ["hinge.fold: --thickness = 1e-09 mm", "accepted"]),
    "thickness_file": (lambda s: _fold_with(s, "t.fold", lambda d: d.update(
        {"foldcore:thickness": 1e300})), [], ["t.fold: foldcore:thickness = 1e+300 mm"]),
    "width_option": (lambda s: str(s / "hinge.fold"), ["--hinge-width", "1e-300"],
                     ["hinge.fold: --hinge-width = 1e-300 mm", "accepted"]),
    "width_denormal": (lambda s: str(s / "hinge.fold"), ["--hinge-width", "5e-324"],
                       ["hinge.fold: --hinge-width = 4.94066e-324 mm"]),
    "width_file": (lambda s: _fold_with(s, "w.fold", _widths(1e-300)), [],
                   ["w.fold: foldcore:edges_width[0] (edge 0) = 1e-300 mm"]),
    "width_hinge_file": (lambda s: _hinge_file(s, "1e-300"), ["--thickness", "1"],
                         ["tiny.hinges), hinge line 3: width of edge 0 = 1e-300 mm"]),
    "obj_thickness": (lambda s: str(s / "hinge.obj"), ["--thickness", "1e300"],
                      ["hinge.obj (hinges ", "--thickness = 1e+300 mm"]),
    "stiffness": (lambda s: _fold_with(s, "k.fold", lambda d: d.update(
        {"foldcore:edges_stiffness": [1e300] * len(d["edges_vertices"])})), [],
                  ["k.fold: foldcore:edges_stiffness[0] (edge 0) = 1e+300", "1e-06 … 1e+06"]),
    "huge_sheet": (lambda s: _fold_with(s, "big.fold", lambda d: d.update(
        {"vertices_coords": [[x * 1e30, y * 1e30] for x, y in d["vertices_coords"]]})), [],
                   ["big.fold: the sheet is 1e+31 mm across", "1e-06 … 1e+07 mm"]),
}


def _hinge_file(scene, width: str) -> str:
    text = (scene / "hinge.hinges").read_text()
    (scene / "tiny.hinges").write_text(text.replace("0 2.0 V", f"0 {width} V"))
    return f"{scene / 'hinge.obj'} --hinges {scene / 'tiny.hinges'}"


@pytest.mark.parametrize("name", sorted(REPRODUCERS))
def test_out_of_range_exits_2_with_one_line_and_no_output(name, scene, capsys):
    make, extra, needles = REPRODUCERS[name]
    out = scene / "out" / "out.fold"
    out.parent.mkdir()
    code = main(["simulate", *make(scene).split(" "), *extra, "-o", str(out),
                 "--report", str(out.parent / "r.json"), "--max-iterations", "20"])
    err = capsys.readouterr().err
    assert code == 2
    assert err.count("\n") == 1 and err.startswith("foldcore: error: "), err
    for needle in needles:
        assert needle in err, err
    assert not list(out.parent.iterdir())


def test_non_finite_iteration_names_the_pattern(scene, capsys, monkeypatch):
    """A non-finite iteration is reported with the pattern's file name."""
    monkeypatch.setattr(Simulation, "_step", lambda self: float("nan"))
    out = scene / "out.fold"
    code = main(["simulate", str(scene / "hinge.fold"), "-o", str(out)])
    err = capsys.readouterr().err
    assert code == 2 and err.count("\n") == 1, err
    assert f"{scene / 'hinge.fold'}: the iteration produced non-finite positions" in err
    assert not out.exists()


def test_render_hinge_width_option_is_checked(scene, capsys):
    out = scene / "out.fold"
    assert main(["simulate", str(scene / "hinge.fold"), "-o", str(out),
                 "--max-iterations", "20"]) == 0
    capsys.readouterr()
    code = main(["export", str(out), "--stl", str(scene / "x.stl"), "--hinge-width", "1e-300"])
    err = capsys.readouterr().err
    assert code == 2 and err.count("\n") == 1, err
    assert f"{out}: --hinge-width = 1e-300 mm is outside" in err
    assert not (scene / "x.stl").exists()


def test_window_is_a_window():
    """Bounds stated in one place: each ratio window is inside every length."""
    for lo, hi in (limits.THICKNESS_RATIO, limits.WIDTH_RATIO, limits.LENGTH_MM,
                   limits.STIFFNESS):
        assert 0 < lo < 1 < hi < np.inf
    assert limits.length_window(limits.THICKNESS_RATIO, 10.0) == pytest.approx((1e-5, 1e5))
    with pytest.raises(PatternError, match=r"^x: t = nan mm is outside"):
        limits.check_length(float("nan"), limits.THICKNESS_RATIO, 10.0, "t", "x")


CORNERS = {  # name: (length scale, H, W, stiffness) — at the window's edges, default solver
    "thin": (1.0, 1e-5, 2.0, None),            # H = 1e-6 × extent
    "thick": (1.0, 1e5, 2.0, None),            # H = 1e4 × extent
    "narrow": (100.0, 1.0, 1e-5, None),        # W = 1e-8 × extent
    "small": (1e-6, 1e-6, 2e-6, None),         # every length near 1e-6 mm
    "large": (1e6, 1e7, 2e6, None),            # every length near 1e7 mm
    "large_thin": (1e6, 10.0, 2e6, None),      # 1e7 mm sheet, H = 1e-6 × extent
    "soft_hinges": (1.0, 1.0, 2.0, {"hinge": 1e-6, "panel": 1e6}),
    "stiff_hinges": (1.0, 1.0, 2.0, {"hinge": 1e6, "panel": 1e-6}),
}


@pytest.mark.parametrize("name", sorted(CORNERS))
def test_corners_of_the_window_fold_to_the_target(name):
    scale, thickness, width, stiffness = CORNERS[name]
    pattern = patterns.single_hinge(panel_length=5.0 * scale, depth=2.0 * scale,
                                    angle=90.0, width=width)
    limits.check_inputs(pattern, thickness, width, stiffness)  # accepted
    mesh = thicken(pattern, thickness, None, 4, stiffness=stiffness)
    result = Simulation(mesh, pattern).run(tolerance=1e-9, max_iterations=2000)
    assert np.isfinite(result.positions).all()
    assert result.converged and abs(result.fold_angles_deg[0] - 90.0) < 0.01



# ------------------------------------------------------------ counts and run options
def _hinge():
    return patterns.single_hinge(panel_length=5.0, depth=2.0, angle=90.0, width=2.0)


@pytest.fixture
def memory_cap():
    """At most 2 GB more address space while the test runs: a mesh that is not refused
    fails with MemoryError, not on the machine."""
    resource = pytest.importorskip("resource")
    soft, hard = resource.getrlimit(resource.RLIMIT_AS)
    try:
        with open("/proc/self/status") as fh:
            size = next(int(line.split()[1]) * 1024 for line in fh if line.startswith("VmSize:"))
    except (OSError, StopIteration):  # no /proc: run uncapped
        yield
        return
    cap = size + (2 << 30)
    resource.setrlimit(resource.RLIMIT_AS, (cap if hard == resource.RLIM_INFINITY
                                            else min(cap, hard), hard))
    yield
    resource.setrlimit(resource.RLIMIT_AS, (soft, hard))


@pytest.mark.parametrize("cells", [5e-324, 1e-300])
def test_a_cell_count_too_large_for_an_integer_is_refused_before_any_cell(cells, memory_cap):
    """5e-324 mm cells made ⌈length / size⌉ infinite: OverflowError; 1e-300 mm grew
    memory without end."""
    from foldcore.errors import MeshError

    with pytest.raises(MeshError, match=r"^single_hinge: elastic (facet|plate) on face 0: .*"
                                        r"more than the 1e\+07 vertices"):
        thicken(_hinge(), 1.0, subdivisions=4, elastic="facets", cell_size=cells)
    with pytest.raises(MeshError, match="elastic plate on face 0"):
        thicken(_hinge(), 1.0, subdivisions=4, elastic="plates", cell_size=cells)


def test_the_mesh_size_is_bounded_before_the_mesh_is_built(monkeypatch, memory_cap):
    from foldcore.errors import MeshError

    with pytest.raises(MeshError, match=r"the elastic cells would have about 3.2e\+07 "
                                        r"vertices, more than the 5e\+05 accepted"):
        thicken(_hinge(), 1.0, subdivisions=4, elastic="plates", cell_size=1e-3)
    monkeypatch.setattr(limits, "MAX_MESH_VERTICES", 100)
    with pytest.raises(MeshError, match=r"^single_hinge: the thick mesh would have about "
                                        r"\d+ vertices, more than the 100 accepted"):
        thicken(_hinge(), 1.0, subdivisions=64)
    assert thicken(_hinge(), 1.0, subdivisions=4).n_vertices < 100


@pytest.mark.parametrize("k", [0, 65, 10**6])
def test_given_sub_strips_are_within_their_range(k, memory_cap):
    from foldcore.errors import MeshError

    with pytest.raises(MeshError, match=r"subdivisions must be integers in 1\.\.64"):
        thicken(_hinge(), 1.0, subdivisions=k)
    assert thicken(_hinge(), 1.0, subdivisions=limits.SUBDIVISIONS[1]).n_vertices > 0


@pytest.mark.parametrize("make, options", [
    (_hinge, {"subdivisions": 4}),
    (_hinge, {"subdivisions": 4, "elastic": "facets", "cell_size": 0.5}),
    (_hinge, {"subdivisions": 4, "elastic": "plates", "cell_size": 0.5}),
    (_hinge, {"subdivisions": 4, "elastic": {0: "auto", 1: "auto"}, "cell_size": 0.5}),
    (lambda: patterns.miura(6, 6), {"hinge_width": 2.0, "subdivisions": 2}),
    (lambda: patterns.miura(4, 4), {"hinge_width": 2.0, "subdivisions": 2, "elastic": "facets",
                                    "cell_size": 1.0}),
    (lambda: patterns.miura(4, 4), {"hinge_width": 2.0, "subdivisions": 2, "elastic": "plates",
                                    "cell_size": 1.0}),
])
def test_the_mesh_size_estimate_is_near_the_count_built(make, options, monkeypatch):
    """The estimate the bound is checked against: at least the count built and at most
    1.5 × it (a Miura 400 × 400, the largest benchmark, stays inside the bound)."""
    from foldcore.thickening import build

    estimates = []
    estimate = build.mesh_vertices
    monkeypatch.setattr(build, "mesh_vertices",
                        lambda *a: estimates.append(estimate(*a)) or estimates[-1])
    mesh = thicken(make(), 1.0, **options)
    total, elastic = estimates[0]
    assert mesh.n_vertices <= total <= 1.5 * mesh.n_vertices
    assert (elastic > 0) == bool(mesh.elastic)


def test_the_tolerance_is_bounded_where_a_verdict_still_means_something():
    """Above 1e-2 × the size a run is called converged degrees short (1e300: an
    OverflowError in the rigid-body stopping rule); 0 still runs the whole budget."""
    from foldcore.errors import SimulationError
    from foldcore.options import OptionError, Solving

    pattern = _hinge()
    sim = Simulation(thicken(pattern, 1.0, subdivisions=4), pattern)
    for tolerance in (1e300, 0.1, -1.0, float("nan")):
        with pytest.raises(SimulationError, match=r"^single_hinge: tolerance must be in "
                                                  r"\[0, 0.01\]"):
            sim.run(tolerance=tolerance, max_iterations=5)
    assert sim.run(tolerance=0, max_iterations=3).iterations == 3
    for tolerance in (1e300, 0.011, 1e-16, 0.0):
        with pytest.raises(OptionError, match=r"solving.tolerance must be in \[1e-15, 0.01\]"):
            Solving(tolerance=tolerance)
    with pytest.raises(OptionError, match=r"solving.max_iterations must be an integer in "
                                          r"1\.\.1000000"):
        Solving(max_iterations=limits.MAX_ITERATIONS + 1)
    Solving(tolerance=1e-2, max_iterations=limits.MAX_ITERATIONS)  # the corners are accepted


def test_elastic_cells_and_ground_are_checked_against_the_sheet(scene):
    """Both in mm, against the sheet's extent (10 mm): named as the options."""
    pattern = _hinge()
    limits.check_inputs(pattern, elastic_cells=1e-3, ground=-1e5)  # the window's corners
    with pytest.raises(PatternError, match=r"thickening.elastic_cells = 0.0009 mm is outside "
                                           r"the accepted 0.001 … 1e\+05 mm"):
        limits.check_inputs(pattern, elastic_cells=9e-4)
    with pytest.raises(PatternError, match=r"solving.ground = 1e\+300 mm is outside the "
                                           r"accepted ±1e\+05 mm"):
        limits.check_inputs(pattern, ground=1e300)
