"""Stretch hinge: a strip stretched across its width with a Poisson contraction along it (§6.3).

Same 8-vertex strip and local frame as :mod:`elements.bending_hinge` (x across
the width, y through the thickness, z along the crease). Its target is the
rest strip scaled by λ across the width and by λ^(−ν) along the crease (the
thickness is kept), rotated onto the current shape. Actuated by λ; M/V,
fold angles and angle limits do not apply. A passive strip (λ = NaN) takes
λ from its current width (mean of its four width edges over the rest width),
so it resists shear, bending and the length change that does not match its
own Poisson contraction, but not stretching.

Parameters (columns of ``params``): ``width`` W and ``height`` H of the rest
strip (mm), ``ratio`` λ (dimensionless, NaN = passive), ``poisson`` ν
(dimensionless, in [−1, 0.5]). The ratio used is written to ``state[0]``.
"""
import math

from numba import njit, prange

from ._registry import ElementType
from .rotation import fit_rotated
from ._strip import strip_widths

STRETCH_PARAMS = ("width", "height", "ratio", "poisson")
W, H, RATIO, POISSON = range(len(STRETCH_PARAMS))


@njit(cache=True)
def estimate_ratio(x, ids, width):
    """Current width over rest width of a strip (mean of its four width edges)."""
    top, bottom = strip_widths(x, ids)
    return 0.5 * (top + bottom) / width


@njit(cache=True)
def stretched_shape(rest, ratio, poisson, out):
    """Write the rest strip scaled by (λ, 1, λ^(−ν)) in its local frame into ``out``."""
    lateral = ratio ** (-poisson)
    for k in range(rest.shape[0]):
        out[k, 0] = rest[k, 0] * ratio
        out[k, 1] = rest[k, 1]
        out[k, 2] = rest[k, 2] * lateral


@njit(cache=True)
def project(x, ids, rest, params, out, state):
    """Rotated stretched target of one strip; returns its residual (mm²).

    Parameters
    ----------
    x : (N, 3) current positions, mm
    ids : (8,) vertex ids (bending-hinge order)
    rest : (8, 3) centred rest shape in the local frame, mm
    params : (4,) see ``STRETCH_PARAMS``
    out : (8, 3) written: the rotated target, mm
    state : (1,) written: the ratio λ used
    """
    ratio = params[RATIO]
    if math.isnan(ratio):
        ratio = estimate_ratio(x, ids, params[W])
    state[0] = ratio
    stretched_shape(rest, ratio, params[POISSON], out)
    return fit_rotated(x, ids, out, out)


@njit(parallel=True, cache=True)
def batch(x, indptr, indices, rest, params, out, energy, state):
    """Project every stretch strip; ``energy[e]`` residual (mm²), ``state[e, 0]`` λ."""
    for e in prange(len(indptr) - 1):
        s, t = indptr[e], indptr[e + 1]
        energy[e] = project(x, indices[s:t], rest[s:t], params[e], out[s:t], state[e])


class StretchHinge(ElementType):
    """Strip stretched across its width by an actuated ratio, with Poisson contraction."""

    name = "stretch_hinge"
    params = STRETCH_PARAMS
    state = ("ratio",)
    batch = batch
    project = project
