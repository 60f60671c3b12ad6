"""Hinge widths (mm), hinge models and sub-strip counts per edge."""
from __future__ import annotations

import numpy as np

from ..errors import MeshError
from ..hinges import DEFAULT_HINGE, HINGE_MODELS
from ..limits import SUBDIVISIONS

__all__ = ["MAX_NARROWING", "MAX_SUBDIVISIONS", "auto_subdivisions", "automatic_widths",
           "fit_widths", "minimum_hinge_width", "resolve_hinges", "resolve_subdivisions",
           "resolve_widths"]

MAX_SUBDIVISIONS = 16
#: Halvings of an automatic hinge width that fitting it to a small face may take
#: (down to 1/64 of Eq. 7's width).
MAX_NARROWING = 6


def minimum_hinge_width(thickness: float, max_angle_deg, bend_radius: float = 0.0):
    """Eq. 7: hinge width W = (r + H/2)·θmax in mm (θmax given in degrees)."""
    return (bend_radius + 0.5 * thickness) * np.radians(max_angle_deg)


def auto_subdivisions(width, thickness: float, max_angle_deg, hinge=DEFAULT_HINGE) -> np.ndarray:
    """Sub-strips per hinge chosen from its largest fold angle.

    k = max(2, ceil(θmax / 45°)); for Eq. 8 hinges (``hinge="eq8"``, per
    hinge or for all) k is then raised, up to :data:`MAX_SUBDIVISIONS`, while
    θmax/k > 2·atan(W/(k·H)), the most one sub-strip can bend
    (docs/architecture.md#sub-strips-per-hinge).

    Parameters
    ----------
    width : float or (n,) float
        Hinge width W, mm.
    thickness : float
        Sheet thickness H, mm.
    max_angle_deg : float or (n,) float
        Largest fold angle θmax, degrees.
    hinge : str or (n,) str
        Hinge model of each hinge.

    Returns
    -------
    (n,) int64
    """
    width = np.atleast_1d(np.asarray(width, dtype=float))
    theta = np.radians(np.broadcast_to(max_angle_deg, width.shape))
    eq8 = np.broadcast_to(np.asarray(hinge) == "eq8", width.shape)
    k = np.maximum(2, np.ceil(np.degrees(theta) / 45.0 - 1e-9)).astype(np.int64)
    for _ in range(MAX_SUBDIVISIONS):
        short = (theta / k > 2 * np.arctan(width / (k * thickness))) & (k < MAX_SUBDIVISIONS) & eq8
        if not short.any():
            break
        k[short] += 1
    return k


def resolve_widths(pattern, thickness, hinge_width, bend_radius) -> np.ndarray:
    """(E,) hinge width per edge, mm (NaN on boundary edges), validated: ``hinge_width``
    or the pattern's, Eq. 7 where NaN."""
    widths = np.array(pattern.widths, dtype=float)
    if hinge_width is not None:
        widths = np.broadcast_to(np.asarray(hinge_width, dtype=float), widths.shape).copy()
    auto = np.isnan(widths)
    widths[auto] = minimum_hinge_width(thickness, pattern.max_angles[auto], bend_radius)
    widths[pattern.assignments == "B"] = np.nan
    bad = np.flatnonzero(~(widths > 0) & (pattern.assignments != "B"))
    if len(bad):
        raise MeshError(f"{pattern.source}: edge {bad[0]}: hinge width must be > 0 mm")
    return widths


def automatic_widths(pattern, hinge_width) -> np.ndarray:
    """(E,) bool: the creases whose width is Eq. 7's (neither ``hinge_width`` nor the
    pattern gives one)."""
    given = np.array(pattern.widths, dtype=float) if hinge_width is None else \
        np.broadcast_to(np.asarray(hinge_width, dtype=float), (pattern.n_edges,))
    return np.isnan(given) & (pattern.assignments != "B")


def fit_widths(pattern, widths, automatic) -> np.ndarray:
    """(E,) share of its width each crease keeps: the ``automatic`` widths (Eq. 7's,
    :func:`automatic_widths`) in the way halved, at most :data:`MAX_NARROWING` times,
    until every face's panel survives its inset (:func:`.panels.inset_faces`) and
    every crease keeps a strip (:func:`.strips.short_creases`). In the way: the sides
    of a face too small, the creases at either end of a crease too short. A crease
    is narrowed with the creases collinear with it through a vertex
    (:func:`collinear_groups`), so a panel's straight side keeps one inset instead
    of stepping across the vertex (:mod:`.panels`). Widths the
    user gave are kept; a face or crease still too small is refused when the mesh
    is built."""
    from .panels import inset_faces
    from .strips import short_creases

    share = np.ones(len(widths))
    group = collinear_groups(pattern)
    for _ in range(MAX_NARROWING):
        corners, failing, _ = inset_faces(pattern, widths * share)
        around = np.isin(pattern.edge_faces, np.flatnonzero(failing)).any(axis=1)
        if not failing.any():
            ends = np.unique(pattern.edges[short_creases(pattern, corners)])
            around = np.isin(pattern.edges, ends).any(axis=1)
        around &= automatic
        if not around.any():
            break
        share[np.isin(group, group[around]) & automatic] *= 0.5
    return share


def collinear_groups(pattern) -> np.ndarray:
    """(E,) int: edges joined where two consecutive sides of a face run straight on
    through their vertex (one label per joined set)."""
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components

    from ..planar import loop_starts, next_in_loop

    loops = pattern.face_loops
    following = next_in_loop(loop_starts(loops.lengths), loops.lengths)
    side = pattern.side_slots % pattern.n_edges
    before = np.empty_like(following)
    before[following] = np.arange(len(following))   # the side ending at each corner
    xy = pattern.vertices
    d_in = xy[loops.flat] - xy[loops.flat[before]]
    d_out = xy[loops.flat[following]] - xy[loops.flat]
    cross = d_in[:, 0] * d_out[:, 1] - d_in[:, 1] * d_out[:, 0]
    dot = np.einsum("ij,ij->i", d_in, d_out)
    straight = (np.abs(cross) <= 1e-9 * np.abs(dot)) & (dot > 0)
    n = pattern.n_edges
    graph = coo_matrix((np.ones(int(straight.sum())), (side[before][straight], side[straight])),
                       shape=(n, n))
    return connected_components(graph, directed=False)[1]


def resolve_hinges(pattern, hinge) -> np.ndarray:
    """(E,) hinge model name per edge ("" for boundary edges), validated."""
    names = np.broadcast_to(np.asarray(DEFAULT_HINGE if hinge is None else hinge, dtype=object),
                            (pattern.n_edges,)).copy()
    names[[n is None for n in names]] = DEFAULT_HINGE
    bad = [e for e, n in enumerate(names) if n not in HINGE_MODELS]
    if bad:
        raise MeshError(f"{pattern.source}: edge {bad[0]}: unknown hinge model "
                        f"{names[bad[0]]!r} (available: {', '.join(HINGE_MODELS)})")
    names[pattern.assignments == "B"] = ""
    return names.astype(str)


def resolve_subdivisions(pattern, widths, thickness, subdivisions, hinges) -> np.ndarray:
    """(E,) int64 sub-strips per edge (0 on boundary edges): ``subdivisions`` validated,
    or :func:`auto_subdivisions` for ``"auto"`` / None."""
    crease = pattern.assignments != "B"
    if subdivisions is None or (isinstance(subdivisions, str) and subdivisions == "auto"):
        k = np.zeros(pattern.n_edges, dtype=np.int64)
        k[crease] = auto_subdivisions(widths[crease], thickness, pattern.max_angles[crease],
                                      hinges[crease])
        return k
    k = np.broadcast_to(np.asarray(subdivisions), (pattern.n_edges,))
    lo, hi = SUBDIVISIONS
    if not np.issubdtype(k.dtype, np.integer) or ((k[crease] < lo) | (k[crease] > hi)).any():
        raise MeshError(f"{pattern.source}: subdivisions must be integers in {lo}..{hi} or "
                        f"'auto', got {subdivisions!r}")
    return np.where(crease, k, 0).astype(np.int64)
