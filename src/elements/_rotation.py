"""Shared numba helpers for element kernels: centroid and optimal rotation."""
import numpy as np
from numba import njit


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
def centroid(x, ids):
    """Mean (3,) of the rows ``x[ids]``."""
    c = np.zeros(3)
    for i in ids:
        for d in range(3):
            c[d] += x[i, d]
    return c / len(ids)


@njit(cache=True)
def fit_rotated(x, ids, target, out):
    """Write R·target (rotated to fit x[ids]) into ``out``; return the residual.

    ``target`` (m, 3) must be centred. The residual is Σ‖(x − c) − R·target‖²
    in mm², the element's unweighted energy.
    """
    c = centroid(x, ids)
    cov = np.zeros((3, 3))
    for k in range(len(ids)):
        for a in range(3):
            for b in range(3):
                cov[a, b] += (x[ids[k], a] - c[a]) * target[k, b]
    r = best_rotation(cov)
    residual = 0.0
    for k in range(len(ids)):
        for a in range(3):
            out[k, a] = r[a, 0] * target[k, 0] + r[a, 1] * target[k, 1] + r[a, 2] * target[k, 2]
            residual += (x[ids[k], a] - c[a] - out[k, a]) ** 2
    return residual
