"""Shared numba helpers for element kernels: the optimal rotation of an element's target.

The fit is allocation-free: the centroid, the 3×3 covariance and the rotation
live in scalars (numba keeps them in registers), because a per-element
``np.linalg.svd`` with its small arrays cost ~4 µs and dominated the whole
projection (measured on Miura 40×40: 3–3.6 µs per element). The rotation is the
orthogonal polar factor of the covariance, by Higham's scaled Newton
iteration X ← ½(γX + X⁻ᵀ/γ) (Higham 1986, "Computing the polar decomposition
— with applications"): for det > 0 it is exactly the Kabsch rotation. When the
covariance is inverted or nearly singular (det ≤ ``DEGENERATE`` ‖A‖³: an
element turned inside out, or collapsed) the SVD with its det flip is used.
Newton keeps the sign of det, so a positive det always yields a rotation; a
thin strip (H/W = 1e-3, L/W = 10) has det/‖A‖³ ≈ 1e-10, well above the cut.
"""
import math

import numpy as np
from numba import njit

DEGENERATE = 1e-14  # det(A)/‖A‖_F³ below which the SVD path is taken
NEWTON_TOL = 1e-15  # relative Frobenius change that ends the Newton iteration
NEWTON_MAX = 30  # iterations cap (quadratic convergence: ~6–9 are used)


@njit(cache=True)
def best_rotation(cov):
    """Rotation R (det = +1) maximising tr(Rᵀ cov), i.e. minimising Σ‖p − R t‖².

    Parameters
    ----------
    cov : (3, 3) float64
        Σ p tᵀ over an element's vertices: p current (centred), t target (centred).

    Returns
    -------
    (3, 3) float64
        Kabsch/Procrustes rotation U·diag(1, 1, det(U Vᵀ))·Vᵀ.
    """
    u, _, vt = np.linalg.svd(cov)
    if np.linalg.det(u) * np.linalg.det(vt) < 0.0:
        u[:, 2] = -u[:, 2]
    return u @ vt


@njit(cache=True)
def _det(a, b, c, d, e, f, g, h, i):
    return a * (e * i - f * h) - b * (d * i - f * g) + c * (d * h - e * g)


@njit(cache=True)
def polar_rotation(a, b, c, d, e, f, g, h, i):
    """Rotation nearest to the row-major 3×3 matrix (a…i), as 9 scalars (row-major).

    Scaled Newton iteration for the polar factor; falls back to the SVD when
    the matrix is inverted or nearly singular (see the module docstring).
    """
    norm = math.sqrt(a * a + b * b + c * c + d * d + e * e + f * f + g * g + h * h + i * i)
    det = _det(a, b, c, d, e, f, g, h, i)
    if not norm > 0.0 or det <= DEGENERATE * norm ** 3:
        r = best_rotation(np.array([[a, b, c], [d, e, f], [g, h, i]]))
        return (r[0, 0], r[0, 1], r[0, 2], r[1, 0], r[1, 1], r[1, 2],
                r[2, 0], r[2, 1], r[2, 2])
    for _ in range(NEWTON_MAX):
        det = _det(a, b, c, d, e, f, g, h, i)
        # X⁻ᵀ = cofactor(X) / det(X)
        ia, ib, ic = (e * i - f * h) / det, (f * g - d * i) / det, (d * h - e * g) / det
        id_, ie, if_ = (c * h - b * i) / det, (a * i - c * g) / det, (b * g - a * h) / det
        ig, ih, ii = (b * f - c * e) / det, (c * d - a * f) / det, (a * e - b * d) / det
        n_x = math.sqrt(a * a + b * b + c * c + d * d + e * e + f * f + g * g + h * h + i * i)
        n_y = math.sqrt(ia * ia + ib * ib + ic * ic + id_ * id_ + ie * ie + if_ * if_
                        + ig * ig + ih * ih + ii * ii)
        gamma = math.sqrt(n_y / n_x)
        s, t = 0.5 * gamma, 0.5 / gamma
        na, nb, nc = s * a + t * ia, s * b + t * ib, s * c + t * ic
        nd, ne, nf = s * d + t * id_, s * e + t * ie, s * f + t * if_
        ng, nh, ni = s * g + t * ig, s * h + t * ih, s * i + t * ii
        change = ((na - a) ** 2 + (nb - b) ** 2 + (nc - c) ** 2 + (nd - d) ** 2
                  + (ne - e) ** 2 + (nf - f) ** 2 + (ng - g) ** 2 + (nh - h) ** 2
                  + (ni - i) ** 2)
        a, b, c, d, e, f, g, h, i = na, nb, nc, nd, ne, nf, ng, nh, ni
        if change <= NEWTON_TOL ** 2 * 3.0:  # ‖R‖_F² = 3
            break
    return a, b, c, d, e, f, g, h, i


@njit(cache=True)
def fit_rotated(x, ids, target, out):
    """Write R·target (rotated to fit x[ids]) into ``out``; return the residual.

    ``target`` (m, 3) must be centred; ``out`` may be ``target`` itself (each
    row is read before it is written). The residual
    is Σ‖(x − c) − R·target‖² in mm², the element's unweighted energy.
    Allocates nothing (except on the rare SVD path).
    """
    m = len(ids)
    c0 = c1 = c2 = 0.0
    for k in range(m):
        c0 += x[ids[k], 0]
        c1 += x[ids[k], 1]
        c2 += x[ids[k], 2]
    c0, c1, c2 = c0 / m, c1 / m, c2 / m
    a = b = c = d = e = f = g = h = i = 0.0
    for k in range(m):
        p0, p1, p2 = x[ids[k], 0] - c0, x[ids[k], 1] - c1, x[ids[k], 2] - c2
        t0, t1, t2 = target[k, 0], target[k, 1], target[k, 2]
        a += p0 * t0
        b += p0 * t1
        c += p0 * t2
        d += p1 * t0
        e += p1 * t1
        f += p1 * t2
        g += p2 * t0
        h += p2 * t1
        i += p2 * t2
    a, b, c, d, e, f, g, h, i = polar_rotation(a, b, c, d, e, f, g, h, i)
    residual = 0.0
    for k in range(m):
        t0, t1, t2 = target[k, 0], target[k, 1], target[k, 2]
        o0 = a * t0 + b * t1 + c * t2
        o1 = d * t0 + e * t1 + f * t2
        o2 = g * t0 + h * t1 + i * t2
        out[k, 0], out[k, 1], out[k, 2] = o0, o1, o2
        residual += ((x[ids[k], 0] - c0 - o0) ** 2 + (x[ids[k], 1] - c1 - o1) ** 2
                     + (x[ids[k], 2] - c2 - o2) ** 2)
    return residual
