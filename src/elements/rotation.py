"""Shared numba helpers for element kernels: the optimal rotation of an element's target.

The fit is allocation-free: the centroid, the 3×3 covariance A and the rotation
live in scalars (numba keeps them in registers), because a per-element
``np.linalg.svd`` with its small arrays dominated the whole projection.

The rotation maximising tr(Rᵀ A) is found as Horn's unit quaternion: the
largest root of the 4×4 key matrix's characteristic polynomial by Newton from
an upper bound (Theobald 2005, "Rapid calculation of RMSDs using a
quaternion-based characteristic polynomial"), its eigenvector from the
adjugate, then Newton steps on the rotation itself (one or two; at most
``POLISH_MAX``) to bring the eigenvector's error, ε(λ/gap)², to the
conditioning of the problem, ε·λ/gap (:func:`quaternion_fit`,
:func:`polish_quaternion`). It always gives a proper rotation (det = +1), also
for inverted elements, in about half the time of the scaled Newton polar
iteration (docs/architecture.md#rotation-fit-of-an-element).

Where the eigen-gap is tiny (nearly collinear or coincident points:
|κ| < ``GAP_MIN`` λ³, κ = Π(λⱼ − λ)) the Newton polar factor is used instead, and
where the covariance is inverted or nearly singular (det ≤ ``DEGENERATE``
‖A‖³) Horn's quaternion again, its eigenvector found by cyclic Jacobi
rotations of the 4×4 key matrix (:func:`jacobi_rotation`), which any
(repeated) eigenvalue leaves well-defined; unlike an ``np.linalg.svd``
fallback it compiles quickly.
"""
import math

import numpy as np
from numba import njit

DEGENERATE = 1e-14  # det(A)/‖A‖_F³ below which the Jacobi path is taken
NEWTON_TOL = 1e-15  # relative Frobenius change that ends the Newton iteration
NEWTON_MAX = 30  # iterations cap (quadratic convergence: ~6–9 are used)
GAP_MIN = 1e-4  # κ/λ³ (~ relative eigen-gap) below which the quaternion path hands over
ROOT_TOL = 1e-14  # relative Newton step on λ that ends the root search
ROOT_MAX = 60  # root-search cap (from the upper bound: 1–4 steps on near-fits)
POLISH_TOL = 1e-10  # rad: a refinement step this small ends the refinement
POLISH_MAX = 4
JACOBI_TOL = 1e-15  # off-diagonal / Frobenius norm of N that ends the Jacobi sweeps
JACOBI_SWEEPS = 30  # cap (cyclic Jacobi converges quadratically: ~4–6 sweeps on 4×4)


@njit(cache=True)
def _det(a, b, c, d, e, f, g, h, i):
    return a * (e * i - f * h) - b * (d * i - f * g) + c * (d * h - e * g)


@njit(cache=True)
def polar_rotation(a, b, c, d, e, f, g, h, i):
    """Rotation nearest to the row-major 3×3 matrix (a…i), as 9 scalars (row-major).

    Scaled Newton iteration for the polar factor; when the matrix is inverted
    or nearly singular, :func:`jacobi_rotation` instead (module docstring).
    """
    norm = math.sqrt(a * a + b * b + c * c + d * d + e * e + f * f + g * g + h * h + i * i)
    det = _det(a, b, c, d, e, f, g, h, i)
    if not norm > 0.0 or det <= DEGENERATE * norm ** 3:
        return jacobi_rotation(a, b, c, d, e, f, g, h, i)
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
def quaternion_matrix(w, x, y, z):
    """Row-major 3×3 rotation (9 scalars) of the unit quaternion w + xi + yj + zk."""
    ww, xx, yy, zz = w * w, x * x, y * y, z * z
    xy, xz, yz, wx, wy, wz = x * y, x * z, y * z, w * x, w * y, w * z
    return (ww + xx - yy - zz, 2.0 * (xy - wz), 2.0 * (xz + wy),
            2.0 * (xy + wz), ww - xx + yy - zz, 2.0 * (yz - wx),
            2.0 * (xz - wy), 2.0 * (yz + wx), ww - xx - yy + zz)


@njit(cache=True)
def horn_matrix(a, b, c, d, e, f, g, h, i):
    """Upper triangle (n11, n12, n13, n14, n22, n23, n24, n33, n34, n44) of Horn's
    symmetric 4×4 key matrix N of the row-major A (a…i): qᵀNq = tr(R(q)ᵀ A)."""
    # built from S = Aᵀ (S = Σ t pᵀ: target t onto current p)
    sxx, sxy, sxz = a, d, g
    syx, syy, syz = b, e, h
    szx, szy, szz = c, f, i
    return (sxx + syy + szz, syz - szy, szx - sxz, sxy - syx,
            sxx - syy - szz, sxy + syx, szx + sxz,
            -sxx + syy - szz, syz + szy,
            -sxx - syy + szz)


@njit(cache=True)
def jacobi_rotation(a, b, c, d, e, f, g, h, i):
    """Rotation maximising tr(Rᵀ A) by Horn's quaternion, N diagonalised by Jacobi.

    Cyclic Jacobi rotations (each zeroes one off-diagonal entry of N and
    accumulates into the eigenvector matrix V) until the off-diagonal part is
    below ``JACOBI_TOL`` of ‖N‖_F; the quaternion is V's column of the largest
    diagonal entry, then polished (:func:`polish_quaternion`, which stops at
    once where the optimum is not isolated). Valid for every A — inverted,
    rank-deficient, zero (identity) — since a repeated top eigenvalue only
    means several rotations are optimal. Returns 9 scalars, row-major.
    """
    n = np.empty((4, 4))
    (n[0, 0], n[0, 1], n[0, 2], n[0, 3], n[1, 1], n[1, 2], n[1, 3], n[2, 2], n[2, 3],
     n[3, 3]) = horn_matrix(a, b, c, d, e, f, g, h, i)
    for p in range(4):
        for q in range(p):
            n[p, q] = n[q, p]
    v = np.eye(4)
    for _ in range(JACOBI_SWEEPS):
        off = total = 0.0
        for p in range(4):
            for q in range(4):
                total += n[p, q] * n[p, q]
                if p != q:
                    off += n[p, q] * n[p, q]
        if not off > JACOBI_TOL * JACOBI_TOL * total:
            break
        for p in range(3):
            for q in range(p + 1, 4):
                if n[p, q] == 0.0:
                    continue
                # rotation J (c, s) in the (p, q) plane with (Jᵀ N J)[p, q] = 0
                theta = (n[q, q] - n[p, p]) / (2.0 * n[p, q])
                t = 1.0 / (abs(theta) + math.sqrt(theta * theta + 1.0))
                if theta < 0.0:
                    t = -t
                cos = 1.0 / math.sqrt(t * t + 1.0)
                sin = t * cos
                for k in range(4):  # N ← N J, V ← V J
                    nkp, nkq = n[k, p], n[k, q]
                    n[k, p], n[k, q] = cos * nkp - sin * nkq, sin * nkp + cos * nkq
                    vkp, vkq = v[k, p], v[k, q]
                    v[k, p], v[k, q] = cos * vkp - sin * vkq, sin * vkp + cos * vkq
                for k in range(4):  # N ← Jᵀ N
                    npk, nqk = n[p, k], n[q, k]
                    n[p, k], n[q, k] = cos * npk - sin * nqk, sin * npk + cos * nqk
    top = 0
    for k in range(1, 4):
        if n[k, k] > n[top, top]:
            top = k
    w, x, y, z = v[0, top], v[1, top], v[2, top], v[3, top]
    inv = 1.0 / math.sqrt(w * w + x * x + y * y + z * z)
    w, x, y, z = polish_quaternion(a, b, c, d, e, f, g, h, i, w * inv, x * inv, y * inv,
                                   z * inv)
    return quaternion_matrix(w, x, y, z)


@njit(cache=True)
def quaternion_fit(a, b, c, d, e, f, g, h, i, upper):
    """Horn's quaternion of the rotation maximising tr(Rᵀ A), A the row-major a…i.

    The largest eigenvalue λ of Horn's symmetric 4×4 matrix N(A) is the root
    of its characteristic polynomial λ⁴ − 2‖A‖²λ² − 8 det(A) λ + det N found by
    Newton from min(``upper``, √3‖A‖_F) (``upper``: any bound ≥ λ, e.g.
    (Σ‖p‖² + Σ‖t‖²)/2, within rounding of λ on near-fits; √3‖A‖_F keeps the
    start within 3 λ when the current shape is tiny against the target): from
    above the quartic is increasing and convex, so the steps fall
    monotonically onto the root. The eigenvector is the column of adj(N − λI)
    with the largest diagonal entry (Theobald 2005, "Rapid calculation of RMSDs
    using a quaternion-based characteristic polynomial"). Returns (ok, w, x,
    y, z); ok is False when the root search does not settle within
    ``ROOT_MAX`` steps or when |κ|, κ = Π(λⱼ − λ) the trace of that adjugate,
    is below ``GAP_MIN`` λ³: a near-double root (nearly collinear or
    coincident points), where the eigenvector is ill-determined. Its error
    grows like ε(λ/gap)², so :func:`polish_quaternion` refines it.
    """
    n11, n12, n13, n14, n22, n23, n24, n33, n34, n44 = horn_matrix(a, b, c, d, e, f, g,
                                                                    h, i)
    fro = a * a + b * b + c * c + d * d + e * e + f * f + g * g + h * h + i * i
    c2 = -2.0 * fro
    c1 = -8.0 * _det(a, b, c, d, e, f, g, h, i)
    # det(N) by 2×2 minors of rows (1,2) and (3,4)
    s0 = n11 * n22 - n12 * n12
    s1 = n11 * n23 - n13 * n12
    s2 = n11 * n24 - n14 * n12
    s3 = n12 * n23 - n13 * n22
    s4 = n12 * n24 - n14 * n22
    s5 = n13 * n24 - n14 * n23
    t0 = n13 * n24 - n23 * n14
    t1 = n13 * n34 - n33 * n14
    t2 = n13 * n44 - n34 * n14
    t3 = n23 * n34 - n33 * n24
    t4 = n23 * n44 - n34 * n24
    t5 = n33 * n44 - n34 * n34
    c0 = s0 * t5 - s1 * t4 + s2 * t3 + s3 * t2 - s4 * t1 + s5 * t0
    # start ≤ 3 λ whatever the scale of ``upper``: λ ≥ σ₁ ≥ ‖A‖_F/√3 and
    # λ ≤ σ₁ + σ₂ + σ₃ ≤ √3 ‖A‖_F (from far above, Newton on a quartic only
    # shrinks λ by ¾ per step)
    lam = min(upper, math.sqrt(3.0 * fro))
    converged = False
    for _ in range(ROOT_MAX):
        l2 = lam * lam
        p = (l2 + c2) * l2 + c1 * lam + c0
        dp = (4.0 * l2 + 2.0 * c2) * lam + c1
        if not dp > 0.0:  # a (near-)double root: leave it to the fallback
            break
        step = p / dp
        lam -= step
        if abs(step) <= ROOT_TOL * abs(lam):
            converged = True
            break
    if not converged:
        return False, 1.0, 0.0, 0.0, 0.0
    # adjugate of M = N − λI: column with the largest diagonal cofactor
    m11, m22, m33, m44 = n11 - lam, n22 - lam, n33 - lam, n44 - lam
    # principal minors (diagonal of adj)
    d1 = _det(m22, n23, n24, n23, m33, n34, n24, n34, m44)
    d2 = _det(m11, n13, n14, n13, m33, n34, n14, n34, m44)
    d3 = _det(m11, n12, n14, n12, m22, n24, n14, n24, m44)
    d4 = _det(m11, n12, n13, n12, m22, n23, n13, n23, m33)
    kappa = d1 + d2 + d3 + d4
    scale = lam * lam * lam
    if not (abs(kappa) > GAP_MIN * scale and lam > 0.0):
        return False, 1.0, 0.0, 0.0, 0.0
    # column j of adj(M): cofactors C_{kj}, adj symmetric
    if abs(d1) >= abs(d2) and abs(d1) >= abs(d3) and abs(d1) >= abs(d4):
        q0 = d1
        q1 = -_det(n12, n23, n24, n13, m33, n34, n14, n34, m44)
        q2 = _det(n12, m22, n24, n13, n23, n34, n14, n24, m44)
        q3 = -_det(n12, m22, n23, n13, n23, m33, n14, n24, n34)
    elif abs(d2) >= abs(d3) and abs(d2) >= abs(d4):
        q0 = -_det(n12, n13, n14, n23, m33, n34, n24, n34, m44)
        q1 = d2
        q2 = -_det(m11, n12, n14, n13, n23, n34, n14, n24, m44)
        q3 = _det(m11, n12, n13, n13, n23, m33, n14, n24, n34)
    elif abs(d3) >= abs(d4):
        q0 = _det(n12, n13, n14, m22, n23, n24, n24, n34, m44)
        q1 = -_det(m11, n13, n14, n12, n23, n24, n14, n34, m44)
        q2 = d3
        q3 = -_det(m11, n12, n13, n12, m22, n23, n14, n24, n34)
    else:
        q0 = -_det(n12, n13, n14, m22, n23, n24, n23, m33, n34)
        q1 = _det(m11, n13, n14, n12, n23, n24, n13, m33, n34)
        q2 = -_det(m11, n12, n14, n12, m22, n24, n13, n23, n34)
        q3 = d4
    norm = math.sqrt(q0 * q0 + q1 * q1 + q2 * q2 + q3 * q3)
    inv = 1.0 / norm
    return True, q0 * inv, q1 * inv, q2 * inv, q3 * inv


@njit(cache=True)
def polish_quaternion(a, b, c, d, e, f, g, h, i, w, x, y, z):
    """Newton steps R ← R·exp([ω]×) on tr(Rᵀ A) from the unit quaternion (w, x, y, z).

    With B = Rᵀ A, the step solves (tr B·I − sym B) ω = (B₃₂ − B₂₃, B₁₃ − B₃₁,
    B₂₁ − B₁₂) (the second-order model of tr(exp(−[ω]×) B)); it is applied as the
    quaternion product q ⊗ (1, ω/2), renormalised. One step brings the
    quaternion fit's ε(λ/gap)² error to the polar factor's ε·λ/gap.
    """
    for _ in range(POLISH_MAX):
        r00, r01, r02, r10, r11, r12, r20, r21, r22 = quaternion_matrix(w, x, y, z)
        # B = Rᵀ A
        b00 = r00 * a + r10 * d + r20 * g
        b01 = r00 * b + r10 * e + r20 * h
        b02 = r00 * c + r10 * f + r20 * i
        b10 = r01 * a + r11 * d + r21 * g
        b11 = r01 * b + r11 * e + r21 * h
        b12 = r01 * c + r11 * f + r21 * i
        b20 = r02 * a + r12 * d + r22 * g
        b21 = r02 * b + r12 * e + r22 * h
        b22 = r02 * c + r12 * f + r22 * i
        s0, s1, s2 = b21 - b12, b02 - b20, b10 - b01
        tr = b00 + b11 + b22
        # M = tr I − sym(B)
        m00, m11, m22 = tr - b00, tr - b11, tr - b22
        m01, m02, m12 = -0.5 * (b01 + b10), -0.5 * (b02 + b20), -0.5 * (b12 + b21)
        det = _det(m00, m01, m02, m01, m11, m12, m02, m12, m22)
        if not det > 0.0:
            break
        inv = 1.0 / det
        o0 = _det(s0, m01, m02, s1, m11, m12, s2, m12, m22) * inv
        o1 = _det(m00, s0, m02, m01, s1, m12, m02, s2, m22) * inv
        o2 = _det(m00, m01, s0, m01, m11, s1, m02, m12, s2) * inv
        p1, p2, p3 = 0.5 * o0, 0.5 * o1, 0.5 * o2
        nw = w - x * p1 - y * p2 - z * p3
        nx = w * p1 + x + y * p3 - z * p2
        ny = w * p2 - x * p3 + y + z * p1
        nz = w * p3 + x * p2 - y * p1 + z
        n = math.sqrt(nw * nw + nx * nx + ny * ny + nz * nz)
        inv = 1.0 / n
        w, x, y, z = nw * inv, nx * inv, ny * inv, nz * inv
        if o0 * o0 + o1 * o1 + o2 * o2 <= POLISH_TOL * POLISH_TOL:
            break
    return w, x, y, z


@njit(cache=True)
def fitted_rotation(a, b, c, d, e, f, g, h, i, upper):
    """Rotation maximising tr(Rᵀ A) for the row-major 3×3 A (a…i), as 9 scalars.

    ``upper`` ≥ the largest eigenvalue of Horn's matrix (see
    :func:`quaternion_fit`). The quaternion fit and one or two polishing
    steps; where its eigen-gap is too small, the Newton polar factor (and its
    Jacobi fallback) instead.
    """
    ok, w, x, y, z = quaternion_fit(a, b, c, d, e, f, g, h, i, upper)
    if not ok:
        return polar_rotation(a, b, c, d, e, f, g, h, i)
    w, x, y, z = polish_quaternion(a, b, c, d, e, f, g, h, i, w, x, y, z)
    return quaternion_matrix(w, x, y, z)


@njit(cache=True, inline="always")
def centroid(x, ids):
    """Mean of the rows ``x[ids]`` as 3 scalars (mm)."""
    m = len(ids)
    c0 = c1 = c2 = 0.0
    for k in range(m):
        c0 += x[ids[k], 0]
        c1 += x[ids[k], 1]
        c2 += x[ids[k], 2]
    return c0 / m, c1 / m, c2 / m


@njit(cache=True, inline="always")
def fit_about(x, ids, target, c0, c1, c2):
    """Rotation (9 scalars, row-major) best fitting ``target`` (m, 3), centred, to
    ``x[ids]`` about its centroid (c0, c1, c2): :func:`fitted_rotation` of their
    covariance."""
    m = len(ids)
    a = b = c = d = e = f = g = h = i = sum_p = sum_t = 0.0
    for k in range(m):
        p0, p1, p2 = x[ids[k], 0] - c0, x[ids[k], 1] - c1, x[ids[k], 2] - c2
        t0, t1, t2 = target[k, 0], target[k, 1], target[k, 2]
        sum_p += p0 * p0 + p1 * p1 + p2 * p2
        sum_t += t0 * t0 + t1 * t1 + t2 * t2
        a += p0 * t0
        b += p0 * t1
        c += p0 * t2
        d += p1 * t0
        e += p1 * t1
        f += p1 * t2
        g += p2 * t0
        h += p2 * t1
        i += p2 * t2
    return fitted_rotation(a, b, c, d, e, f, g, h, i, 0.5 * (sum_p + sum_t))


@njit(cache=True)
def fit_rotated(x, ids, target, out):
    """Write R·target (rotated to fit x[ids]) into ``out``; return the residual.

    ``target`` (m, 3) must be centred; ``out`` may be ``target`` itself (each
    row is read before it is written). The residual
    is Σ‖(x − c) − R·target‖² in mm², the element's unweighted energy.
    Allocates nothing (except on the rare Jacobi path).
    """
    m = len(ids)
    c0, c1, c2 = centroid(x, ids)
    a, b, c, d, e, f, g, h, i = fit_about(x, ids, target, c0, c1, c2)
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
