"""Fabrication files (foldcore.fabrication) and ``foldcore export``.

Every file is read back by an independent library: SVG by an XML parser
(xml.etree), DXF by ezdxf, STL by trimesh (and its edges counted here).

Volume checks (STL, float32 coordinates):

* rest: enclosed volume = Σ prism volumes (``mesh.volume()``), relative 1e-6;
* single hinge folded by the rigid strategy (each sub-strip a planar-faced
  prism bent by φ about the arc's centre): panels keep their volume and each
  sub-strip's cross-section becomes a trapezoid of area W/k·H·sin φ/φ, so the
  volume is V_panels + Σ V_strip·sin φ/φ, relative 1e-6;
* degree-4 vertex folded: the panels keep their volume and no sub-strip can
  lose more than its chord deficit, so V_panels + V_hinges·sin φmax/φmax −
  1e-6·V ≤ V ≤ V_rest + 1e-6·V.
"""
from __future__ import annotations

import json
import sys
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np
import pytest

import folded
from folded import scene
from foldcore import patterns
from foldcore.strain import neutral_lengths
from foldcore.cli import main
from foldcore.errors import PatternError
from foldcore.fabrication import ExportError, sheet_outlines
from foldcore.files import atomic_path
from foldcore.result_file import read_result
from foldcore.surface import stl_bytes, surface_triangles, triangulate_polygon

SVG_NS = "{http://www.w3.org/2000/svg}"


@pytest.fixture
def result_fold(tmp_path):
    return folded.result_fold(tmp_path)


def _area(xy) -> float:
    xy = np.asarray(xy, dtype=float)
    return 0.5 * float(np.sum(xy[:, 0] * np.roll(xy[:, 1], -1) - np.roll(xy[:, 0], -1) * xy[:, 1]))


# ------------------------------------------------------------------ STL
def _trimesh_of(data: bytes, tmp_path):
    trimesh = pytest.importorskip("trimesh")
    path = tmp_path / "solid.stl"
    path.write_bytes(data)
    return trimesh.load(str(path), file_type="stl", process=True)


def _check_closed_and_oriented(faces: np.ndarray):
    """Every edge in exactly two triangles, once in each direction (consistent winding)."""
    directed = np.vstack([faces[:, [0, 1]], faces[:, [1, 2]], faces[:, [2, 0]]])
    undirected, counts = np.unique(np.sort(directed, axis=1), axis=0, return_counts=True)
    assert (counts == 2).all(), f"{(counts != 2).sum()} edges not shared by two triangles"
    assert len(np.unique(directed, axis=0)) == len(directed), "an edge used twice one way"


@pytest.mark.parametrize("name", ["hinge", "d4"])
def test_stl_at_rest_is_watertight_with_the_prism_volume(name, tmp_path):
    _, mesh, _ = scene(name)
    solid = _trimesh_of(stl_bytes(mesh), tmp_path)
    assert solid.is_watertight and solid.is_winding_consistent
    _check_closed_and_oriented(solid.faces)
    assert solid.volume == pytest.approx(mesh.volume(), rel=1e-6)     # > 0: outward normals
    assert len(solid.faces) == len(surface_triangles(mesh))


def test_folded_hinge_stl_volume_is_panels_plus_chord_trapezoids(tmp_path):
    _, mesh, result = scene("hinge")
    solid = _trimesh_of(stl_bytes(mesh, result.positions), tmp_path)
    assert solid.is_watertight and solid.is_winding_consistent
    _check_closed_and_oriented(solid.faces)
    hinges = mesh.groups["bending_hinge"]
    phi = np.radians(np.abs(result.strip_angles_deg))
    # a strip's planar-faced prism: cross-section ℓ·H·sin(φ)/φ for a neutral axis ℓ
    # (the axis hinge shortens it to ℓ < w as it bends, the arc keeps ℓ = w)
    shorter = neutral_lengths(hinges.params, phi) / hinges.params[:, 0]
    expected = mesh.groups["rigid_panel"].volumes.sum() + (hinges.volumes * shorter * np.sinc(
        phi / np.pi)).sum()
    assert solid.volume == pytest.approx(expected, rel=1e-6)


def test_folded_vertex_stl_keeps_the_panel_volume(tmp_path):
    from foldcore.render import strip_bend_angles

    _, mesh, result = scene("d4")
    solid = _trimesh_of(stl_bytes(mesh, result.positions), tmp_path)
    assert solid.is_watertight and solid.is_winding_consistent
    _check_closed_and_oriented(solid.faces)
    panels = mesh.groups["rigid_panel"].volumes.sum()
    strips = mesh.groups["bending_hinge"]
    phi = np.radians(np.abs(strip_bend_angles(mesh, result.positions)))
    shortest = (neutral_lengths(strips.params, phi) / strips.params[:, 0]).min()  # axis hinges
    tol = 1e-6 * mesh.volume()
    assert panels + strips.volumes.sum() * shortest * np.sinc(phi.max() / np.pi) - tol \
        <= solid.volume <= mesh.volume() + tol


def test_stl_header_is_binary_and_refuses_bad_positions():
    _, mesh, _ = scene("hinge")
    data = stl_bytes(mesh)
    n = int(np.frombuffer(data[80:84], "<u4")[0])
    assert len(data) == 84 + 50 * n and not data.startswith(b"solid")
    with pytest.raises(ExportError, match="positions"):
        stl_bytes(mesh, np.zeros((3, 3)))


def test_triangulation_of_a_non_convex_polygon_with_collinear_points():
    # an L shape, with extra points on two sides (as panels get strip corners)
    xy = np.array([[0, 0], [1, 0], [2, 0], [2, 1], [1, 1], [1, 2], [1, 3], [0, 3], [0, 1.5]],
                  dtype=float)
    for poly in (xy, xy[::-1]):
        tris = triangulate_polygon(poly)
        assert tris.shape == (len(poly) - 2, 3)
        areas = [_area(poly[t]) for t in tris]
        sign = np.sign(_area(poly))
        assert all(sign * a > 1e-12 for a in areas)                 # no slivers, one winding
        assert sum(areas) == pytest.approx(_area(poly))


# ------------------------------------------------------------------ outlines
def test_outlines_cover_the_sheet_with_a_hole_at_the_vertex():
    _, mesh, _ = scene("d4")
    out = sheet_outlines(mesh)
    assert len(out["PANEL"]) == 4 and len(out["HINGE"]) == 4
    areas = [_area(p) for p in out["CUT"]]
    assert sum(a > 0 for a in areas) == 1 and sum(a < 0 for a in areas) == 1  # sheet + hole
    footprint = (mesh.groups["rigid_panel"].volumes.sum() +
                 mesh.groups["bending_hinge"].volumes.sum()) / mesh.thickness
    assert sum(areas) == pytest.approx(footprint, rel=1e-9)
    assert sum(_area(p) for p in out["PANEL"]) == pytest.approx(
        mesh.groups["rigid_panel"].volumes.sum() / mesh.thickness, rel=1e-9)
    assert sum(_area(p) for p in out["HINGE"]) == pytest.approx(
        mesh.groups["bending_hinge"].volumes.sum() / mesh.thickness, rel=1e-9)
    for loops in out.values():
        for p in loops:
            assert len(p) >= 3 and not np.allclose(p[0], p[-1])    # closed, not repeated


def _svg_polygons(path):
    root = ET.parse(path).getroot()
    assert root.tag == f"{SVG_NS}svg"
    assert root.get("width").endswith("mm") and root.get("height").endswith("mm")
    x0, y0, w, h = map(float, root.get("viewBox").split())
    assert float(root.get("width")[:-2]) == pytest.approx(w)      # 1 user unit = 1 mm
    layers = {}
    for group in root.iter(f"{SVG_NS}g"):
        polys = []
        for poly in group.iter(f"{SVG_NS}polygon"):
            pts = np.array([[float(v) for v in pair.split(",")]
                            for pair in poly.get("points").split()])
            assert ((pts >= [x0, y0]) & (pts <= [x0 + w, y0 + h])).all()
            polys.append(pts * [1, -1])                              # back to y up
        layers[group.get("id").upper()] = polys
    # only polygons (closed by definition): no open polylines or paths
    assert not list(root.iter(f"{SVG_NS}polyline")) and not list(root.iter(f"{SVG_NS}path"))
    return layers


def _dxf_polylines(path):
    ezdxf = pytest.importorskip("ezdxf")
    doc = ezdxf.readfile(path)
    assert doc.header["$INSUNITS"] == 4                              # millimetres
    layers = {}
    for e in doc.modelspace():
        assert e.dxftype() == "LWPOLYLINE" and e.closed
        layers.setdefault(e.dxf.layer, []).append(np.array(e.get_points("xy")))
    return layers


def test_cli_export_writes_svg_dxf_stl_read_back_independently(result_fold, tmp_path):
    svg, dxf, stl = (tmp_path / f"sheet.{s}" for s in ("svg", "dxf", "stl"))
    assert main(["export", str(result_fold), "--svg", str(svg), "--dxf", str(dxf),
                 "--stl", str(stl)]) == 0
    pattern, mesh, result = scene("d4")
    expected = sheet_outlines(mesh, pattern)
    from_svg, from_dxf = _svg_polygons(svg), _dxf_polylines(dxf)
    assert set(from_svg) == set(from_dxf) == set(expected)
    for layer, loops in expected.items():
        assert len(from_svg[layer]) == len(from_dxf[layer]) == len(loops), layer
        for want, got_svg, got_dxf in zip(loops, from_svg[layer], from_dxf[layer]):
            assert got_svg == pytest.approx(want, abs=1e-6)
            assert got_dxf == pytest.approx(want, abs=1e-9)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["d4.fold", "sheet.dxf", "sheet.stl",
                                                          "sheet.svg"]     # no temp files
    solid = _trimesh_of(stl.read_bytes(), tmp_path)
    assert solid.is_watertight
    assert solid.bounds == pytest.approx(np.array([result.positions.min(axis=0),
                                                   result.positions.max(axis=0)]), abs=1e-5)


def test_hinges_are_on_mountain_and_valley_layers_in_origami_simulators_colours(
        result_fold, tmp_path):
    """Red means mountain, as in Origami Simulator (the cut outline is black); M and V
    strips are on layers of their own; the stroke width follows the sheet's size."""
    import xml.etree.ElementTree as ET

    pattern, mesh, _ = scene("d4")
    outlines = sheet_outlines(mesh, pattern)
    kinds = {str(pattern.assignments[e]) for e in mesh.strips_of_crease}
    assert {k for k in kinds if k in "MV"} == {"M", "V"}
    counts = {k: sum(pattern.assignments[e] == k for e in mesh.strips_of_crease) for k in kinds}
    assert len(outlines["HINGE_M"]) == counts["M"] and len(outlines["HINGE_V"]) == counts["V"]
    assert len(sheet_outlines(mesh)["HINGE"]) == len(mesh.strips_of_crease)  # no pattern
    svg = tmp_path / "s.svg"
    assert main(["export", str(result_fold), "--svg", str(svg)]) == 0
    root = ET.parse(svg).getroot()
    groups = {g.get("id"): g for g in root.iter("{http://www.w3.org/2000/svg}g")}
    colours = {k: g.get("stroke") for k, g in groups.items()}
    assert colours["cut"] == "#000000" and colours["hinge_m"] == "#ff0000"
    assert colours["hinge_v"] == "#0000ff"
    every = np.vstack([p for loops in outlines.values() for p in loops])
    extent = float(np.ptp(every, axis=0).max())
    assert float(groups["cut"].get("stroke-width")) == pytest.approx(
        min(0.1, 1e-3 * extent), rel=1e-5)
    assert main(["export", str(result_fold), "--svg", str(svg), "--stroke-width", "0.02",
                 "--margin", "5"]) == 0
    root = ET.parse(svg).getroot()
    assert {g.get("stroke-width") for g in root.iter("{http://www.w3.org/2000/svg}g")} \
        == {"0.02"}
    width = float(root.get("width").removesuffix("mm"))
    assert width == pytest.approx(np.ptp(every[:, 0]) + 10.0, abs=1e-5)


def test_cli_export_any_subset(result_fold, tmp_path):
    stl = tmp_path / "only.stl"
    assert main(["export", str(result_fold), "--stl", str(stl)]) == 0
    assert sorted(p.name for p in tmp_path.iterdir()) == ["d4.fold", "only.stl"]


def test_read_result_finds_explicit_subdivisions(tmp_path):
    """simulate --subdivisions 4 leaves no trace in the file; the frame's faces tell."""
    from foldcore.outputs import write_result

    pattern, mesh, result = scene("hinge")        # k = 4, auto would be 2
    path = tmp_path / "hinge.fold"
    write_result(result, pattern, mesh, 1.0, {}, fold=path)
    res = read_result(path)
    assert res.mesh.subdivisions.tolist() == mesh.subdivisions.tolist()
    assert res.positions == pytest.approx(result.positions, abs=1e-12)
    assert res.footprint_misfit_mm < 1e-9


def test_a_result_with_elastic_panels_reads_back_and_exports(tmp_path, capsys):
    """foldcore:faces_cells carries the cell counts, so the bar, plate and ring cells
    are rebuilt (same mesh, same positions) and the folded solid exports watertight; a
    malformed entry is refused naming the face, exit code 2 from the CLI."""
    from foldcore.outputs import write_result
    from foldcore.simulation import Simulation
    from foldcore.thickening import thicken

    pattern = patterns.single_hinge(panel_length=20.0, depth=20.0, angle=60.0, width=2.0)
    for elastic in ({1: 3}, {0: (3, 2), 1: (4, 3)}, {0: ("rings", 2), 1: ("rings", 3)}):
        mesh = thicken(pattern, 1.0, subdivisions=2, elastic=elastic)
        result = Simulation(mesh, pattern).run(tolerance=1e-9, max_iterations=2_000)
        path = tmp_path / "plate.fold"
        write_result(result, pattern, mesh, 1.0, {}, fold=path)
        back = read_result(path)
        assert back.mesh.elastic == elastic
        assert back.mesh.n_vertices == mesh.n_vertices
        assert back.positions == pytest.approx(result.positions, abs=1e-12)
    stl = tmp_path / "plate.stl"
    assert main(["export", str(path), "--stl", str(stl)]) == 0 and stl.exists()
    edited = json.loads(path.read_text())
    edited["foldcore:faces_cells"][1] = [4, 0]
    bad = tmp_path / "bad.fold"
    bad.write_text(json.dumps(edited))
    assert main(["export", str(bad), "--stl", str(tmp_path / "bad.stl")]) == 2
    err = capsys.readouterr().err
    assert "bad.fold" in err and "foldcore:faces_cells[1] (face 1)" in err
    assert not (tmp_path / "bad.stl").exists()


def test_a_result_with_stretch_hinges_reads_back(tmp_path):
    """foldcore:edges_poisson carries the stretch hinges: rebuilt and re-read (a stretch
    strip's width is set by its ratio, so the file's faces alone could not say)."""
    from foldcore.outputs import write_result
    from foldcore.simulation import Simulation
    from foldcore.thickening import thicken

    pattern = patterns.single_hinge(panel_length=10.0, depth=10.0, width=2.0)
    mesh = thicken(pattern, 1.0, stretch={0: 0.3}, stiffness={"panel": 0.1})
    sim = Simulation(mesh, pattern)
    sim.set_stretch_ratios({0: 1.2})
    result = sim.run(tolerance=1e-9, max_iterations=2_000)
    path = tmp_path / "stretch.fold"
    write_result(result, pattern, mesh, 1.0, {}, fold=path)
    back = read_result(path)
    assert list(back.mesh.groups) == list(mesh.groups)
    assert back.mesh.groups["stretch_hinge"].params[0, 3] == pytest.approx(0.3)
    assert back.positions == pytest.approx(result.positions, abs=1e-12)
    edited = json.loads(path.read_text())
    edited["foldcore:edges_poisson"][0] = 0.7
    bad = tmp_path / "bad.fold"
    bad.write_text(json.dumps(edited))
    with pytest.raises(PatternError, match=r"foldcore:edges_poisson\[0\] \(edge 0\)"):
        read_result(bad)


def _bad_export_inputs(result_fold, tmp_path):
    from foldcore.io import write_fold

    plain = tmp_path / "plain.fold"
    write_fold(plain, scene("d4")[0], thickness=1.0)
    edited = json.loads(result_fold.read_text())
    edited["file_frames"][0]["vertices_coords"] = edited["file_frames"][0]["vertices_coords"][:-1]
    short = tmp_path / "short.fold"
    short.write_text(json.dumps(edited))
    data = json.loads(result_fold.read_text())
    del data["foldcore:thickness"]  # kills tools/mutation.py's "no-thickness" mutant
    no_thickness = tmp_path / "no_thickness.fold"
    no_thickness.write_text(json.dumps(data))
    variants = {}
    for name, edit in (("huge", lambda f: f["vertices_coords"][3].__setitem__(0, 1e308)),
                       ("classes", lambda f: f.__setitem__("frame_classes", 5)),
                       ("unit", lambda f: f.__setitem__("frame_unit", ["mm"]))):
        data = json.loads(result_fold.read_text())  # folded frames to refuse
        edit(data["file_frames"][0])
        variants[name] = tmp_path / f"{name}.fold"
        variants[name].write_text(json.dumps(data))
    svg, stl = str(tmp_path / "o.svg"), str(tmp_path / "o.stl")
    fold = str(result_fold)
    return {
        "coordinate 1e308": (["export", str(variants["huge"]), "--svg", svg], "vertex 3"),
        "frame_classes not a list": (["export", str(variants["classes"]), "--stl", stl],
                                     "frame_classes"),
        "frame_unit a list": (["export", str(variants["unit"]), "--stl", stl], "frame_unit"),
        "no thickness": (["export", str(no_thickness), "--stl", stl], "thickness"),
        "nothing asked": (["export", fold], "nothing to export"),
        "missing file": (["export", str(tmp_path / "nope.fold"), "--stl", stl], "nope.fold"),
        "not a result": (["export", str(plain), "--stl", stl], "no folded frame"),
        "frame mismatch": (["export", str(short), "--stl", stl], "short.fold"),
        "wrong width": (["export", fold, "--svg", svg, "--hinge-width", "3"], "--hinge-width"),
        "wrong subdivisions": (["export", fold, "--stl", stl, "--subdivisions", "3"],
                               "--subdivisions"),
        "no folder": (["export", fold, "--stl", str(tmp_path / "no" / "o.stl")],
                      "no such folder"),
        "bad width": (["export", fold, "--stl", stl, "--hinge-width", "-1"], "--hinge-width"),
    }


def test_cli_export_bad_input_exits_2_with_one_line_and_no_file(result_fold, tmp_path,
                                                                capsys):
    cases = _bad_export_inputs(result_fold, tmp_path)
    for what, (argv, needle) in cases.items():
        before = set(tmp_path.iterdir())
        assert main(argv) == 2, what
        err = capsys.readouterr().err
        assert err.count("\n") == 1 and err.startswith("foldcore: error: "), (what, err)
        assert needle in err and "Traceback" not in err, (what, err)
        assert set(tmp_path.iterdir()) == before, what


def test_missing_ezdxf_fails_before_any_file_is_written(result_fold, tmp_path, monkeypatch,
                                                       capsys):
    monkeypatch.setitem(sys.modules, "ezdxf", None)          # as if not installed
    svg, dxf = tmp_path / "a.svg", tmp_path / "a.dxf"
    assert main(["export", str(result_fold), "--svg", str(svg), "--dxf", str(dxf)]) == 2
    assert "ezdxf" in capsys.readouterr().err
    assert not svg.exists() and not dxf.exists()


def test_atomic_path_leaves_nothing_on_error(tmp_path):
    target = tmp_path / "x.stl"
    with pytest.raises(RuntimeError):
        with atomic_path(target) as tmp:
            open(tmp, "wb").write(b"half")
            raise RuntimeError("writer failed")
    assert list(tmp_path.iterdir()) == []
    with atomic_path(target) as tmp:
        assert tmp.endswith(".stl")
        open(tmp, "wb").write(b"whole")
    assert target.read_bytes() == b"whole" and len(list(tmp_path.iterdir())) == 1


def test_stretch_hinges_join_the_sheet_and_bars_have_no_surface(tmp_path):
    """A stretch strip is part of the sheet (one CUT outline of the whole area, one
    HINGE outline); a 2-vertex element (examples/plugin_bar) adds no faces."""
    import dataclasses

    from foldcore.mesh import surface_polygons
    from foldcore.thickening import thicken

    pattern = patterns.single_hinge(panel_length=10.0, depth=10.0, width=2.0)
    mesh = thicken(pattern, 1.0, stretch={0: 0.3})
    outlines = sheet_outlines(mesh)
    assert len(outlines["CUT"]) == 1 and len(outlines["HINGE"]) == 1
    assert _area(outlines["CUT"][0]) == pytest.approx(pattern.area(), rel=1e-12)
    surf = surface_polygons(mesh)
    assert surf.is_hinge.sum() > 0 and set(surf.group[surf.is_hinge]) == {"stretch_hinge"}
    sys.path.insert(0, str(Path(__file__).parent.parent / "examples" / "plugin_bar"))
    from bar import bar_group

    with_bar = dataclasses.replace(mesh, groups={**mesh.groups,
                                                 "bar": bar_group([[0, 5]], [1.0], [1.0])})
    assert stl_bytes(with_bar, with_bar.rest_positions) == stl_bytes(mesh, mesh.rest_positions)


def test_export_checks_every_destination_before_writing(result_fold, tmp_path):
    svg = tmp_path / "ok.svg"
    assert main(["export", str(result_fold), "--svg", str(svg),
                 "--stl", str(tmp_path / "missing" / "x.stl")]) == 2
    assert not svg.exists()


def test_a_pattern_given_for_a_result_is_asked_for_a_result_fold(tmp_path, capsys):
    """``foldcore export pattern.svg``: not 'not valid JSON', but what to give."""
    from foldcore.cli import main

    svg = tmp_path / "p.svg"
    svg.write_text('<svg xmlns="http://www.w3.org/2000/svg"/>')
    for command in (["export", str(svg), "--stl", str(tmp_path / "x.stl")],
                    ["view", str(svg), "-o", str(tmp_path / "x.html")]):
        assert main(command) == 2
        (line,) = capsys.readouterr().err.splitlines()
        assert "not a result FOLD file" in line and "simulate PATTERN -o" in line, line
    assert not (tmp_path / "x.stl").exists() and not (tmp_path / "x.html").exists()


# ------------------------------------------------------------------ thin sheets
def test_a_thin_sheets_result_exports_its_lines_and_its_folded_triangles(tmp_path):
    """A square cut in two flaps folded opposite ways with no thickness: the SVG and DXF
    hold each edge once as an open line in its layer (the cut's two sides drawn once),
    the STL the folded triangles at the result's positions, area kept."""
    flaps = tmp_path / "flaps.fold"
    flaps.write_text(json.dumps({
        "file_spec": 1.1, "frame_unit": "mm",
        "vertices_coords": [[0, 0], [50, 0], [100, 0], [100, 50], [100, 100], [0, 100],
                            [0, 50], [50, 50]],
        "edges_vertices": [[0, 1], [1, 2], [2, 3], [3, 4], [4, 5], [5, 6], [6, 0], [6, 7],
                           [7, 3], [1, 7]],
        "edges_assignment": ["B"] * 7 + ["V", "M", "C"],
        "edges_foldAngle": [None] * 7 + [90, -90, None]}))
    result = tmp_path / "flaps-out.fold"
    assert main(["simulate", str(flaps), "-o", str(result), "-q"]) == 0
    svg, dxf, stl = tmp_path / "f.svg", tmp_path / "f.dxf", tmp_path / "f.stl"
    assert main(["export", str(result), "--svg", str(svg), "--dxf", str(dxf),
                 "--stl", str(stl)]) == 0
    layers = {g.get("id"): g for g in ET.parse(svg).getroot().iter(f"{SVG_NS}g")}
    lines = {k: len(g.findall(f"{SVG_NS}polyline")) for k, g in layers.items()}
    assert lines == {"cut": 8, "hinge_m": 1, "hinge_v": 1}  # 7 border edges + the cut
    ezdxf = pytest.importorskip("ezdxf")
    polylines = ezdxf.readfile(str(dxf)).modelspace().query("LWPOLYLINE")
    assert len(polylines) == 10 and not any(p.closed for p in polylines)
    res = read_result(result, thin=True)
    solid = _trimesh_of(stl.read_bytes(), tmp_path)
    assert solid.area == pytest.approx(100.0 * 100.0, rel=1e-6)
    assert len(stl.read_bytes()) == 84 + 50 * len(res.triangles)
    lowest = float(np.asarray(res.frames[-1].positions)[:, 2].min())
    assert solid.bounds[0, 2] == pytest.approx(lowest, abs=1e-4)
