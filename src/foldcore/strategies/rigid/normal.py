"""Normal equations of the rigid-body step, assembled strip by strip in numba.

Why: the rigid-body Levenberg–Marquardt step (:mod:`.step`) solves
(JᵀJ + λD) δq = −Jᵀr, and forming the sparse Jacobian J and multiplying it
with SciPy cost most of a step
(`docs/architecture.md#normal-equations-without-j`). Here JᵀJ's values are
written directly into a CSC matrix whose pattern is fixed per column layout
(so CHOLMOD reuses its symbolic analysis across steps), and Jᵀu, J·v are
applied without J.

The strip rows. Strip s (8 vertices k) has residual rows
r_k = √w (x_k − x̄ − R t_k); a vertex moves with the unknowns as
∂x_k/∂q = G_k: α_b·[−[x_k − c_b]× | I] in the columns (rotation, shift) of
each panel b carrying it (its own panel with α = 1, or the two panels of its
crease with the blend weights of a hinge-interior vertex), plus I in its own
three columns when it is a hinge-interior vertex. With Ḡ = ⅛ Σ_k G_k and the
strip's rotation / angle columns E_k = [√w [R t_k]× | √w c d_k]
(d_k = R ∂T_k/∂φ, c = −1/k the crease's share):

    J_k = √w (G_k − Ḡ) + E_k,
    JᵀJ = w (Σ_k G_kᵀG_k − 8 ḠᵀḠ) + Σ_k (G_k − Ḡ)ᵀE_k √w + (…)ᵀ + Σ_k E_kᵀE_k,

using Σ_k (G_k − Ḡ) = 0; each G_k touches at most 15 columns, so a strip
costs a few thousand flops instead of the 24 × n_loc² of a dense product.
The local columns of a strip are its crease's two panels (6 each, when they
move), its hinge-interior vertices (3 each), its rotation (3) and, when its
crease is passive, its crease's angle (1).

Pattern: the lower triangle (row ≥ column; CHOLMOD reads only that one,
:class:`foldcore.linsolve.Factor`; half the entries to write and keep) of
every local pair but the structural zeros (two hinge-interior
coordinates of different axes), every diagonal entry and every panel's 6 × 6
block (position targets and M/V side rows add only there or inside a strip's
block). Units: mm, rad.
"""
from __future__ import annotations

import math
from pathlib import Path

import numba
import numpy as np
from numba import njit, prange

import elements
from elements.cache import choose_cache_dir, drop_stale_kernels
from elements.rotation import centroid, fit_about

choose_cache_dir(Path(__file__))  # before this module's cache=True kernels (read-only installs)
# these kernels call elements.rotation: recompile them when it changes (elements.cache)
drop_stale_kernels(Path(__file__).parent, numba.__version__, (Path(elements.__file__).parent,),
                   module=Path(__file__).stem)

MAX_LOCAL = 12 + 24 + 3 + 1  # columns of a strip: 2 panels, 8 interior vertices, rotation, angle


@njit(cache=True, inline="always")
def _vertex_columns(s, k, ids, x, c_p, side, off_panel, alpha, own_off, cols, vecs):
    """Columns of G_k (strip s, vertex k): local indices (≤ 15,) and their 3-vectors.

    Returns the number of columns written to ``cols`` / ``vecs`` (15,) / (15, 3).
    """
    n = 0
    v = ids[s, k]
    for b in range(2):
        o = off_panel[s, b]
        al = alpha[s, k, b]
        if o < 0 or al == 0.0:
            continue
        p = side[s, b]
        a0 = x[v, 0] - c_p[p, 0]
        a1 = x[v, 1] - c_p[p, 1]
        a2 = x[v, 2] - c_p[p, 2]
        # −[a]× columns (rotation), then I (shift), each × α
        cols[n] = o
        vecs[n, 0], vecs[n, 1], vecs[n, 2] = 0.0, -al * a2, al * a1
        cols[n + 1] = o + 1
        vecs[n + 1, 0], vecs[n + 1, 1], vecs[n + 1, 2] = al * a2, 0.0, -al * a0
        cols[n + 2] = o + 2
        vecs[n + 2, 0], vecs[n + 2, 1], vecs[n + 2, 2] = -al * a1, al * a0, 0.0
        for d in range(3):
            cols[n + 3 + d] = o + 3 + d
            vecs[n + 3 + d, 0] = 0.0
            vecs[n + 3 + d, 1] = 0.0
            vecs[n + 3 + d, 2] = 0.0
            vecs[n + 3 + d, d] = al
        n += 6
    o = own_off[s, k]
    if o >= 0:
        for d in range(3):
            cols[n] = o + d
            vecs[n, 0] = 0.0
            vecs[n, 1] = 0.0
            vecs[n, 2] = 0.0
            vecs[n, d] = 1.0
            n += 1
    return n


@njit(cache=True, inline="always")
def _rotation_columns(s, k, off_w, off_phi, sqrt_w, targets, d_targets, ecols, evecs):
    """Columns of E_k (strip s, vertex k): rotation (3) and angle (0 or 1). Returns the count."""
    sw = sqrt_w[s]
    t0, t1, t2 = targets[s, k, 0], targets[s, k, 1], targets[s, k, 2]
    o = off_w[s]
    # √w [t]×, column by column
    ecols[0] = o
    evecs[0, 0], evecs[0, 1], evecs[0, 2] = 0.0, sw * t2, -sw * t1
    ecols[1] = o + 1
    evecs[1, 0], evecs[1, 1], evecs[1, 2] = -sw * t2, 0.0, sw * t0
    ecols[2] = o + 2
    evecs[2, 0], evecs[2, 1], evecs[2, 2] = sw * t1, -sw * t0, 0.0
    if off_phi[s] < 0:
        return 3
    ecols[3] = off_phi[s]
    for d in range(3):
        evecs[3, d] = sw * d_targets[s, k, d]
    return 4


@njit(parallel=True, cache=True)
def assemble(ids, x, c_p, side, off_panel, alpha, own_off, off_w, off_phi, loc_cols,
             sqrt_w, targets, d_targets, n_loc, residual, rounds, crease_ptr, crease_strips,
             indptr, indices, data, grad):
    """Add every strip's JᵀJ into ``data`` (CSC values, fixed pattern) and Jᵀr into ``grad``.

    Creases are taken in rounds (``rounds``: CSR (R + 1,) into the crease list);
    no two creases of a round share a panel, so a round's creases are added in
    parallel without two threads writing one entry.

    Parameters
    ----------
    ids : (S, 8) int, strip vertices
    x : (N, 3) positions, mm; c_p : (P, 3) panel centroids, mm
    side : (S, 2) int, the crease's two panels; off_panel : (S, 2) int, their local
        column offsets (−1: the panel does not move)
    alpha : (S, 8, 2) float, weight of each panel's motion on each vertex
    own_off : (S, 8) int, local offset of a hinge-interior vertex's columns (−1: none)
    off_w, off_phi : (S,) int, local offsets of the rotation and angle columns
        (angle −1: actuated strip)
    loc_cols : (S, MAX_LOCAL) int, global column of each local one, increasing
    sqrt_w : (S,) float, √w; targets, d_targets : (S, 8, 3) mm, R t_k and c·R ∂T_k/∂φ
        (these first thirteen: ``apply_jacobian``'s and ``apply_transpose``'s too)
    n_loc : (S,) int, local columns of each strip
    residual : (S, 8, 3) mm^(5/2), the strip rows r
    rounds : (R + 1,) int; crease_ptr : (C + 1,) int, crease_strips : (S,) int, the
        strips of each crease (CSR)
    indptr, indices : CSC pattern (n + 1,), (nnz,); data : (nnz,) float, added to
    grad : (n,) float, added to

    Returns
    -------
    int
        Number of nonzero local entries that had no place in the pattern (0 unless
        the layout is wrong).
    """
    missing = 0
    for r in range(len(rounds) - 1):
        for c in prange(rounds[r], rounds[r + 1]):
            local = np.zeros((MAX_LOCAL, MAX_LOCAL))
            g_loc = np.zeros(MAX_LOCAL)
            work = np.empty((3 + 15 + 4, MAX_LOCAL))  # Ḡ, G_k's and E_k's columns, Σ E_k, Σ r
            cols = np.empty(15 + 4, dtype=np.int64)
            for q in range(crease_ptr[c], crease_ptr[c + 1]):
                s = crease_strips[q]
                _strip_normal(s, ids, x, c_p, side, off_panel, alpha, own_off, off_w, off_phi,
                              n_loc[s], sqrt_w, targets, d_targets, residual, local, g_loc,
                              work, cols)
                missing += _scatter(n_loc[s], loc_cols[s], local, g_loc, indptr, indices,
                                    data, grad)
    return missing


@njit(cache=True)
def _strip_normal(s, ids, x, c_p, side, off_panel, alpha, own_off, off_w, off_phi, nl,
                  sqrt_w, targets, d_targets, residual, local, g_loc, work, index):
    """Strip s's JᵀJ, its lower triangle (row ≥ column; the upper one is left
    undefined), into ``local`` (nl, nl) and Jᵀr into ``g_loc`` (nl,), overwritten;
    ``work`` (22, MAX_LOCAL) float and ``index`` (19,) int are scratch."""
    gbar = work[0:3]
    vecs = work[3:18, 0:3]
    evecs = work[18:22, 0:3]
    ebar = work[18:21, 3:7]
    rsum = work[21, 3:6]
    cols = index[0:15]
    ecols = index[15:19]
    gbar[:, :nl] = 0.0
    ebar[:, :] = 0.0
    rsum[:] = 0.0
    w = sqrt_w[s] * sqrt_w[s]
    sw = sqrt_w[s]
    local[:nl, :nl] = 0.0
    g_loc[:nl] = 0.0
    n_e = 4
    for k in range(8):
        n = _vertex_columns(s, k, ids, x, c_p, side, off_panel, alpha, own_off, cols, vecs)
        n_e = _rotation_columns(s, k, off_w, off_phi, sqrt_w, targets, d_targets, ecols, evecs)
        r0, r1, r2 = residual[s, k, 0], residual[s, k, 1], residual[s, k, 2]
        rsum[0] += r0
        rsum[1] += r1
        rsum[2] += r2
        for i in range(n):
            ci = cols[i]
            vi0, vi1, vi2 = vecs[i, 0], vecs[i, 1], vecs[i, 2]
            for j in range(i + 1):  # one triangle: the lower one is stored
                cj = cols[j]
                value = w * (vi0 * vecs[j, 0] + vi1 * vecs[j, 1] + vi2 * vecs[j, 2])
                if ci >= cj:
                    local[ci, cj] += value
                else:
                    local[cj, ci] += value
            for j in range(n_e):  # Σ_k G_kᵀ E_k √w (E's columns come after G's)
                local[ecols[j], ci] += sw * (vi0 * evecs[j, 0] + vi1 * evecs[j, 1]
                                             + vi2 * evecs[j, 2])
            gbar[0, ci] += 0.125 * vi0
            gbar[1, ci] += 0.125 * vi1
            gbar[2, ci] += 0.125 * vi2
            g_loc[ci] += sw * (vi0 * r0 + vi1 * r1 + vi2 * r2)
        for i in range(n_e):
            ci = ecols[i]
            for j in range(i + 1):  # ecols increasing
                local[ci, ecols[j]] += (evecs[i, 0] * evecs[j, 0] + evecs[i, 1] * evecs[j, 1]
                                        + evecs[i, 2] * evecs[j, 2])
            for d in range(3):
                ebar[d, i] += evecs[i, d]
            g_loc[ci] += evecs[i, 0] * r0 + evecs[i, 1] * r1 + evecs[i, 2] * r2
    n_pos = off_w[s]  # position columns come first
    for i in range(n_pos):
        gi0, gi1, gi2 = gbar[0, i], gbar[1, i], gbar[2, i]
        if gi0 == 0.0 and gi1 == 0.0 and gi2 == 0.0:
            continue
        for j in range(i + 1):
            local[i, j] -= 8.0 * w * (gi0 * gbar[0, j] + gi1 * gbar[1, j] + gi2 * gbar[2, j])
        for j in range(n_e):  # − Ḡᵀ Σ_k E_k √w
            local[ecols[j], i] -= sw * (gi0 * ebar[0, j] + gi1 * ebar[1, j] + gi2 * ebar[2, j])
        g_loc[i] -= sw * (gi0 * rsum[0] + gi1 * rsum[1] + gi2 * rsum[2])


@njit(cache=True, inline="always")
def _scatter(nl, cols, local, g_loc, indptr, indices, data, grad):
    """Add a strip's local matrix's lower triangle into the CSC values, walking each
    column once (``cols`` increasing: the layout orders the local blocks so, and
    row ≥ column is local i ≥ j)."""
    missing = 0
    for j in range(nl):
        col = cols[j]
        grad[col] += g_loc[j]
        p, end = indptr[col], indptr[col + 1]
        for i in range(j, nl):
            value = local[i, j]
            if value == 0.0:
                continue
            row = cols[i]
            while p < end and indices[p] < row:
                p += 1
            if p < end and indices[p] == row:
                data[p] += value
            else:
                missing += 1
    return missing


@njit(parallel=True, cache=True)
def apply_jacobian(ids, x, c_p, side, off_panel, alpha, own_off, off_w, off_phi, loc_cols,
                   sqrt_w, targets, d_targets, v, out):
    """out (S, 8, 3) = the strip rows of J·v for an increment v (n,) of the unknowns."""
    for s in prange(ids.shape[0]):
        cols = np.empty(15, dtype=np.int64)
        vecs = np.empty((15, 3))
        ecols = np.empty(4, dtype=np.int64)
        evecs = np.empty((4, 3))
        sw = sqrt_w[s]
        mean = np.zeros(3)
        for k in range(8):
            n = _vertex_columns(s, k, ids, x, c_p, side, off_panel, alpha, own_off, cols, vecs)
            move = np.zeros(3)
            for i in range(n):
                vi = v[loc_cols[s, cols[i]]]
                for d in range(3):
                    move[d] += vecs[i, d] * vi
            for d in range(3):
                out[s, k, d] = sw * move[d]
                mean[d] += 0.125 * sw * move[d]
        for k in range(8):
            n_e = _rotation_columns(s, k, off_w, off_phi, sqrt_w, targets, d_targets,
                                    ecols, evecs)
            for d in range(3):
                value = out[s, k, d] - mean[d]
                for i in range(n_e):
                    value += evecs[i, d] * v[loc_cols[s, ecols[i]]]
                out[s, k, d] = value


@njit(cache=True)
def apply_transpose(ids, x, c_p, side, off_panel, alpha, own_off, off_w, off_phi, loc_cols,
                    sqrt_w, targets, d_targets, u, grad):
    """grad (n,) += the strip rows' Jᵀ·u for row values u (S, 8, 3)."""
    cols = np.empty(15, dtype=np.int64)
    vecs = np.empty((15, 3))
    ecols = np.empty(4, dtype=np.int64)
    evecs = np.empty((4, 3))
    for s in range(ids.shape[0]):
        sw = sqrt_w[s]
        mean = np.zeros(3)
        for k in range(8):
            for d in range(3):
                mean[d] += 0.125 * u[s, k, d]
        for k in range(8):
            n = _vertex_columns(s, k, ids, x, c_p, side, off_panel, alpha, own_off, cols, vecs)
            n_e = _rotation_columns(s, k, off_w, off_phi, sqrt_w, targets, d_targets,
                                    ecols, evecs)
            c0 = u[s, k, 0] - mean[0]
            c1 = u[s, k, 1] - mean[1]
            c2 = u[s, k, 2] - mean[2]
            for i in range(n):
                grad[loc_cols[s, cols[i]]] += sw * (vecs[i, 0] * c0 + vecs[i, 1] * c1
                                                    + vecs[i, 2] * c2)
            u0, u1, u2 = u[s, k, 0], u[s, k, 1], u[s, k, 2]
            for i in range(n_e):
                grad[loc_cols[s, ecols[i]]] += evecs[i, 0] * u0 + evecs[i, 1] * u1 \
                    + evecs[i, 2] * u2


TRANSLATION, ROTATION = 0, 3  # column kinds (+ axis 0–2) in ``pattern_keys``'s ``kind``


@njit(cache=True)
def pattern_csc(n_loc, loc_cols, kind, n_columns):
    """CSC pattern (indptr (n + 1,), indices (nnz,), rows sorted) of the lower
    triangle (row ≥ column) of every structural local pair of every block (strip,
    or an extra block such as a panel's 6 × 6), and of every column's diagonal
    (first in its column): JᵀJ is symmetric and CHOLMOD reads only that
    triangle (module docstring). The diagonal is added here rather than as a
    block per column, which padded to ``MAX_LOCAL`` took 0.3 GB at Miura 50 × 50.

    ``kind`` (B, MAX_LOCAL) int: ``TRANSLATION`` + axis for a hinge-interior
    vertex's or a panel's shift column, ``ROTATION`` + axis for the strip's
    rotation column, −1 for the others (panel rotations, angle). Identically
    zero, so left out: two translations along different axes (G's translation
    columns are unit vectors), a translation and the strip's rotation about the
    same axis ([t]× has a zero diagonal). Column by column, blocks merged with a
    marker array: no global sort.
    """
    n_blocks = len(n_loc)
    count = np.zeros(n_columns + 1, dtype=np.int64)
    for b in range(n_blocks):
        for j in range(n_loc[b]):
            count[loc_cols[b, j] + 1] += 1
    col_ptr = np.cumsum(count)
    col_block = np.empty(col_ptr[-1], dtype=np.int64)  # (block, local index) per column
    col_local = np.empty(col_ptr[-1], dtype=np.int64)
    fill = col_ptr[:-1].copy()
    for b in range(n_blocks):
        for j in range(n_loc[b]):
            c = loc_cols[b, j]
            col_block[fill[c]] = b
            col_local[fill[c]] = j
            fill[c] += 1
    mark = np.full(n_columns, -1, dtype=np.int64)
    indptr = np.zeros(n_columns + 1, dtype=np.int64)
    indices = np.empty(0, dtype=np.int64)
    for sweep in range(2):  # count, then fill
        if sweep == 1:
            indices = np.empty(indptr[-1], dtype=np.int64)
            mark[:] = -1
        for c in range(n_columns):
            m = indptr[c]
            mark[c] = c  # the diagonal
            if sweep == 1:
                indices[m] = c
            m += 1
            for q in range(col_ptr[c], col_ptr[c + 1]):
                b, j = col_block[q], col_local[q]
                for i in range(n_loc[b]):
                    row = loc_cols[b, i]
                    if row < c or mark[row] == c or _structural_zero(kind[b, i], kind[b, j]):
                        continue
                    mark[row] = c
                    if sweep == 1:
                        indices[m] = row
                    m += 1
            if sweep == 0:
                indptr[c + 1] = m
            else:
                indices[indptr[c]:m] = np.sort(indices[indptr[c]:m])
    return indptr, indices


@njit(cache=True, inline="always")
def _structural_zero(ki, kj):
    if ki < 0 or kj < 0:
        return False
    if ki < ROTATION and kj < ROTATION:
        return ki != kj
    if ki < ROTATION or kj < ROTATION:  # a translation and the strip's rotation
        return ki % 3 == kj % 3
    return False


@njit(cache=True)
def add_entries(indptr, indices, data, rows, cols, values):
    """data[(row, col)] += value for COO entries (binary search in each CSC column).

    Returns the number of entries with no place in the pattern (left out).
    """
    missing = 0
    for m in range(len(rows)):
        lo, hi = indptr[cols[m]], indptr[cols[m] + 1]
        p = lo + np.searchsorted(indices[lo:hi], rows[m])
        if p < hi and indices[p] == rows[m]:
            data[p] += values[m]
        else:
            missing += 1
    return missing


@njit(parallel=True, cache=True)
def strip_rows(ids, x, rot_e, shape, sqrt_w, targets, residual):
    """Targets R_e t_k and residual rows √w (x_k − x̄ − R_e t_k) of every strip.

    Parameters
    ----------
    ids : (S, 8) int; x : (N, 3) mm; rot_e : (S, 3, 3); shape : (S, 8, 3) mm, centred
    sqrt_w : (S,); targets, residual : (S, 8, 3), written
    """
    for s in prange(ids.shape[0]):
        c0, c1, c2 = centroid(x, ids[s])
        sw = sqrt_w[s]
        for k in range(8):
            t0, t1, t2 = shape[s, k, 0], shape[s, k, 1], shape[s, k, 2]
            for d in range(3):
                value = rot_e[s, d, 0] * t0 + rot_e[s, d, 1] * t1 + rot_e[s, d, 2] * t2
                targets[s, k, d] = value
            residual[s, k, 0] = sw * (x[ids[s, k], 0] - c0 - targets[s, k, 0])
            residual[s, k, 1] = sw * (x[ids[s, k], 1] - c1 - targets[s, k, 1])
            residual[s, k, 2] = sw * (x[ids[s, k], 2] - c2 - targets[s, k, 2])


@njit(parallel=True, cache=True)
def fit_strip_rotations(ids, x, shape, rot_e):
    """Each strip's rotation R maximising tr(Rᵀ Σ_k (x_k − x̄) t_kᵀ) (Procrustes), into
    ``rot_e`` (S, 3, 3); ``shape`` (S, 8, 3) centred, mm."""
    for s in prange(ids.shape[0]):
        c0, c1, c2 = centroid(x, ids[s])
        r00, r01, r02, r10, r11, r12, r20, r21, r22 = fit_about(x, ids[s], shape[s],
                                                                 c0, c1, c2)
        rot_e[s, 0, 0], rot_e[s, 0, 1], rot_e[s, 0, 2] = r00, r01, r02
        rot_e[s, 1, 0], rot_e[s, 1, 1], rot_e[s, 1, 2] = r10, r11, r12
        rot_e[s, 2, 0], rot_e[s, 2, 1], rot_e[s, 2, 2] = r20, r21, r22


@njit(cache=True)
def place_sides(x, known, unknown, shape_known, shape_unknown):
    """Each strip's unknown vertices placed by the rigid motion that best fits its bent
    shape's known side onto where those vertices are (Procrustes about the centroids).

    Parameters
    ----------
    x : (N, 3) mm
        Positions; the rows ``unknown`` are written.
    known, unknown : (b, m) int
        Vertex ids of each strip's placed side and of the side to place.
    shape_known, shape_unknown : (b, m, 3) mm
        The bent shape's points of those sides, both relative to the known side's
        centroid.
    """
    for s in range(known.shape[0]):
        c0, c1, c2 = centroid(x, known[s])
        r00, r01, r02, r10, r11, r12, r20, r21, r22 = fit_about(x, known[s], shape_known[s],
                                                                 c0, c1, c2)
        for k in range(unknown.shape[1]):
            t0, t1, t2 = shape_unknown[s, k, 0], shape_unknown[s, k, 1], shape_unknown[s, k, 2]
            v = unknown[s, k]
            x[v, 0] = r00 * t0 + r01 * t1 + r02 * t2 + c0
            x[v, 1] = r10 * t0 + r11 * t1 + r12 * t2 + c1
            x[v, 2] = r20 * t0 + r21 * t1 + r22 * t2 + c2


@njit(cache=True)
def carry_free(slot, panel, weight, y, c_old, rot_old, rot_new, c_new, out):
    """Free vertices moved by the blend of their panels' rigid motions (old → new).

    out[slot] = Σ weight · (R_new R_oldᵀ (y[slot] − c_old) + c_new) over each
    vertex's carrying panels; ``out`` (F, 3) is overwritten.
    """
    out[:, :] = 0.0
    for m in range(len(slot)):
        v, p, w = slot[m], panel[m], weight[m]
        a0, a1, a2 = y[v, 0] - c_old[p, 0], y[v, 1] - c_old[p, 1], y[v, 2] - c_old[p, 2]
        b0 = rot_old[p, 0, 0] * a0 + rot_old[p, 1, 0] * a1 + rot_old[p, 2, 0] * a2
        b1 = rot_old[p, 0, 1] * a0 + rot_old[p, 1, 1] * a1 + rot_old[p, 2, 1] * a2
        b2 = rot_old[p, 0, 2] * a0 + rot_old[p, 1, 2] * a1 + rot_old[p, 2, 2] * a2
        for d in range(3):
            out[v, d] += w * (rot_new[p, d, 0] * b0 + rot_new[p, d, 1] * b1
                              + rot_new[p, d, 2] * b2 + c_new[p, d])


@njit(cache=True, inline="always")
def _rodrigues(w0, w1, w2):
    """exp([w]×) of one rotation vector (rad), as its 9 entries row by row."""
    angle = math.sqrt(w0 * w0 + w1 * w1 + w2 * w2)
    if angle < 1e-8:
        a, b = 1.0 - angle ** 2 / 6.0, 0.5 - angle ** 2 / 24.0
    else:
        a, b = math.sin(angle) / angle, (1.0 - math.cos(angle)) / angle ** 2
    # I + a K + b K², K = [w]×, K² = w wᵀ − |w|² I
    s = w0 * w0 + w1 * w1 + w2 * w2
    return (1.0 + b * (w0 * w0 - s), -a * w2 + b * w0 * w1, a * w1 + b * w0 * w2,
            a * w2 + b * w1 * w0, 1.0 + b * (w1 * w1 - s), -a * w0 + b * w1 * w2,
            -a * w1 + b * w2 * w0, a * w0 + b * w2 * w1, 1.0 + b * (w2 * w2 - s))


@njit(cache=True)
def rotate_by(w, rot, out):
    """out[i] = exp([w_i]×) rot[i] for (n, 3) rotation vectors (rad) and (n, 3, 3) rotations."""
    for i in range(w.shape[0]):
        e = _rodrigues(w[i, 0], w[i, 1], w[i, 2])
        for r in range(3):
            for c in range(3):
                out[i, r, c] = (e[3 * r] * rot[i, 0, c] + e[3 * r + 1] * rot[i, 1, c]
                                + e[3 * r + 2] * rot[i, 2, c])


@njit(cache=True)
def move_panels(rot_p, c_p, w, panel, body, weight, rot_out, c_out):
    """Panels moved by increments ``w`` (P, 6: rotation vector, rad, and shift, mm).

    Rotations: rot_out = exp([ω]×) rot_p. Centres: c_out = c_p + the weighted
    mean over each panel's joint vertices (``panel`` (N,) their panel, ``body``
    (N, 3) their body-frame offsets, ``weight`` (N,)) of the shift that makes the
    rigid motion meet the linear prediction a + ω × a + t there (a = rot_p · body).
    """
    rotate_by(w[:, :3], rot_p, rot_out)
    c_out[:, :] = 0.0
    total = np.zeros(c_p.shape[0])
    for n in range(panel.shape[0]):
        p = panel[n]
        b0, b1, b2 = body[n, 0], body[n, 1], body[n, 2]
        a0 = rot_p[p, 0, 0] * b0 + rot_p[p, 0, 1] * b1 + rot_p[p, 0, 2] * b2
        a1 = rot_p[p, 1, 0] * b0 + rot_p[p, 1, 1] * b1 + rot_p[p, 1, 2] * b2
        a2 = rot_p[p, 2, 0] * b0 + rot_p[p, 2, 1] * b1 + rot_p[p, 2, 2] * b2
        o0, o1, o2 = w[p, 0], w[p, 1], w[p, 2]
        lin0 = a0 + o1 * a2 - o2 * a1 + w[p, 3]
        lin1 = a1 + o2 * a0 - o0 * a2 + w[p, 4]
        lin2 = a2 + o0 * a1 - o1 * a0 + w[p, 5]
        e = _rodrigues(o0, o1, o2)
        wt = weight[n]
        c_out[p, 0] += wt * (lin0 - (e[0] * a0 + e[1] * a1 + e[2] * a2))
        c_out[p, 1] += wt * (lin1 - (e[3] * a0 + e[4] * a1 + e[5] * a2))
        c_out[p, 2] += wt * (lin2 - (e[6] * a0 + e[7] * a1 + e[8] * a2))
        total[p] += wt
    for p in range(c_p.shape[0]):
        scale = 1.0 / max(total[p], 1e-300)
        for d in range(3):
            c_out[p, d] = c_p[p, d] + c_out[p, d] * scale


@njit(cache=True)
def place_on_panels(rot_p, c_p, vertex, panel, body, x):
    """x[vertex[n]] = rot_p[panel[n]] · body[n] + c_p[panel[n]] (mm)."""
    for n in range(vertex.shape[0]):
        v, p = vertex[n], panel[n]
        for d in range(3):
            x[v, d] = (rot_p[p, d, 0] * body[n, 0] + rot_p[p, d, 1] * body[n, 1]
                       + rot_p[p, d, 2] * body[n, 2] + c_p[p, d])


@njit(cache=True, inline="always")
def mv_side_at(t, wall, slack):
    """(value, slope) of an M/V side row's shape at ``t`` rad (one crease; the
    shape and why: :func:`.residual.mv_side`)."""
    turn = -(wall * math.pi + slack) / (1.0 + wall)  # where the two branches meet
    if t < -slack and t >= turn:
        return t + slack, 1.0
    if t < turn:
        return -(t + math.pi) * wall, -wall
    return 0.0, 0.0


@njit(cache=True)
def mv_terms(rot_p, left, right, axis, sign, sqrt_mv, wall, slack, value, grad):
    """M/V side rows of the creases (C,) between panels ``left`` and ``right``.

    Per crease: d̂ = the unit of (R_L + R_R)·axis (the crease's direction, its
    panels' mean); ρ = atan2((n_R × n_L)·d̂, n_L·n_R), the panels' dihedral
    about d̂ (n = each rotation's third column); the row is √μ·v(sign·ρ) and
    its derivative along the left panel's rotation √μ·sign·v′(sign·ρ)·d̂
    (:func:`mv_side_at`: v, v′).

    Parameters
    ----------
    rot_p : (P, 3, 3) panel rotations
    left, right : (C,) int64 panel of each crease's two sides
    axis : (C, 3) crease direction in the flat pattern, mm
    sign : (C,) +1 valley, −1 mountain
    sqrt_mv : (C,) √ of each row's weight
    wall, slack : the shape's constants (``MV_WALL``, ``MV_SLACK``)
    value : (C,) written: the rows
    grad : (C, 3) written: ∂row/∂ω_L (0 where the row is flat)
    """
    d = np.empty(3)
    for c in range(len(left)):
        rl, rr = rot_p[left[c]], rot_p[right[c]]
        for i in range(3):
            d[i] = (rl[i, 0] + rr[i, 0]) * axis[c, 0] + (rl[i, 1] + rr[i, 1]) * axis[c, 1] \
                + (rl[i, 2] + rr[i, 2]) * axis[c, 2]
        norm = math.sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2])
        for i in range(3):
            d[i] /= norm
        l0, l1, l2 = rl[0, 2], rl[1, 2], rl[2, 2]
        r0, r1, r2 = rr[0, 2], rr[1, 2], rr[2, 2]
        sine = (r1 * l2 - r2 * l1) * d[0] + (r2 * l0 - r0 * l2) * d[1] \
            + (r0 * l1 - r1 * l0) * d[2]
        rho = math.atan2(sine, l0 * r0 + l1 * r1 + l2 * r2)
        v, slope = mv_side_at(sign[c] * rho, wall, slack)
        value[c] = sqrt_mv[c] * v
        scale = sqrt_mv[c] * sign[c] * slope
        for i in range(3):
            grad[c, i] = scale * d[i] if slope != 0.0 else 0.0


@njit(cache=True)
def mv_side_many(t, wall, slack, value, slope):
    """:func:`mv_side_at` at every ``t`` (C,): ``value``, ``slope`` (C,) written."""
    for c in range(len(t)):
        value[c], slope[c] = mv_side_at(t[c], wall, slack)
