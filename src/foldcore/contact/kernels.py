"""numba kernels of the parts' broad phase (:class:`~.solids.PartSolids`).

A part is a run ``vertices[ptr[p]:ptr[p + 1]]`` of model vertex ids: a panel's
top loop first, the bottom loop after it; a hinge strip's top vertices, then
its bottom's (the "normal" its first half gives is then some axis, and any
axis gives a valid bound). Each kernel walks those runs in place:
no gathered copies of the positions, no temporaries per pair (the numpy
version of the separating-axis bound built some twenty arrays per call and
cost a tenth of a rigid step on a Miura 40 × 40). Units: mm.
"""
from __future__ import annotations

import math
from pathlib import Path

import numpy as np
from numba import njit

from elements.cache import choose_cache_dir

choose_cache_dir(Path(__file__))  # before this module's cache=True kernels (read-only installs)

USABLE_AXIS = 1e-6  # an axis shorter than this (mm, or a unit normals' sum) is left out


@njit(cache=True)
def boxes(x, vertices, ptr, lo, hi):
    """Each panel's axis-aligned box at positions x (N, 3) into lo, hi (n_panels, 3)."""
    for p in range(len(ptr) - 1):
        for k in range(3):
            lo[p, k], hi[p, k] = math.inf, -math.inf
        for i in range(ptr[p], ptr[p + 1]):
            v = vertices[i]
            for k in range(3):
                lo[p, k] = min(lo[p, k], x[v, k])
                hi[p, k] = max(hi[p, k], x[v, k])


@njit(cache=True, inline="always")
def _frame(x, vertices, start, stop):
    """(unit normal, centroid) of the panel whose vertices are ``vertices[start:stop]``:
    Newell's normal of its top loop (about the centroid, which loses fewer digits
    far from the origin), each a 3-tuple."""
    n = stop - start
    cx = cy = cz = 0.0
    for i in range(start, stop):
        v = vertices[i]
        cx += x[v, 0]
        cy += x[v, 1]
        cz += x[v, 2]
    cx, cy, cz = cx / n, cy / n, cz / n
    half = n // 2
    nx = ny = nz = 0.0
    for i in range(half):
        v, w = vertices[start + i], vertices[start + (i + 1) % half]
        ax, ay, az = x[v, 0] - cx, x[v, 1] - cy, x[v, 2] - cz
        bx, by, bz = x[w, 0] - cx, x[w, 1] - cy, x[w, 2] - cz
        nx += ay * bz - az * by
        ny += az * bx - ax * bz
        nz += ax * by - ay * bx
    length = max(math.sqrt(nx * nx + ny * ny + nz * nz), 1e-300)
    return (nx / length, ny / length, nz / length), (cx, cy, cz)


@njit(cache=True, inline="always")
def _span(y, vertices, start, stop, ux, uy, uz):
    """(lo, hi) of the vertices ``vertices[start:stop]`` at y projected on (ux, uy, uz)."""
    lo, hi = math.inf, -math.inf
    for i in range(start, stop):
        v = vertices[i]
        s = y[v, 0] * ux + y[v, 1] * uy + y[v, 2] * uz
        lo, hi = min(lo, s), max(hi, s)
    return lo, hi


@njit(cache=True, inline="always")
def _gap_along(x, later, moving, vertices, a0, a1, b0, b1, axis):
    """The gap between two panels' vertex intervals along ``axis`` (a 3-tuple,
    normalised here), mm; −inf where the axis is shorter than ``USABLE_AXIS``.

    When ``moving``, a bound over the straight-line motion x → ``later``: b's
    lowest point less a's highest is concave in the motion's parameter (a
    minimum of linear functions less a maximum), so the smaller of its end
    values bounds it, and the same for a over b; the larger of those two is
    the bound. (The smaller of the two ends' gaps is not one: a panel that
    passes through the other in one step is apart at both ends.)"""
    length = math.sqrt(axis[0] * axis[0] + axis[1] * axis[1] + axis[2] * axis[2])
    if not length > USABLE_AXIS:
        return -math.inf
    ux, uy, uz = axis[0] / length, axis[1] / length, axis[2] / length
    b_over_a = a_over_b = math.inf
    for j in range(2 if moving else 1):
        y = later if j else x
        lo_a, hi_a = _span(y, vertices, a0, a1, ux, uy, uz)
        lo_b, hi_b = _span(y, vertices, b0, b1, ux, uy, uz)
        b_over_a, a_over_b = min(b_over_a, lo_b - hi_a), min(a_over_b, lo_a - hi_b)
    return max(b_over_a, a_over_b)


@njit(cache=True)
def gap_bounds(x, later, moving, vertices, ptr, pairs, edges, out):
    """Each pair's separating-axis lower bound of its distance into out (K,), mm.

    Parameters
    ----------
    x, later : (N, 3) float
        Positions, mm; ``later`` is read only when ``moving`` (the bound then
        holds for the whole straight-line motion x → later).
    moving : bool
    vertices, ptr : (n,) int64, (n_panels + 1,) int64
        The panels' vertex runs.
    pairs : (K, 2) int64
        Panel pairs (a, b).
    edges : (K, 2) int64 or (0, 2) int64
        Model vertex ids of an edge per pair (joined pairs: its crease's edge),
        whose in-plane normals are two more axes; none when empty.
    out : (K,) float
        The widest gap along the axes n_a, n_b, n_a + n_b, n_a − n_b, c_b − c_a
        (and n_a × e, n_b × e): ≤ 0 where not proved apart.
    """
    with_edges = len(edges) > 0
    for k in range(len(pairs)):
        a, b = pairs[k, 0], pairs[k, 1]
        a0, a1, b0, b1 = ptr[a], ptr[a + 1], ptr[b], ptr[b + 1]
        na, ca = _frame(x, vertices, a0, a1)
        nb, cb = _frame(x, vertices, b0, b1)
        best = -math.inf
        for axis in ((na[0], na[1], na[2]), (nb[0], nb[1], nb[2]),
                     (na[0] + nb[0], na[1] + nb[1], na[2] + nb[2]),
                     (na[0] - nb[0], na[1] - nb[1], na[2] - nb[2]),
                     (cb[0] - ca[0], cb[1] - ca[1], cb[2] - ca[2])):
            best = max(best, _gap_along(x, later, moving, vertices, a0, a1, b0, b1, axis))
        if with_edges:
            e0, e1 = edges[k, 0], edges[k, 1]
            ex, ey, ez = x[e1, 0] - x[e0, 0], x[e1, 1] - x[e0, 1], x[e1, 2] - x[e0, 2]
            for n in (na, nb):
                axis = (n[1] * ez - n[2] * ey, n[2] * ex - n[0] * ez, n[0] * ey - n[1] * ex)
                best = max(best, _gap_along(x, later, moving, vertices, a0, a1, b0, b1, axis))
        out[k] = best


@njit(cache=True)
def boxes_near(lo, hi, margin, joined):
    """(K, 2) int64 panel pairs (a < b, sorted by a · n_panels + b) whose boxes lo, hi
    (n_panels, 3) come within ``margin`` mm of each other on every axis, less the
    pairs whose code a · n_panels + b is in ``joined`` (sorted).

    Sweep and prune: the boxes sorted by their low end along the axis their
    centres spread widest on; each box is compared only with the boxes that
    start before it ends there."""
    n = len(lo)
    spread, axis = -1.0, 0
    for k in range(3):
        centres = lo[:, k] + hi[:, k]
        if centres.max() - centres.min() > spread:
            spread, axis = centres.max() - centres.min(), k
    order = np.argsort(lo[:, axis])
    codes = []
    for i in range(n):
        p = order[i]
        end = hi[p, axis] + margin
        for j in range(i + 1, n):
            q = order[j]
            if lo[q, axis] > end:
                break
            if (lo[q, 0] > hi[p, 0] + margin or lo[p, 0] > hi[q, 0] + margin
                    or lo[q, 1] > hi[p, 1] + margin or lo[p, 1] > hi[q, 1] + margin
                    or lo[q, 2] > hi[p, 2] + margin or lo[p, 2] > hi[q, 2] + margin):
                continue
            code = min(p, q) * n + max(p, q)
            m = np.searchsorted(joined, code)
            if m < len(joined) and joined[m] == code:
                continue
            codes.append(code)
    found = np.sort(np.array(codes, dtype=np.int64))
    out = np.empty((len(found), 2), dtype=np.int64)
    out[:, 0] = found // n
    out[:, 1] = found % n
    return out


def compile_all() -> None:
    """Call every kernel once on two unit cubes 1 mm apart, so numba compiles and
    caches each (:mod:`foldcore.warmup`, where contact is installed): a first run
    with contact would wait several seconds for them."""
    square = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])
    cube = np.vstack([np.column_stack([square, np.ones(4)]), np.column_stack([square, np.zeros(4)])])
    x = np.vstack([cube, cube + [2.0, 0.0, 0.0]])
    vertices, ptr = np.arange(16, dtype=np.int64), np.array([0, 8, 16], dtype=np.int64)
    lo, hi = np.empty((2, 3)), np.empty((2, 3))
    boxes(x, vertices, ptr, lo, hi)
    pairs = boxes_near(lo, hi, 1.0, np.zeros(0, dtype=np.int64))
    gap_bounds(x, x, False, vertices, ptr, pairs, np.array([[1, 2]], dtype=np.int64),
               np.empty(len(pairs)))
