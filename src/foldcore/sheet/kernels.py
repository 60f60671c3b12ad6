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
def _symmetrise(h, n):
    """``h``'s leading (n, n) block replaced by its symmetric part, so the assembled
    Hessian is symmetric to the last bit (the chain rule's two orders of
    differentiation round differently)."""
    for i in range(n):
        for j in range(i):
            mean = 0.5 * (h[i, j] + h[j, i])
            h[i, j] = mean
            h[j, i] = mean


@njit(cache=True, inline="always")
def _skew_at(u, a, b):
    """Entry (a, b) of [u]×, the matrix of v ↦ u × v."""
    turn = (b - a) % 3
    if turn == 0:
        return 0.0
    return -u[3 - a - b] if turn == 1 else u[3 - a - b]


@njit(cache=True)
def _normal_gradient_jacobians(s, w, ww, r, e, sign, out_r, out_e):
    """Jacobians (3, 3) of a tip's gradient g = −s w / (w·w) (s = |e|, w the triangle's
    normal: w = r × e for the left tip (``sign`` 1: ∂w/∂r = −[e]×, ∂w/∂e = [r]×), w =
    e × r for the right (``sign`` −1: ∂w/∂r = [e]×, ∂w/∂e = −[r]×)) with respect to
    the tip's vector r (into ``out_r``) and the edge e (into ``out_e``)."""
    for i in range(3):
        for j in range(3):
            # P = I − 2 w wᵀ / (w·w): the derivative of w / (w·w) is P / (w·w) ∂w
            pr = 0.0
            pe = 0.0
            for l in range(3):
                proj = (1.0 if i == l else 0.0) - 2.0 * w[i] * w[l] / ww
                pr += proj * (-sign * _skew_at(e, l, j))
                pe += proj * (sign * _skew_at(r, l, j))
            out_r[i, j] = -s / ww * pr
            out_e[i, j] = -s / ww * pe - w[i] * e[j] / (s * ww)


@njit(cache=True)
def fold_angle_hessian(p, g, h):
    """∂φ/∂p into ``g`` (4, 3) and ∂²φ/∂p² into ``h`` (12, 12) of hinge points ``p``
    (4, 3) = (a, b, c, d): the derivatives of :func:`fold_angle_gradient`'s
    expressions (g_c = −|e| m / |m|², g_d = −|e| n / |n|², g_b = −s_c g_c − s_d g_d,
    g_a = −g_b − g_c − g_d, s = r·e / |e|²), by the chain rule through r_c = c − a,
    r_d = d − a, e = b − a; False (both zero) where :func:`fold_angle_gradient`
    finds a triangle degenerate."""
    h[:, :] = 0.0
    if not fold_angle_gradient(p, g):
        return False
    e = _vec(p, 1, 0)
    rc, rd = _vec(p, 2, 0), _vec(p, 3, 0)
    m, n = _cross(rc, e), _cross(e, rd)
    ee, mm, nn = _dot(e, e), _dot(m, m), _dot(n, n)
    le = math.sqrt(ee)
    jac = np.empty((4, 3, 3))  # ∂g_c/∂r_c, ∂g_c/∂e, ∂g_d/∂r_d, ∂g_d/∂e
    _normal_gradient_jacobians(le, m, mm, rc, e, 1.0, jac[0], jac[1])
    _normal_gradient_jacobians(le, n, nn, rd, e, -1.0, jac[2], jac[3])
    sc, sd = _dot(rc, e) / ee, _dot(rd, e) / ee
    # through r_c = c − a, r_d = d − a, e = b − a: per point k (a, b, c, d) the
    # weights of ∂/∂r and ∂/∂e in ∂/∂p_k
    on_r = ((-1.0, 0.0, 1.0, 0.0), (-1.0, 0.0, 0.0, 1.0))  # r_c, r_d
    on_e = (-1.0, 1.0, 0.0, 0.0)
    for k in range(4):
        for j in range(3):
            col = 3 * k + j
            # ∂s_c/∂p_k, ∂s_d/∂p_k (component j): ∂s/∂r = e / ee, ∂s/∂e = (r − 2 s e) / ee
            dsc = (on_r[0][k] * e[j] + on_e[k] * (rc[j] - 2.0 * sc * e[j])) / ee
            dsd = (on_r[1][k] * e[j] + on_e[k] * (rd[j] - 2.0 * sd * e[j])) / ee
            for i in range(3):
                dgc = on_r[0][k] * jac[0, i, j] + on_e[k] * jac[1, i, j]
                dgd = on_r[1][k] * jac[2, i, j] + on_e[k] * jac[3, i, j]
                gb = -g[2, i] * dsc - sc * dgc - g[3, i] * dsd - sd * dgd
                h[3 + i, col] = gb
                h[6 + i, col] = dgc
                h[9 + i, col] = dgd
                h[i, col] = -gb - dgc - dgd
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
def _hinge_hessian(p, k, target, reference, h):
    """The Hessian (12, 12) of a hinge's energy ½ k (φ − φ̄)² into ``h``:
    k (∇φ ∇φᵀ + (φ − φ̄) ∇²φ) (zero where a triangle is degenerate, as its
    gradient is)."""
    g = np.empty((4, 3))
    if not fold_angle_hessian(p, g, h):
        return
    miss = fold_angle(p, reference) - target
    for i in range(12):
        gi = g[i // 3, i % 3]
        for j in range(12):
            h[i, j] = k * (gi * g[j // 3, j % 3] + miss * h[i, j])
    _symmetrise(h, 12)


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
def _corner_hessian(p, i, j, l, k, rest, h, work):
    """Add the Hessian of ½ k (α − rest)² of the corner at p[i] (between p[j], p[l])
    into ``h`` (9, 9, point-major): k (∇α ∇αᵀ + (α − rest) ∇²α), with u = p[j] − p[i],
    v = p[l] − p[i], n = u × v / |u × v|, ∂α/∂u = −n × u / |u|², ∂α/∂v = n × v / |v|²
    (:func:`_corner`'s) differentiated through n: ∂n = (I − n nᵀ)(u × ∂v − v × ∂u) / |u × v|;
    ``work`` (60,) scratch."""
    u, v = _vec(p, j, i), _vec(p, l, i)
    w = _cross(u, v)
    s = math.sqrt(_dot(w, w))
    uu, vv = _dot(u, u), _dot(v, v)
    if s <= 1e-30 * (uu + vv) or uu <= 0.0 or vv <= 0.0:
        return
    alpha = math.atan2(s, _dot(u, v))
    n = (w[0] / s, w[1] / s, w[2] / s)
    nu, nv = _cross(n, u), _cross(n, v)
    grad = work[:6].reshape(2, 3)  # ∂α/∂u, ∂α/∂v
    dn = work[6:24].reshape(2, 3, 3)  # ∂n/∂u, ∂n/∂v
    block = work[24:60].reshape(2, 2, 3, 3)  # ∂²α/∂(u, v)²
    for a in range(3):
        grad[0, a], grad[1, a] = -nu[a] / uu, nv[a] / vv
        for b in range(3):
            du = 0.0
            dv = 0.0
            for c in range(3):
                proj = ((1.0 if a == c else 0.0) - n[a] * n[c]) / s
                du -= proj * _skew_at(v, c, b)
                dv += proj * _skew_at(u, c, b)
            dn[0, a, b], dn[1, a, b] = du, dv
    for a in range(3):
        for b in range(3):
            for q in range(2):  # derivative with respect to u (0) or v (1)
                turn_u = 0.0  # −[u]× ∂n/∂q
                turn_v = 0.0  # −[v]× ∂n/∂q
                for c in range(3):
                    turn_u -= _skew_at(u, a, c) * dn[q, c, b]
                    turn_v -= _skew_at(v, a, c) * dn[q, c, b]
                block[0, q, a, b] = -turn_u / uu
                block[1, q, a, b] = turn_v / vv
            block[0, 0, a, b] += -_skew_at(n, a, b) / uu + 2.0 * nu[a] * u[b] / (uu * uu)
            block[1, 1, a, b] += _skew_at(n, a, b) / vv - 2.0 * nv[a] * v[b] / (vv * vv)
    slope, curvature = k * (alpha - rest), k  # dE/dα, d²E/dα²
    ratio = alpha / rest if rest > 0.0 else 1.0
    if ratio < SLIVER:  # the sliver barrier k (SLIVER / r − 1)², r = α / rest
        slope -= 2.0 * k * (SLIVER / ratio - 1.0) * SLIVER / (ratio * ratio * rest)
        curvature += 2.0 * k * SLIVER / (rest * rest) * (
            SLIVER / ratio ** 4 + 2.0 * (SLIVER / ratio - 1.0) / ratio ** 3)
    points = (i, j, l)
    # point r's coordinates enter u with weight cu[r], v with cv[r]
    cu, cv = (-1.0, 1.0, 0.0), (-1.0, 0.0, 1.0)
    for r in range(3):
        for t in range(3):
            for a in range(3):
                gr = cu[r] * grad[0, a] + cv[r] * grad[1, a]
                for b in range(3):
                    gt = cu[t] * grad[0, b] + cv[t] * grad[1, b]
                    second = (cu[r] * cu[t] * block[0, 0, a, b] + cu[r] * cv[t] * block[0, 1, a, b]
                              + cv[r] * cu[t] * block[1, 0, a, b]
                              + cv[r] * cv[t] * block[1, 1, a, b])
                    h[3 * points[r] + a, 3 * points[t] + b] += curvature * gr * gt + slope * second


@njit(cache=True)
def _triangle_hessian(p, k, rest, h):
    """The Hessian (9, 9) of a triangle's corner-angle energy into ``h``'s first 9 rows
    and columns (the rest zero)."""
    h[:, :] = 0.0
    work = np.empty(60)
    _corner_hessian(p, 0, 1, 2, k, rest[0], h, work)
    _corner_hessian(p, 1, 2, 0, k, rest[1], h, work)
    _corner_hessian(p, 2, 0, 1, k, rest[2], h, work)
    _symmetrise(h, 9)


@njit(cache=True)
def _triangle_gradient(p, k, rest, g):
    g[:] = 0.0
    return (_corner(p, 0, 1, 2, k, rest[0], g) + _corner(p, 1, 2, 0, k, rest[1], g)
            + _corner(p, 2, 0, 1, k, rest[2], g))


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
        elif kinds[e] == 1:
            _hinge_hessian(p, stiffness[e], rest[e, 0], reference[e], hessian[e])
        else:
            _triangle_hessian(p, stiffness[e], rest[e], hessian[e])


@njit(cache=True, parallel=True)
def fold_angles(x, hinges, reference, out):
    """Fold angle (radians) of every hinge (H, 4) at x, unwrapped near ``reference``."""
    for h in prange(len(hinges)):
        p = np.empty((4, 3))
        for a in range(4):
            p[a] = x[hinges[h, a]]
        out[h] = fold_angle(p, reference[h])
