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
--color-by strain``), each with its legend under the controls (the colours of
the assignments; the angle and strain scales with their ends). ``#frame=K&colour=angle`` in the URL
chooses the first view (used by the tests). Geometry: the outer surface of
the thick mesh rebuilt from the file (:func:`foldcore.result_file.read_result`),
float32 positions per frame, base64-encoded. A thin sheet's result (no
thickness) shows its folded triangles as grey facets with its creases drawn
over them as lines, coloured by assignment or by their angle, or its facets
coloured by strain (each triangle's largest side strain against the flat
sheet, as Origami Simulator colours its strain).

Nothing from the file becomes markup or script: the values are those
``read_result`` checked (types, shapes, ranges), they reach the page only as
JSON in a ``<script type="application/json">`` element, escaped so that no
string can end it (:func:`script_json`), read with ``JSON.parse``; the page
shows text with ``textContent``, and the file's name in ``<title>`` is
HTML-escaped.
"""
from __future__ import annotations

import base64
import html
import json
import os
import re
from pathlib import Path

import numpy as np

ASSETS = Path(__file__).parent / "viewer_assets"
#: Triangle kinds of the page: panel, then the crease assignments.
KINDS = {"M": 1, "V": 2, "F": 3}  # anything else on a hinge: 4 (undriven)


def view_html(path, output) -> None:
    """Write the viewer page of the result file ``path`` to ``output`` (atomically).

    Every value shown comes from :func:`foldcore.result_file.read_result`, which
    checks each folded frame (coordinates finite and within
    ±``MAX_FRAME_COORDINATE_MM`` mm, titles text of at most ``MAX_TITLE_CHARS``
    characters, angles null or within ±180°, one per crease); it reaches the
    page only as JSON escaped for a ``<script>`` element (:func:`script_json`),
    and the page shows text with ``textContent`` only.

    Raises
    ------
    PatternError
        ``path`` is not a result file foldcore can rebuild, or a folded frame is
        malformed, out of range or does not match the rebuilt mesh; nothing is
        written.
    """
    from .files import write_text
    from .mesh import surface_polygons
    from .result_file import SheetResultFile, read_result
    from .surface import surface_triangles

    source = os.fspath(path)
    res = read_result(source, thin=True)
    if isinstance(res, SheetResultFile):
        write_text(output, _page(source, _sheet_data(res)))
        return
    surface = surface_polygons(res.mesh)
    triangles, face = surface_triangles(res.mesh, surface, return_faces=True, source=source)
    crease = np.where(surface.is_hinge[face], surface.source[face], -1).astype(np.int32)
    kind = np.zeros(len(triangles), dtype=np.uint8)
    hinge = crease >= 0
    kind[hinge] = [KINDS.get(str(res.pattern.assignments[e]), 4) for e in crease[hinge]]
    bending = surface.group[face] == "bending_hinge"
    strip = np.where(bending, surface.element[face], -1).astype(np.int32)
    data = {"triangles": _b64(triangles.astype("<u4")), "kind": _b64(kind),
            "crease": _b64(crease.astype("<i4")), "strip": _b64(strip),
            "strain_label": STRAIN_LABELS["thick"],
            "frames": [_page_frame(frame, res.mesh) for frame in res.frames]}
    write_text(output, _page(source, data))


#: What the strain colouring shows, per kind of result (the page's legend).
STRAIN_LABELS = {"thick": "largest surface strain of each hinge sub-strip",
                 "thin": "largest side strain of each facet"}


def _sheet_data(res) -> dict:
    """The page's data of a thin sheet's result: its triangles, all facets (kind 0,
    no crease; each triangle its own ``strip``, coloured by its strain); its
    pattern's edges as lines (``lines``, ``line_kind``: 0 boundary, else as
    :data:`KINDS`, ``line_crease``: the edge, −1 on the boundary) drawn over them;
    per frame its positions, its facets' strains
    (:func:`foldcore.measure.facet_strains`) and its angles."""
    from .measure import facet_strains

    count = len(res.triangles)
    kinds = [str(k) for k in res.pattern.assignments]
    line_kind = np.array([0 if k == "B" else KINDS.get(k, 4) for k in kinds], dtype=np.uint8)
    line_crease = np.where(line_kind > 0, np.arange(len(kinds)), -1).astype("<i4")
    return {"triangles": _b64(res.triangles.astype("<u4")),
            "kind": _b64(np.zeros(count, dtype=np.uint8)),
            "crease": _b64(np.full(count, -1, dtype="<i4")),
            "strip": _b64(np.arange(count, dtype="<i4")), "strain_label": STRAIN_LABELS["thin"],
            "lines": _b64(np.asarray(res.pattern.edges, dtype="<u4")),
            "line_kind": _b64(line_kind), "line_crease": _b64(line_crease),
            "frames": [_frame_entry(frame, facet_strains(res.pattern, res.triangles,
                                                         frame.positions))
                       for frame in res.frames]}


def _page(source: str, data: dict) -> str:
    """The page of ``data`` (:func:`view_html`) from ``viewer_assets/view.html``: its
    placeholders replaced in one pass (a value holding a placeholder's name stays
    as it is), the file's name escaped as HTML text, the rest as :func:`script_json`."""
    name = Path(source).name.encode("utf-8", "replace").decode("utf-8")  # undecodable: ?
    values = {"__TITLE__": html.escape(f"foldcore: {name}"),
              "__IMPORTMAP__": script_json({"imports": {
                  "three": _module_url("three.module.min.js"),
                  "three/addons/controls/OrbitControls.js": _module_url("OrbitControls.js")}}),
              "__DATA__": script_json(data)}
    template = (ASSETS / "view.html").read_text()
    return re.sub("|".join(values), lambda m: values[m.group(0)], template)


#: Characters that could end a ``<script>`` element, open a comment in it, or end a
#: JavaScript line inside a string, and their JSON escapes.
SCRIPT_ESCAPES = {"<": "\\u003c", ">": "\\u003e", "&": "\\u0026", "\u2028": "\\u2028",
                  "\u2029": "\\u2029"}


def script_json(value) -> str:
    """``value`` as JSON text safe inside an HTML ``<script>`` element.

    The same JSON, with ``<``, ``>``, ``&``, U+2028 and U+2029 written as
    ``\\uXXXX`` escapes (they can only occur inside JSON strings), so no value
    can close the element or open markup; NaN and infinities are refused
    (``ValueError``), as JSON has none.
    """
    text = json.dumps(value, allow_nan=False)
    return re.sub("[<>&\u2028\u2029]", lambda m: SCRIPT_ESCAPES[m.group(0)], text)


def _page_frame(frame, mesh) -> dict:
    """The page's entry of one :class:`~foldcore.result_file.FoldedFrame`: title,
    (N·3) float32 positions and (S,) float32 sub-strip strains (base64), and the
    achieved angle per crease (degrees, null where none)."""
    return _frame_entry(frame, _strip_strains(mesh, frame.positions))


def _frame_entry(frame, strains: np.ndarray) -> dict:
    """One frame's entry of the page: title, positions, ``strains`` (S,), angles."""
    return {"title": frame.title, "xyz": _b64(frame.positions.astype("<f4")),
            "strain": _b64(strains.astype("<f4")),
            "angles": [None if np.isnan(a) else float(a) for a in frame.angles.tolist()]}


def _strip_strains(mesh, positions: np.ndarray) -> np.ndarray:
    """(S,) each bending sub-strip's larger surface tension strain at ``positions``
    (as ``foldcore render --color-by strain``; dimensionless)."""
    from .strain import estimated_strip_angles, strip_strains

    hinges = mesh.groups.get("bending_hinge")
    if hinges is None or not len(hinges):
        return np.zeros(0)
    return strip_strains(hinges.params, estimated_strip_angles(hinges, positions)).max(axis=1)


def _b64(array: np.ndarray) -> str:
    return base64.b64encode(np.ascontiguousarray(array).tobytes()).decode("ascii")


def _module_url(name: str) -> str:
    text = (ASSETS / name).read_bytes()
    return "data:text/javascript;base64," + base64.b64encode(text).decode("ascii")
