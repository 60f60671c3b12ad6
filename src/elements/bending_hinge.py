"""Bending hinge sub-strip: a 4-sided prism bent about its long axis (paper §4.1–4.3).

Vertex order and local frame (x across the width toward the left panel, y up
through the thickness, z along the crease from its end a to end b)::

     top (y = +H/2)            bottom (y = -H/2)
      3 ───────── 2             7 ───────── 6      end b
      │           │             │           │
      0 ───────── 1             4 ───────── 5      end a
     left       right

Parameters (columns of ``params``, angles per sub-strip in radians):

* ``width`` W and ``height`` H of the rest strip, mm;
* ``target`` bend angle φ (valley > 0), NaN for a passive strip;
* ``sign`` +1 valley, −1 mountain, 0 unassigned (passive strips are clamped to
  their sign's side, §4.2);
* ``max_angle`` largest |φ| (§4.3); ``floor`` smallest |φ| a passive M/V strip
  is given when its estimate has the wrong sign;
* ``model``: ``AXIS`` (2) arc whose neutral axis shortens so the panels turn
  about the crease's mid-line (:func:`axis_length`), ``ARC`` (1) circular
  arc of constant neutral-axis length (the paper's), ``EQ8`` (0) Eq. 8's
  trapezoid (end faces sheared, error O(φ²)); why: :mod:`foldcore.hinges`;
* ``strips`` k, sub-strips in series across the crease, and ``series`` this
  strip's place among them (0 … k−1; the k are consecutive elements): the
  axis model shortens each strip for its crease's total bend θ, the sum of
  the k strips' angles (:func:`series_bend`).

A passive strip's angle is estimated from its current shape by Eq. 9,
θ = 2·atan((W_b − W_t) / (2 H_p)), with H_p the *perpendicular* height
√(s² − ((W_b − W_t)/2)²) recovered from the mean end-face length s (the end
faces of an Eq. 8 trapezoid are slanted, s = H / cos(θ/2); the paper's H_p = s
would return 2·atan(sin(θ/2)) instead of θ). Equivalently θ = 2·asin((W_b − W_t)
/ (2s)), which also inverts every arc (radial end faces, s = H, and
W_b − W_t = 2H·sin(θ/2) whatever the arc's length), so all three targets are
fixed points of their own estimate. The angle used is written to
``state[0]``.
"""
import math

import numpy as np

from numba import njit, prange

from ._registry import ElementType
from .rotation import fit_rotated
from ._strip import distance, strip_widths

HINGE_PARAMS = ("width", "height", "target", "sign", "max_angle", "floor", "model", "strips",
                "series")
W, H, TARGET, SIGN, MAX_ANGLE, FLOOR, MODEL, STRIPS, SERIES = range(len(HINGE_PARAMS))
EQ8, ARC, AXIS, SLACK = 0.0, 1.0, 2.0, 3.0  # ``model`` codes (foldcore.hinges.HINGE_MODELS order)
PIVOT_BLEND = 0.05  # width (× w) of the band in which the axis hinge turns into pivoting


@njit(cache=True)
def estimate_angle(x, ids):
    """Bend angle (rad, valley > 0) of a strip from its current shape (Eq. 9).

    H_p is the perpendicular height √(s² − d²), s the mean end-face length and
    d = (W_b − W_t)/2, so Eq. 8 trapezoids and every arc (axis or constant
    length) return their θ.
    """
    w_top, w_bot = strip_widths(x, ids)
    s = 0.25 * (distance(x, ids[0], ids[4]) + distance(x, ids[1], ids[5])
                + distance(x, ids[2], ids[6]) + distance(x, ids[3], ids[7]))
    d = 0.5 * (w_bot - w_top)
    return 2.0 * math.atan2(d, math.sqrt(max(s * s - d * d, 0.0)))


@njit(parallel=True, cache=True)
def estimate_angles(x, indptr, indices, out):
    """Eq. 9 estimate (rad, valley > 0) of every strip's bend angle into ``out`` (S,)."""
    for e in prange(len(indptr) - 1):
        out[e] = estimate_angle(x, indices[indptr[e]:indptr[e + 1]])


@njit(cache=True)
def clamp_angle(phi, sign, floor, max_angle):
    """Project a passive strip's angle onto its allowed interval (§4.2–4.3)."""
    if sign > 0.0:
        return min(max(phi, floor), max_angle)
    if sign < 0.0:
        return max(min(phi, -floor), -max_angle)
    return min(max(phi, -max_angle), max_angle)


@njit(cache=True)
def limit_excess(x, indptr, indices, params, out):
    """Signed distance (rad) of each passive strip's Eq. 9 estimate past its max angle.

    ``out[e]`` > 0: the strip is bent beyond ``max_angle`` on its allowed side
    (valley for V, mountain for M, either for U) by that much; ≤ 0: by how much
    it is short of it; NaN for actuated strips. Only the max-angle side is a
    physical stop (the joint closes); the M/V side is left to the projection
    (§4.2) because strips pass through flat transiently while a pattern folds,
    and a stiff flat strip there jams the fold (measured). Serial loop: it runs
    once per iteration, where a parallel launch costs more.
    """
    for e in range(len(indptr) - 1):
        p = params[e]
        if math.isnan(p[TARGET]):
            phi = estimate_angle(x, indices[indptr[e]:indptr[e + 1]])
            if p[SIGN] < 0.0:
                phi = -phi
            elif p[SIGN] == 0.0:
                phi = abs(phi)
            out[e] = phi - p[MAX_ANGLE]
        else:
            out[e] = math.nan


@njit(cache=True)
def axis_length(width, height, phi, theta):
    """Neutral-axis length (mm) of an axis-true sub-strip of width w bent by φ (rad).

    w·f(θ), f(θ) = (θ/2)/tan(θ/2), θ the bend of its whole crease (the sum
    over its series of sub-strips): when the k sub-strips bend alike an arc
    of that length has the end faces of a rotation by θ about the crease's
    mid-line (same chord W·cos(θ/2), same directions). Never below H·|φ|/2,
    the length at which the strip's inner surface has radius 0: from
    θ* = 2·atan(W/H) on (the panels' inner edges touch there) the strip
    pivots about its inner surface instead, so flat panels stack H apart
    instead of overlapping. The switch is rounded (:func:`smooth_max`) where
    the two lengths are within ``PIVOT_BLEND`` × w of each other (a few
    degrees about θ*).
    """
    half = 0.5 * theta
    if abs(half) < 1e-4:
        f = 1.0 - half * half / 3.0
    else:
        f = half * math.cos(half) / math.sin(half)
    return smooth_max(width * f, 0.5 * height * abs(phi), PIVOT_BLEND * width)


@njit(cache=True)
def smooth_max(a, b, delta):
    """max(a, b), rounded over |a − b| < δ by the parabola that joins both lines with
    matching slopes (C¹): the axis hinge's switch to pivoting has no kink for the
    Gauss–Newton steps to stall at, and is exact outside that band."""
    gap = a - b
    if abs(gap) >= delta:
        return max(a, b)
    return 0.5 * (a + b) + gap * gap / (4.0 * delta) + 0.25 * delta


@njit(cache=True)
def bent_shape(rest, width, height, phi, model, theta, out):
    """Write the strip bent by ``phi`` (rad) into ``out`` (m, 3), centred, local frame.

    ``model``: ``EQ8`` trapezoid, ``ARC`` (neutral axis keeps its length w) or
    ``AXIS`` (neutral axis of :func:`axis_length`, ``theta`` the crease's
    bend). Arcs: a point at (x, y) goes to ((1 − κy) sin ψ / κ,
    2 sin²(ψ/2)/κ + y cos ψ), ψ = φx/w, κ = φ/ℓ (ℓ the neutral-axis length),
    from s = sin(ψ/2), c = cos(ψ/2) (sin ψ = 2sc, cos ψ = 1 − 2s², no
    cancellation at small ψ); the pair is computed once per distinct rest x
    (a strip has two: its vertices share x across the thickness and along the
    crease) and kept in ``out``'s rows meanwhile.
    """
    if model != EQ8 and abs(phi) >= 1e-12:
        length = width if model == ARC else axis_length(width, height, phi, theta)
        arc_shape(rest, width, phi, length, out)
    else:
        for k in range(rest.shape[0]):
            x, y = rest[k, 0], rest[k, 1]
            out[k, 0] = x * (1.0 - 2.0 * y / width * math.tan(0.5 * phi)) if model == EQ8 else x
            out[k, 1] = y
            out[k, 2] = rest[k, 2]
        centre(out)


@njit(cache=True)
def arc_shape(rest, width, phi, length, out):
    """Write the strip bent by ``phi`` (rad, ≠ 0) along a neutral axis of ``length``
    (mm) into ``out`` (m, 3), centred, local frame (see :func:`bent_shape`)."""
    m = rest.shape[0]
    turn = phi / width  # ψ per mm of rest x
    kappa = phi / length
    for k in range(m):  # pass 1: (sin ψ, cos ψ, 2 sin²(ψ/2)) per vertex
        shared = -1
        for j in range(k):
            if rest[j, 0] == rest[k, 0]:
                shared = j
                break
        if shared >= 0:
            out[k, 0], out[k, 1], out[k, 2] = out[shared, 0], out[shared, 1], out[shared, 2]
        else:
            half = 0.5 * turn * rest[k, 0]
            sh, ch = math.sin(half), math.cos(half)
            out[k, 0], out[k, 1], out[k, 2] = 2.0 * sh * ch, 1.0 - 2.0 * sh * sh, 2.0 * sh * sh
    for k in range(m):  # pass 2: the bent point
        y = rest[k, 1]
        sin_psi, cos_psi, versine = out[k, 0], out[k, 1], out[k, 2]
        out[k, 0] = (1.0 - kappa * y) * sin_psi / kappa
        out[k, 1] = versine / kappa + y * cos_psi
        out[k, 2] = rest[k, 2]
    centre(out)


@njit(cache=True)
def centre(out):
    """Shift ``out`` (m, 3) so its x and y means are 0 (the local frame's origin)."""
    m = out.shape[0]
    for d in range(2):
        mean = 0.0
        for k in range(m):
            mean += out[k, d]
        for k in range(m):
            out[k, d] -= mean / m


@njit(cache=True)
def neutral_chord(x, ids):
    """Distance (mm) between the centres of a strip's two end faces (vertices 0, 3,
    4, 7 on the left, 1, 2, 5, 6 on the right): the chord of its neutral axis."""
    total = 0.0
    for d in range(3):
        left = x[ids[0], d] + x[ids[3], d] + x[ids[4], d] + x[ids[7], d]
        right = x[ids[1], d] + x[ids[2], d] + x[ids[5], d] + x[ids[6], d]
        total += (0.25 * (right - left)) ** 2
    return math.sqrt(total)


@njit(cache=True)
def slack_length(x, ids, width, height, phi, theta):
    """Neutral-axis length (mm) a ``SLACK`` sub-strip is projected with: the length
    of the arc bent by φ on its current neutral chord c, ℓ = c·(φ/2)/sin(φ/2),
    kept between the axis hinge's (:func:`axis_length`: the shortest, panels
    turning about the crease's mid-line) and max(w, H·|φ|/2) (no longer than
    its rest width, unless its inner surface would need a radius below 0)."""
    low = axis_length(width, height, phi, theta)
    high = max(width, 0.5 * height * abs(phi), low)
    half = 0.5 * phi
    chord = neutral_chord(x, ids)
    length = chord if abs(half) < 1e-6 else chord * half / math.sin(half)
    return min(max(length, low), high)


@njit(cache=True)
def bend_from(x, ids, rest, params, phi, theta, out):
    """:func:`bend`, a ``SLACK`` strip with the length :func:`slack_length` reads
    from its current shape ``x[ids]``."""
    if params[MODEL] == SLACK and abs(phi) >= 1e-12:
        arc_shape(rest, params[W], phi,
                  slack_length(x, ids, params[W], params[H], phi, theta), out)
    else:
        bend(rest, params, phi, theta, out)


@njit(cache=True)
def bend(rest, params, phi, theta, out):
    """:func:`bent_shape` with a strip's own parameters (``HINGE_PARAMS``)."""
    bent_shape(rest, params[W], params[H], phi, params[MODEL], theta, out)


@njit(cache=True)
def strip_angle(x, ids, params):
    """Bend angle (rad) a strip is projected with: its target, or (passive) its
    Eq. 9 estimate clamped to its interval."""
    phi = params[TARGET]
    if math.isnan(phi):
        phi = clamp_angle(estimate_angle(x, ids), params[SIGN], params[FLOOR],
                          params[MAX_ANGLE])
    return phi


@njit(cache=True)
def series_bend(angles, params, e):
    """θ (rad): the bend of strip ``e``'s whole crease, the sum of ``angles[j, 0]``
    over its series of ``strips`` sub-strips (consecutive elements, ``series``
    its place in them); an actuated strip's crease bends ``strips`` × its target.
    A series that does not fit the group is taken as bending alike (k·φ)."""
    p = params[e]
    k = int(p[STRIPS])
    first = e - int(p[SERIES])
    if not math.isnan(p[TARGET]) or first < 0 or first + k > len(angles):
        return k * angles[e, 0]
    total = 0.0
    for j in range(first, first + k):
        total += angles[j, 0]
    return total


@njit(cache=True)
def project(x, ids, rest, params, out, state):
    """Rotated bent target of one sub-strip, its crease bending alike (θ = kφ);
    returns its residual (mm²). :func:`batch` takes θ from the strip's series.

    Parameters
    ----------
    x : (N, 3) current positions, mm
    ids : (8,) vertex ids in the order drawn in the module docstring
    rest : (8, 3) centred rest shape in the local frame, mm
    params : (9,) see ``HINGE_PARAMS``
    out : (8, 3) written: the rotated target, mm (holds the unrotated one first)
    state : (1,) written: the bend angle used, rad
    """
    phi = strip_angle(x, ids, params)
    state[0] = phi
    bend_from(x, ids, rest, params, phi, params[STRIPS] * phi, out)
    return fit_rotated(x, ids, out, out)


@njit(cache=True)
def project_in_series(x, ids, rest, params, angles, e, out):
    """Rotated target of strip ``e`` bent by ``angles[e, 0]`` for its crease's bend
    (:func:`series_bend` over ``angles``), written to ``out``; its residual (mm²)."""
    bend_from(x, ids, rest, params[e], angles[e, 0], series_bend(angles, params, e), out)
    return fit_rotated(x, ids, out, out)


@njit(parallel=True, cache=True)
def batch(x, indptr, indices, rest, params, out, energy, state):
    """Project every sub-strip; ``energy[e]`` residual (mm²), ``state[e, 0]`` angle (rad).

    Two passes: every strip's angle first (``state``), then every target from
    its angle and its crease's bend (:func:`series_bend`), so a passive
    crease whose sub-strips bend unequally shortens each of them for the
    crease's total bend, not k times its own.
    """
    for e in prange(len(indptr) - 1):
        state[e, 0] = strip_angle(x, indices[indptr[e]:indptr[e + 1]], params[e])
    for e in prange(len(indptr) - 1):
        s, t = indptr[e], indptr[e + 1]
        energy[e] = project_in_series(x, indices[s:t], rest[s:t], params, state, e, out[s:t])


@njit(parallel=True, cache=True)
def prepare(indptr, rest, params, shapes):
    """Bent shape of every actuated strip into its rows of ``shapes`` (nnz, 3), mm.

    Local frame, centred, as :func:`batch` makes it: an actuated strip's
    target depends on its parameters only, so the engine computes it here
    once per change of targets instead of every iteration
    (docs/architecture.md#prepared-shapes-of-actuated-strips). Passive strips' rows
    are not written.
    """
    for e in prange(len(indptr) - 1):
        phi = params[e, TARGET]
        if not math.isnan(phi):
            s, t = indptr[e], indptr[e + 1]
            bend(rest[s:t], params[e], phi, params[e, STRIPS] * phi, shapes[s:t])


@njit(parallel=True, cache=True)
def prepared_batch(x, indptr, indices, rest, shapes, params, out, energy, state):
    """:func:`batch` with the actuated strips' bent shapes taken from ``shapes``
    (same arithmetic, so the same result to the last bit)."""
    for e in prange(len(indptr) - 1):
        state[e, 0] = strip_angle(x, indices[indptr[e]:indptr[e + 1]], params[e])
    for e in prange(len(indptr) - 1):
        s, t = indptr[e], indptr[e + 1]
        if math.isnan(params[e, TARGET]) or params[e, MODEL] == SLACK:
            energy[e] = project_in_series(x, indices[s:t], rest[s:t], params, state, e,
                                          out[s:t])
        else:
            energy[e] = fit_rotated(x, indices[s:t], shapes[s:t], out[s:t])


@njit(parallel=True, cache=True)
def slack_lengths(x, indptr, indices, params, phi, out):
    """Neutral-axis length (mm) of every ``SLACK`` sub-strip bent by ``phi`` (S,) rad,
    its crease's strips alike (:func:`slack_length`), into ``out`` (S,); NaN for
    strips of other models."""
    for e in prange(len(indptr) - 1):
        p = params[e]
        if p[MODEL] != SLACK:
            out[e] = math.nan
            continue
        out[e] = slack_length(x, indices[indptr[e]:indptr[e + 1]], p[W], p[H], phi[e],
                              p[STRIPS] * phi[e])


SLACK_STEP = 1e-6  # × w, central-difference step of :func:`slack_directions`


@njit(parallel=True, cache=True)
def slack_directions(x, indptr, indices, rest, params, state, out):
    """How each free ``SLACK`` sub-strip's projection moves per mm of its length.

    For solvers that linearise the projections (``newton``): a slack strip's
    target follows its own length between the bounds of :func:`slack_length`,
    a freedom its rotations alone do not span. Central difference (step
    ``SLACK_STEP`` × w) of the rotated target at the state's angles.

    Parameters
    ----------
    x : (N, 3) positions, mm
    indptr, indices : the group's slots
    rest : (nnz, 3) centred rest shapes, mm
    params : (S, 9) see ``HINGE_PARAMS``
    state : (S, 1) angles of the last projection, rad
    out : (nnz, 3) written: d(R·T)/dℓ (dimensionless), zero for strips of
        other models and slack strips held at a bound
    """
    for e in prange(len(indptr) - 1):
        s, t = indptr[e], indptr[e + 1]
        for k in range(s, t):
            out[k, 0], out[k, 1], out[k, 2] = 0.0, 0.0, 0.0
        p = params[e]
        phi = state[e, 0]
        if p[MODEL] != SLACK or abs(phi) < 1e-12:
            continue
        ids = indices[s:t]
        theta = series_bend(state, params, e)
        length = slack_length(x, ids, p[W], p[H], phi, theta)
        low = axis_length(p[W], p[H], phi, theta)
        high = max(p[W], 0.5 * p[H] * abs(phi), low)
        step = SLACK_STEP * p[W]
        if length - step <= low or length + step >= high:
            continue
        up = np.empty((t - s, 3))
        down = np.empty((t - s, 3))
        arc_shape(rest[s:t], p[W], phi, length + step, up)
        arc_shape(rest[s:t], p[W], phi, length - step, down)
        fit_rotated(x, ids, up, up)
        fit_rotated(x, ids, down, down)
        for k in range(t - s):
            for d in range(3):
                out[s + k, d] = (up[k, d] - down[k, d]) / (2.0 * step)


SHAPE_STEP = 1e-6  # rad, central-difference step of :func:`shape_derivatives`


@njit(parallel=True, cache=True)
def bent_shapes(indptr, rest, params, phi, out):
    """Bent shapes T(φ) of every sub-strip (local frame), for the rigid-body
    strategy; their derivative is :func:`shape_derivatives`, apart, because
    most of that strategy's shape updates are energy evaluations that need no
    Jacobian.

    Parameters
    ----------
    indptr : (S+1,) int64, slots of each strip
    rest : (nnz, 3) centred rest shapes, mm
    params : (S, 9) see ``HINGE_PARAMS``
    phi : (S,) bend angle per strip, rad
    out : (nnz, 3) written: T(φ), mm
    """
    for e in prange(len(indptr) - 1):
        s, t = indptr[e], indptr[e + 1]
        bend(rest[s:t], params[e], phi[e], params[e, STRIPS] * phi[e], out[s:t])


@njit(parallel=True, cache=True)
def shape_derivatives(indptr, rest, params, phi, scratch, d_out):
    """Derivatives dT/dφ of every sub-strip's bent shape (local frame).

    For solvers that treat each strip's bend angle as an unknown (the
    rigid-body strategy; its shapes T(φ) come from :func:`bent_shapes`).
    dT/dφ is a central difference of :func:`bent_shape` with step
    ``SHAPE_STEP`` (truncation ~1e-12·W, round-off ~1e-10·W: ample for a
    Jacobian), so it stays consistent with the target whatever the shape
    rule. Allocates nothing.

    Parameters
    ----------
    indptr : (S+1,) int64, slots of each strip
    rest : (nnz, 3) centred rest shapes, mm
    params : (S, 9) see ``HINGE_PARAMS``
    phi : (S,) bend angle per strip, rad (the strips of a crease alike)
    scratch : (nnz, 3) overwritten (the shapes at φ − ``SHAPE_STEP``), mm
    d_out : (nnz, 3) written: dT/dφ, mm/rad
    """
    for e in prange(len(indptr) - 1):
        s, t = indptr[e], indptr[e + 1]
        strips = params[e, STRIPS]  # the rigid strategy bends a crease's strips alike
        up, down = phi[e] + SHAPE_STEP, phi[e] - SHAPE_STEP
        bend(rest[s:t], params[e], up, strips * up, d_out[s:t])
        bend(rest[s:t], params[e], down, strips * down, scratch[s:t])
        for k in range(s, t):
            for d in range(3):
                d_out[k, d] = (d_out[k, d] - scratch[k, d]) / (2.0 * SHAPE_STEP)


class BendingHinge(ElementType):
    """Hinge sub-strip bent to a target (actuated) or estimated (passive) angle."""

    name = "bending_hinge"
    params = HINGE_PARAMS
    state = ("angle",)
    batch = batch
    project = project
    prepare = prepare
    prepared_batch = prepared_batch
