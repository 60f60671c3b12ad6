"""Element groups of the thick mesh: panel prisms (or their cells), bending-hinge
sub-strips and stretch strips, extruded to thickness H (mid-plane at z = 0)."""
from __future__ import annotations

import numpy as np

from elements.bending_hinge import HINGE_PARAMS
from ..hinges import HINGE_MODELS
from ..mesh import ElementGroup
from .cells import nearest
from .geometry import polygon_area, vector_length

__all__ = ["crease_panels", "hinge_group", "panel_group", "stretch_group"]


def _prism(ids2d, points, thickness):
    """Footprint point ids (m,) and rest coordinates (2m, 3) of one prism: top loop,
    then bottom loop, centred, world frame."""
    ids2d = np.asarray(ids2d, dtype=np.int64)
    return ids2d, _prisms(ids2d[None], points, thickness)[0]


def _prisms(footprints, points, thickness):
    """Rest coordinates (n, 2m, 3) of the prisms on ``footprints`` (n, m) point ids:
    each its top loop (z = +H/2) then its bottom loop, centred, world frame."""
    xy = points[footprints]
    h = np.full(footprints.shape + (1,), 0.5 * thickness)
    xyz = np.concatenate([np.concatenate([xy, h], axis=2), np.concatenate([xy, -h], axis=2)],
                         axis=1)
    return xyz - xyz.mean(axis=1, keepdims=True)


def panel_group(pattern, points, loops, cells, thickness, stiffness):
    """The panel group (whole panels, or the cells of elastic ones) and each face's
    measuring element (the panel, or the cell next to the crease).

    Parameters
    ----------
    pattern : CreasePattern
    points : (N, 2) float
        The sheet's points, mm.
    loops : list
        Footprint point ids of each panel.
    cells : dict
        {face: [cell loops]} of the elastic faces.
    thickness : float
        H, mm.
    stiffness : float or (F,) float
        Stiffness factor per face.

    Returns
    -------
    group : ElementGroup
    panel_of_face : (F,) int64
    """
    prisms, rests, vols, source, panel_of_face = [], [], [], [], []
    n_top = len(points)
    for f, loop in enumerate(loops):
        panel_of_face.append(len(prisms))
        for cell in cells.get(f, [loop]):
            loop2d, rest = _prism(cell, points, thickness)
            prisms.append(np.concatenate([loop2d, loop2d + n_top]))
            rests.append(rest)
            vols.append(polygon_area(points[loop2d]) * thickness)
            source.append(f)
    vols, source = np.array(vols), np.array(source, dtype=np.int64)
    factor = np.broadcast_to(np.asarray(stiffness, dtype=float), (len(loops),))[source]
    return (_group("rigid_panel", prisms, rests, np.zeros((len(prisms), 0)), vols,
                   vols * factor, source), np.array(panel_of_face, dtype=np.int64))


def crease_panels(pattern, points, cells, panel_of_face) -> np.ndarray:
    """(E, 2) the panel elements measuring each crease on its two faces (−1: none):
    the face's panel, or the cell of an elastic face whose footprint centroid is
    nearest the crease's middle (cells of face f are numbered from
    ``panel_of_face[f]`` on, in the order of ``cells[f]``)."""
    faces = pattern.edge_faces
    out = np.where(faces >= 0, panel_of_face[np.maximum(faces, 0)], -1)
    for e in pattern.creases:
        middle = pattern.vertices[pattern.edges[e]].mean(axis=0)
        for side, f in enumerate(faces[e]):
            if f >= 0 and int(f) in cells:
                out[e, side] = panel_of_face[f] + nearest(cells[int(f)], points, middle)
    return out


def hinge_group(pattern, points, strip_points, widths, ks, thickness, hinges, stiffness):
    """The bending-hinge group: k × m sub-strips per crease (m segments along it), and
    each crease's strip ids ({crease: (k·m,) int64}). The footprints are gathered
    a crease at a time, the prisms and parameters built for all strips at once
    (docs/architecture.md#building-the-thick-mesh-fast)."""
    n_top = len(points)
    creases = list(strip_points)
    quads, series, lengths, strips_of, count = [], [], [], {}, 0
    for e in creases:
        k = int(ks[e])
        grid = np.asarray(strip_points[e], dtype=np.int64)  # (k + 1, m + 1): line j, point t
        m = grid.shape[1] - 1  # segments along the crease
        strips_of[e] = np.arange(count, count + k * m, dtype=np.int64)
        count += k * m
        # segment-major: each segment's k strips left → right
        quads.append(np.stack([grid[:-1, :-1].T, grid[1:, :-1].T, grid[1:, 1:].T,
                               grid[:-1, 1:].T], axis=-1).reshape(k * m, 4))
        series.append(np.arange(k * m) % k)  # each strip's place in its series
        # per segment, as before: a vectorised norm sums differently (not bit-identical)
        lengths.append([vector_length(points[b] - points[a])
                        for a, b in zip(grid[0, :-1], grid[0, 1:])])
    if not creases:
        return _group("bending_hinge", [], [], np.zeros((0, len(HINGE_PARAMS))), np.zeros(0),
                      np.zeros(0), np.zeros(0, dtype=np.int64)), strips_of
    quads = np.concatenate(quads)
    rests = _prisms(quads, points, thickness)  # (S, 8, 3), local frames below
    for e in creases:
        rests[strips_of[e]] = rests[strips_of[e]] @ _hinge_frame(pattern, e)
    e_arr = np.array(creases, dtype=np.int64)
    k_arr = ks[e_arr].astype(np.int64)
    per_crease = np.array([len(strips_of[e]) for e in creases])
    src = np.repeat(e_arr, per_crease)
    params = np.repeat(_hinge_params(pattern, e_arr, widths, k_arr, thickness, hinges), per_crease,
                       axis=0)
    params[:, HINGE_PARAMS.index("series")] = np.concatenate(series)
    vols = np.concatenate([np.repeat(widths[e] / ks[e] * np.array(length) * thickness, ks[e])
                           for e, length in zip(creases, lengths)])
    stiff_e = np.broadcast_to(np.asarray(stiffness, dtype=float), (pattern.n_edges,))
    return _group("bending_hinge", list(np.concatenate([quads, quads + n_top], axis=1)),
                  [rests.reshape(-1, 3)], params, vols, vols * stiff_e[src], src), strips_of


def stretch_group(pattern, points, strip_points, stretch, widths, thickness, stiffness):
    """One stretch strip per stretch crease (its whole width), passive (λ = NaN)."""
    from elements.stretch_hinge import STRETCH_PARAMS

    n_top = len(points)
    stiff_e = np.broadcast_to(np.asarray(stiffness, dtype=float), (pattern.n_edges,))
    loops, rests, params, vols = [], [], [], []
    for e, nu in stretch.items():
        (a0, b0), (a1, b1) = strip_points[e][0], strip_points[e][-1]
        loop2d, rest = _prism([a0, a1, b1, b0], points, thickness)
        loops.append(np.concatenate([loop2d, loop2d + n_top]))
        rests.append(rest @ _hinge_frame(pattern, e))
        row = np.zeros(len(STRETCH_PARAMS))
        row[[STRETCH_PARAMS.index(k) for k in ("width", "height", "ratio", "poisson")]] = \
            (widths[e], thickness, np.nan, nu)
        params.append(row)
        vols.append(widths[e] * float(np.linalg.norm(points[b0] - points[a0])) * thickness)
    src = np.array(list(stretch), dtype=np.int64)
    vols = np.array(vols)
    return _group("stretch_hinge", loops, rests, np.array(params), vols, vols * stiff_e[src],
                  src)


def _hinge_frame(pattern, e) -> np.ndarray:
    """(3, 3) columns: local x (across, toward the left face), y (up), z (along a→b).

    x = ẑ × u written out as ``np.cross`` evaluates it, signed zeros included
    (docs/architecture.md#building-the-thick-mesh-fast).
    """
    a, b = pattern.edges[e]
    d = pattern.vertices[b] - pattern.vertices[a]
    ux, uy = d / vector_length(d)
    return np.array([[0.0 * 0.0 - 1.0 * uy, 0.0, ux],
                     [1.0 * ux - 0.0 * 0.0, 0.0, uy],
                     [0.0 * uy - 0.0 * ux, 1.0, 0.0]])


def _hinge_params(pattern, creases, widths, ks, thickness, hinges) -> np.ndarray:
    """(C, len(HINGE_PARAMS)) one sub-strip's parameters per crease (``series`` 0;
    ``floor`` 0, set by Simulation): width W / k, height H, target and max angle per
    sub-strip (rad), M/V sign, hinge model code, k."""
    sign = {"V": 1.0, "M": -1.0, "U": 0.0, "F": 0.0}
    kinds = pattern.assignments[creases]
    target = np.where(kinds == "F", 0.0, pattern.fold_angles[creases])
    p = np.zeros((len(creases), len(HINGE_PARAMS)))
    p[:, HINGE_PARAMS.index("width")] = widths[creases] / ks
    p[:, HINGE_PARAMS.index("height")] = thickness
    p[:, HINGE_PARAMS.index("target")] = np.radians(target) / ks
    p[:, HINGE_PARAMS.index("sign")] = [sign[a] for a in kinds]
    p[:, HINGE_PARAMS.index("max_angle")] = np.radians(pattern.max_angles[creases]) / ks
    p[:, HINGE_PARAMS.index("model")] = [float(HINGE_MODELS.index(h)) for h in hinges[creases]]
    p[:, HINGE_PARAMS.index("strips")] = ks
    return p


def _group(kind, loops, rests, params, volumes, weights, source) -> ElementGroup:
    """An :class:`ElementGroup` from per-element footprint loops and rest coordinates."""
    sizes = np.array([len(x) for x in loops], dtype=np.int64)
    indptr = np.zeros(len(loops) + 1, dtype=np.int64)
    np.cumsum(sizes, out=indptr[1:])
    indices = np.concatenate(loops) if loops else np.zeros(0, np.int64)
    rest = np.vstack(rests) if rests else np.zeros((0, 3))
    return ElementGroup(kind, indptr, indices.astype(np.int64), np.ascontiguousarray(rest),
                        np.ascontiguousarray(params, dtype=np.float64),
                        np.asarray(volumes, dtype=float), np.asarray(weights, dtype=float),
                        source)
