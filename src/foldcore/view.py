"""``foldcore view RESULT.fold -o view.html``: a self-contained interactive page.

One HTML file, no network and no server: three.js (vendored from its npm
package, ``viewer_assets/README.md``) and the geometry are inlined, the
library through an import map of ``data:`` URLs. The page draws the folded
thick solid with orbit controls, a slider over the file's folded frames (a
``simulate --series`` file has one per fold percent; a ``simulate -o`` result
has one) and three colourings: mountain/valley (Origami Simulator's red/blue,
panels grey, facet yellow, undriven magenta), each crease's achieved fold
angle (valley blue, mountain red), and each hinge sub-strip's larger surface
strain (dark to yellow, 0 to the largest over the frames; as ``foldcore render
--color-by strain``). ``#frame=K&colour=angle`` in the URL
chooses the first view (used by the tests). Geometry: the outer surface of
the thick mesh rebuilt from the file (:func:`foldcore.result_file.read_result`),
float32 positions per frame, base64-encoded.
"""
from __future__ import annotations

import base64
import json
import os
from pathlib import Path

import numpy as np

ASSETS = Path(__file__).parent / "viewer_assets"
#: Triangle kinds of the page: panel, then the crease assignments.
KINDS = {"M": 1, "V": 2, "F": 3}  # anything else on a hinge: 4 (undriven)


def view_html(path, output) -> None:
    """Write the viewer page of the result file ``path`` to ``output`` (atomically).

    Raises
    ------
    PatternError
        ``path`` is not a result file foldcore can rebuild, or a folded frame does
        not match the rebuilt mesh.
    """
    from .files import write_text
    from .io.fold import read_bytes
    from .mesh import surface_polygons
    from .result_file import read_result
    from .surface import surface_triangles

    source = os.fspath(path)
    res = read_result(source)
    d = json.loads(read_bytes(source))
    surface = surface_polygons(res.mesh)
    triangles, face = surface_triangles(res.mesh, surface, return_faces=True, source=source)
    crease = np.where(surface.is_hinge[face], surface.source[face], -1).astype(np.int32)
    kind = np.zeros(len(triangles), dtype=np.uint8)
    hinge = crease >= 0
    kind[hinge] = [KINDS.get(str(res.pattern.assignments[e]), 4) for e in crease[hinge]]
    bending = surface.group[face] == "bending_hinge"
    strip = np.where(bending, surface.element[face], -1).astype(np.int32)
    frames = _frames(d, res.mesh.n_vertices, source)
    for frame, xyz in frames:
        frame["strain"] = _b64(_strip_strains(res.mesh, xyz).astype("<f4"))
    data = {"triangles": _b64(triangles.astype("<u4")), "kind": _b64(kind),
            "crease": _b64(crease.astype("<i4")), "strip": _b64(strip),
            "frames": [frame for frame, _ in frames]}
    page = (ASSETS / "view.html").read_text()
    page = page.replace("__TITLE__", f"foldcore: {Path(source).name}")
    page = page.replace("__IMPORTMAP__", json.dumps({"imports": {
        "three": _module_url("three.module.min.js"),
        "three/addons/controls/OrbitControls.js": _module_url("OrbitControls.js")}}))
    page = page.replace("__DATA__", json.dumps(data))
    write_text(output, page)


def _strip_strains(mesh, positions: np.ndarray) -> np.ndarray:
    """(S,) each bending sub-strip's larger surface tension strain at ``positions``
    (as ``foldcore render --color-by strain``; dimensionless)."""
    from .strain import estimated_strip_angles, strip_strains

    hinges = mesh.groups.get("bending_hinge")
    if hinges is None or not len(hinges):
        return np.zeros(0)
    return strip_strains(hinges.params, estimated_strip_angles(hinges, positions)).max(axis=1)


def _frames(d: dict, n_vertices: int, source: str) -> list:
    """Every folded frame of the file with the mesh's vertex count, in order, as (page
    entry, positions): title, (N·3) float32 positions (base64) and per key-frame edge
    achieved angles; positions (N, 3) mm."""
    from .errors import PatternError
    from .outputs import SERIES_ANGLE_KEY

    out = []
    for i, f in enumerate(d.get("file_frames") or []):
        if not isinstance(f, dict) or "foldedForm" not in (f.get("frame_classes") or []):
            continue
        xyz = np.asarray(f.get("vertices_coords"), dtype=np.float64)
        if xyz.shape != (n_vertices, 3):
            raise PatternError(f"{source}: file_frames[{i}] has {len(xyz)} vertices, the "
                               f"rebuilt thick mesh {n_vertices}")
        angles = f.get(SERIES_ANGLE_KEY, d.get("edges_foldAngle"))
        out.append(({"title": str(f.get("frame_title", f"frame {i}")),
                     "xyz": _b64(xyz.astype("<f4")), "angles": angles}, xyz))
    return out


def _b64(array: np.ndarray) -> str:
    return base64.b64encode(np.ascontiguousarray(array).tobytes()).decode("ascii")


def _module_url(name: str) -> str:
    text = (ASSETS / name).read_bytes()
    return "data:text/javascript;base64," + base64.b64encode(text).decode("ascii")
