"""numba kernels of the bar-and-hinge sheet: energy, gradient and Hessian.

Three element kinds, each with its analytic gradient. A bar's Hessian is
analytic too; a hinge's and a triangle's are the forward difference of
their gradients (exact to ~1e-8 relative at these sizes, plenty for Newton's
steps, and one code path instead of two hand-derived second derivatives
that are easy to get wrong). Not the bars': their axial stiffness dwarfs the
bending springs (a bar by a facet 1e-3 high has k ≈ 1e4), so a difference's
1e-8 relative error in their blocks is larger than the soft directions'
entries, and Newton's steps along those stall (Origami Simulator's shell14
at 60 %: 500 steps, 25 s, unsettled; with analytic bars 58 steps):

* **bar** ``(a, b)``: ``½ k (L − L₀)²``;
* **hinge** ``(a, b, c, d)``: ``½ k (φ − φ̄)²``, the hinge on ``a → b``, ``c``
  the tip of the triangle left of it, ``d`` of the one right of it; ``φ`` the
  fold angle (radians, valley > 0 for a counter-clockwise sheet seen from +z),
  unwrapped to within π of a reference so a fold past ±180° keeps counting;
* **triangle** ``(a, b, c)``: ``½ k Σ (α − α₀)²`` over its three corner angles,
  plus ``k (s / r − 1)²`` for a corner closed below ``s`` = :data:`SLIVER` of its
  rest angle (``r = α / α₀``): a barrier that keeps a facet from collapsing. A
  crease's force on a facet grows as 1 / its height, so a facet squashed flat
  (heights of 1e-8 … 1e-11) held Newton's damping at μ = 1e8 … 1e10 for the
  rest of the budget; Origami Simulator switches such a crease off instead,
  which makes the energy jump and stops a line search
  (`docs/architecture.md#facets-that-would-collapse`). Facets of a fold that
  keep their shape never meet it.

Units: the sheet's normalised frame (lengths / its bounding radius), angles in
radians. All kernels take positions ``x`` (N, 3).
"""
from __future__ import annotations

import math
from pathlib import Path

import numpy as np
from numba import njit, prange

from elements.cache import choose_cache_dir

choose_cache_dir(Path(__file__))  # before this module's cache=True kernels (read-only installs)

STEP = 1e-8  # forward-difference step of the Hessians × the element's size (√ε: ~1e-8 relative)
#: A triangle lower than this (normalised units) has collapsed: Origami Simulator's
#: tolerance, below which it disables a crease; the smallest element size a step scales to.
COLLAPSED = 1e-6
#: A corner closed below this share of its rest angle is a sliver: the barrier
#: k (SLIVER / r − 1)², r = α / α₀, keeps its triangle from collapsing.
SLIVER = 0.1


@njit(cache=True, inline="always")
def _vec(p, i, j):
    """p[i] − p[j] as a 3-tuple (no allocation)."""
    return (p[i, 0] - p[j, 0], p[i, 1] - p[j, 1], p[i, 2] - p[j, 2])


@njit(cache=True, inline="always")
def _cross(u, v):
    return (u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0])


@njit(cache=True, inline="always")
def _dot(u, v):
    return u[0] * v[0] + u[1] * v[1] + u[2] * v[2]


@njit(cache=True)
def fold_angle(p, reference):
    """Fold angle (radians) of hinge points ``p`` (4, 3) = (a, b, c, d), the value
    of ``atan2`` plus the multiple of 2π nearest ``reference``."""
    e = _vec(p, 1, 0)
    m = _cross(_vec(p, 2, 0), e)   # normal of the left triangle (c side), length 2 A₁
    n = _cross(e, _vec(p, 3, 0))   # normal of the right triangle (d side)
    le = math.sqrt(_dot(e, e))
    if le == 0.0:
        return reference  # a collapsed hinge has no angle of its own
    phi = math.atan2(_dot(_cross(n, m), e) / le, _dot(m, n))
    return phi + 2.0 * math.pi * round((reference - phi) / (2.0 * math.pi))


@njit(cache=True)
def fold_angle_gradient(p, g):
    """∂φ/∂p of hinge points ``p`` (4, 3) into ``g`` (4, 3); False when a triangle
    is degenerate (g left zero)."""
    e = _vec(p, 1, 0)
    ee = _dot(e, e)
    rc, rd = _vec(p, 2, 0), _vec(p, 3, 0)
    m = _cross(rc, e)
    n = _cross(e, rd)
    mm, nn = _dot(m, m), _dot(n, n)
    g[:] = 0.0
    if ee <= 0.0 or mm <= 1e-30 * ee * ee or nn <= 1e-30 * ee * ee:
        return False
    le = math.sqrt(ee)
    sc, sd = _dot(rc, e) / ee, _dot(rd, e) / ee
    for k in range(3):
        gc = -le / mm * m[k]
        gd = -le / nn * n[k]
        g[2, k] = gc
        g[3, k] = gd
        g[0, k] = -(1.0 - sc) * gc - (1.0 - sd) * gd
        g[1, k] = -sc * gc - sd * gd
    return True


@njit(cache=True)
def _bar_gradient(p, k, rest, g):
    d = _vec(p, 1, 0)
    length = math.sqrt(_dot(d, d))
    if length <= 0.0:
        g[:] = 0.0
        return 0.0
    f = k * (length - rest) / length
    for c in range(3):
        g[0, c] = -f * d[c]
        g[1, c] = f * d[c]
    return 0.5 * k * (length - rest) ** 2


@njit(cache=True)
def _bar_hessian(p, k, rest, h):
    """The Hessian (6, 6) of a bar's energy into ``h``: [[K, −K], [−K, K]] with
    K = k [u uᵀ + (1 − L₀/L)(I − u uᵀ)], u the unit vector along it (zero for a
    bar of length 0, whose gradient is zero too)."""
    d = _vec(p, 1, 0)
    length = math.sqrt(_dot(d, d))
    h[:, :] = 0.0
    if length <= 0.0:
        return
    u = (d[0] / length, d[1] / length, d[2] / length)
    side = 1.0 - rest / length
    for r in range(3):
        for c in range(3):
            block = k * ((1.0 - side) * (u[r] * u[c]) + (side if r == c else 0.0))
            h[r, c] = h[3 + r, 3 + c] = block
            h[r, 3 + c] = h[3 + r, c] = -block


@njit(cache=True)
def _hinge_gradient(p, k, target, reference, g):
    phi = fold_angle(p, reference)
    fold_angle_gradient(p, g)
    g *= k * (phi - target)
    return 0.5 * k * (phi - target) ** 2


@njit(cache=True)
def _corner(p, i, j, l, k, rest, g):
    """Add ½ k (α − rest)² of the corner at p[i] (between p[j], p[l]), plus the sliver
    barrier below ``SLIVER`` × rest, and its gradient into g; returns the energy."""
    u = _vec(p, j, i)
    v = _vec(p, l, i)
    n = _cross(u, v)
    s = math.sqrt(_dot(n, n))
    uu, vv = _dot(u, u), _dot(v, v)
    if s <= 1e-30 * (uu + vv) or uu <= 0.0 or vv <= 0.0:
        return 0.0
    alpha = math.atan2(s, _dot(u, v))
    n = (n[0] / s, n[1] / s, n[2] / s)
    nu, nv = _cross(n, u), _cross(n, v)
    f = k * (alpha - rest)
    barrier = 0.0
    r = alpha / rest if rest > 0.0 else 1.0
    if r < SLIVER:  # a sliver: k (SLIVER / r − 1)², its derivative in α added to f
        barrier = k * (SLIVER / r - 1.0) ** 2
        f -= 2.0 * k * (SLIVER / r - 1.0) * SLIVER / (r * r * rest)
    for c in range(3):
        gj = -nu[c] / uu
        gl = nv[c] / vv
        g[j, c] += f * gj
        g[l, c] += f * gl
        g[i, c] -= f * (gj + gl)
    return 0.5 * k * (alpha - rest) ** 2 + barrier


@njit(cache=True)
def _triangle_gradient(p, k, rest, g):
    g[:] = 0.0
    return (_corner(p, 0, 1, 2, k, rest[0], g) + _corner(p, 1, 2, 0, k, rest[1], g)
            + _corner(p, 2, 0, 1, k, rest[2], g))


@njit(cache=True)
def _element_size(p, size):
    """The element's smallest height (or a bar's length): the scale its forces change
    over, so the difference step of its Hessian is a fixed share of it (a sliver
    triangle 1e-6 high needs steps well below 1e-6)."""
    if size == 2:
        d = _vec(p, 1, 0)
        return max(math.sqrt(_dot(d, d)), 1e-300)
    smallest = math.inf
    for i in range(size):  # each side of each triangle, the height over it
        for j in range(i + 1, size):
            e = _vec(p, j, i)
            le = math.sqrt(_dot(e, e))
            smallest = min(smallest, le)
            for k in range(size):
                if k != i and k != j and (size == 3 or (i, j) == (0, 1)):
                    n = _cross(e, _vec(p, k, i))
                    smallest = min(smallest, math.sqrt(_dot(n, n)) / max(le, 1e-300))
    return max(smallest, COLLAPSED)


@njit(cache=True)
def _element_gradient(kind, p, k, rest, reference, g):
    """Energy and gradient (into g) of one element of ``kind`` 0 bar, 1 hinge,
    2 triangle at its points ``p``."""
    if kind == 0:
        return _bar_gradient(p, k, rest[0], g)
    if kind == 1:
        return _hinge_gradient(p, k, rest[0], reference, g)
    return _triangle_gradient(p, k, rest, g)


@njit(cache=True, parallel=True)
def evaluate(x, nodes, sizes, kinds, stiffness, rest, reference, energy, gradient, hessian,
             want_hessian):
    """Every element's energy, gradient and (``want_hessian``) Hessian.

    Parameters
    ----------
    x : (N, 3) float, positions
    nodes : (M, 4) int, each element's nodes (the first ``sizes[e]`` used)
    sizes, kinds : (M,) int, node count and kind (0 bar, 1 hinge, 2 triangle)
    stiffness : (M,) float
    rest : (M, 3) float, rest length / target angle / rest corner angles
    reference : (M,) float, each hinge's unwrapping reference angle
    energy : (M,) float, out
    gradient : (M, 12) float, out: ∂E/∂(node coordinates), node-major
    hessian : (M, 12, 12) float, out when ``want_hessian``
    """
    for e in prange(len(kinds)):
        size = sizes[e]
        p = np.empty((size, 3))
        for a in range(size):
            p[a] = x[nodes[e, a]]
        g = np.zeros((size, 3))
        energy[e] = _element_gradient(kinds[e], p, stiffness[e], rest[e], reference[e], g)
        for a in range(size):
            for c in range(3):
                gradient[e, 3 * a + c] = g[a, c]
        if not want_hessian:
            continue
        if kinds[e] == 0:
            _bar_hessian(p, stiffness[e], rest[e, 0], hessian[e])
            continue
        gp = np.zeros((size, 3))
        step = STEP * _element_size(p, size)
        for a in range(size):
            for c in range(3):
                keep = p[a, c]
                p[a, c] = keep + step
                _element_gradient(kinds[e], p, stiffness[e], rest[e], reference[e], gp)
                p[a, c] = keep
                column = 3 * a + c
                for b in range(size):
                    for d in range(3):
                        hessian[e, 3 * b + d, column] = (gp[b, d] - g[b, d]) / step
        for i in range(3 * size):  # symmetric: the mean of the two differences
            for j in range(i):
                mean = 0.5 * (hessian[e, i, j] + hessian[e, j, i])
                hessian[e, i, j] = mean
                hessian[e, j, i] = mean


@njit(cache=True, parallel=True)
def fold_angles(x, hinges, reference, out):
    """Fold angle (radians) of every hinge (H, 4) at x, unwrapped near ``reference``."""
    for h in prange(len(hinges)):
        p = np.empty((4, 3))
        for a in range(4):
            p[a] = x[hinges[h, a]]
        out[h] = fold_angle(p, reference[h])
