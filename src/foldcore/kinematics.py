"""Zero-thickness rigid-origami closed forms: the ground truth of accuracy tests.

This module is the project's reference for rigid origami: each closed form
is stated in its function's docstring. Core functions take and return
**radians**; the ``*_deg`` wrappers take and return degrees. A fold angle ρ is
the FOLD ``edges_foldAngle`` (deviation from flat, valley > 0, mountain < 0).

Closure convention
------------------
Creases around a vertex are numbered counter-clockwise (seen from +z), each with
its direction ``d_i`` pointing away from the vertex in the flat sheet. Panel i
lies between crease i and crease i+1, i.e. to the *left* of ``d_i``. Holding
panel 0 (before crease 1) fixed, panel k sits at ``R(d_1,ρ_1)···R(d_k,ρ_k)``
(axes in flat-sheet coordinates), so a rigid state satisfies::

    R(d_1, ρ_1) · R(d_2, ρ_2) ··· R(d_n, ρ_n) = I        (product in CCW order)

``R`` is the right-hand rotation, so ρ > 0 lifts the panel on the left of
``d_i`` towards +z: the two panels close over their +z faces, a valley. The
reversed product with the same signs is the mirror image (z → −z) of this one,
so closure alone cannot tell valley from mountain; the sign convention above is
what fixes it. Pehrson's mode-A state (90, 45, 90, −45)° closes.
"""
from __future__ import annotations

import numpy as np
from scipy.optimize import least_squares

__all__ = [
    "rotation", "closure_residual", "degree4_directions", "degree4_mode_a",
    "degree4_mode_b", "degree4_deg", "miura_angles", "miura_angles_deg", "miura_cell",
    "waterbomb_minor", "waterbomb_major", "waterbomb_minor_deg", "waterbomb_major_deg",
    "solve_vertex", "crease_star", "vertex_closure_residuals",
]


# ------------------------------------------------------------------ closure
def rotation(axis, angle: float) -> np.ndarray:
    """(3, 3) right-hand rotation by ``angle`` (radians) about ``axis``.

    Parameters
    ----------
    axis : (3,) or (2,) array_like
        Rotation axis (any non-zero length; a 2D axis lies in the xy-plane).
    angle : float
        Rotation angle in radians, counter-clockwise looking down the axis.
    """
    k = _as_3d(axis)
    k = k / np.linalg.norm(k)
    kx = np.array([[0.0, -k[2], k[1]], [k[2], 0.0, -k[0]], [-k[1], k[0], 0.0]])
    return np.eye(3) + np.sin(angle) * kx + (1.0 - np.cos(angle)) * (kx @ kx)


def closure_residual(directions, rho) -> float:
    """Frobenius norm of ``R(d_1,ρ_1)···R(d_n,ρ_n) − I`` (0 for a rigid state).

    Parameters
    ----------
    directions : (n, 3) or (n, 2) array_like
        Crease directions in the flat sheet, counter-clockwise around the vertex.
    rho : (n,) array_like
        Fold angles in radians, valley positive.
    """
    return float(np.linalg.norm(_closure_product(directions, rho) - np.eye(3)))


def _closure_product(directions, rho) -> np.ndarray:
    product = np.eye(3)
    for d, r in zip(np.asarray(directions, dtype=float), np.asarray(rho, dtype=float)):
        product = product @ rotation(d, r)
    return product


def _as_3d(v) -> np.ndarray:
    v = np.asarray(v, dtype=float)
    return np.append(v, 0.0) if v.shape == (2,) else v


# ---------------------------------------------------------- degree-4 vertex
def degree4_directions(alpha: float, beta: float) -> np.ndarray:
    """(4, 3) crease directions of a flat-foldable degree-4 vertex.

    Sectors (α, β, π−α, π−β) in radians; crease 1 along +x, then CCW at
    angles 0, α, α+β, π+β. Crease 1 lies between sector 4 and sector 1.
    """
    phi = np.array([0.0, alpha, alpha + beta, np.pi + beta])
    return np.stack([np.cos(phi), np.sin(phi), np.zeros(4)], axis=1)


def degree4_mode_a(alpha: float, beta: float, rho1) -> np.ndarray:
    """Mode A of a flat-foldable degree-4 vertex: ρ3 = ρ1, ρ4 = −ρ2.

    ``tan(ρ2/2) = −cos((α+β)/2) / cos((α−β)/2) · tan(ρ1/2)``.

    Parameters
    ----------
    alpha, beta : float
        Sectors 1 and 2 in radians (sectors are (α, β, π−α, π−β)).
    rho1 : float or array_like
        Fold angle of crease 1 in radians, in [−π, π].

    Returns
    -------
    (..., 4) ndarray
        (ρ1, ρ2, ρ3, ρ4) in radians, valley positive.
    """
    ratio = -np.cos((alpha + beta) / 2) / np.cos((alpha - beta) / 2)
    rho1 = np.asarray(rho1, dtype=float)
    rho2 = _scaled_half_tan(ratio, rho1)
    return np.stack([rho1, rho2, rho1, -rho2], axis=-1)


def degree4_mode_b(alpha: float, beta: float, rho1) -> np.ndarray:
    """Mode B of a flat-foldable degree-4 vertex: ρ3 = −ρ1, ρ4 = ρ2.

    ``tan(ρ2/2) = sin((α+β)/2) / sin((α−β)/2) · tan(ρ1/2)``. Degenerate for
    α = β (creases 2 and 4 collinear; the mode is a fold along them, ρ1 = 0).

    Parameters
    ----------
    alpha, beta : float
        Sectors 1 and 2 in radians (sectors are (α, β, π−α, π−β)), α ≠ β.
    rho1 : float or array_like
        Fold angle of crease 1 in radians, in [−π, π].

    Returns
    -------
    (..., 4) ndarray
        (ρ1, ρ2, ρ3, ρ4) in radians, valley positive.
    """
    ratio = np.sin((alpha + beta) / 2) / np.sin((alpha - beta) / 2)
    rho1 = np.asarray(rho1, dtype=float)
    rho2 = _scaled_half_tan(ratio, rho1)
    return np.stack([rho1, rho2, -rho1, rho2], axis=-1)


def _scaled_half_tan(ratio: float, rho):
    """ρ' with tan(ρ'/2) = ratio · tan(ρ/2), exact at ρ = ±π (radians)."""
    return 2.0 * np.arctan2(ratio * np.sin(rho / 2), np.cos(rho / 2))


def degree4_deg(alpha: float, beta: float, rho1, mode: str = "A") -> np.ndarray:
    """Degree wrapper of :func:`degree4_mode_a` / :func:`degree4_mode_b`.

    ``alpha``, ``beta``, ``rho1`` and the returned (..., 4) angles in degrees.
    """
    fn = {"A": degree4_mode_a, "B": degree4_mode_b}[mode.upper()]
    return np.degrees(fn(np.radians(alpha), np.radians(beta), np.radians(rho1)))


# --------------------------------------------------------------- Miura-ori
def miura_angles(gamma: float, theta) -> tuple:
    """Fold magnitudes of a Miura-ori at facet tilt θ (radians in and out).

    Parameters
    ----------
    gamma : float
        Acute parallelogram angle γ in radians, in (0, π/2).
    theta : float or array_like
        Dihedral between a facet and the xy-plane, radians, in [0, π/2].

    Returns
    -------
    rho_zigzag_abs, rho_straight_abs : float or ndarray
        |ρ| of the zig-zag creases (b-edges) = 2θ and of the straight creases
        (a-edges), tan(|ρ_s|/2) = cos γ · tan θ; radians.
    """
    theta = np.asarray(theta, dtype=float)
    straight = 2.0 * np.arctan2(np.cos(gamma) * np.sin(theta), np.cos(theta))
    return 2.0 * theta, straight


def miura_angles_deg(gamma: float, theta) -> tuple:
    """Degree wrapper of :func:`miura_angles` (γ, θ and results in degrees)."""
    z, s = miura_angles(np.radians(gamma), np.radians(theta))
    return np.degrees(z), np.degrees(s)


def miura_cell(a: float, b: float, gamma: float, theta: float) -> tuple:
    """Miura unit-cell dimensions (H, S, L, V) in the units of ``a``, ``b``.

    γ and θ in radians. H = a sinθ sinγ (height), L = a√(1 − sin²θ sin²γ),
    V = b/√(1 + cos²θ tan²γ), S = b cosθ tanγ/√(1 + cos²θ tan²γ).
    """
    root = np.sqrt(1.0 + np.cos(theta) ** 2 * np.tan(gamma) ** 2)
    height = a * np.sin(theta) * np.sin(gamma)
    length = a * np.sqrt(1.0 - np.sin(theta) ** 2 * np.sin(gamma) ** 2)
    return height, b * np.cos(theta) * np.tan(gamma) / root, length, b / root


# --------------------------------------------------------------- waterbomb
def waterbomb_minor(n_creases: int, major) -> np.ndarray:
    """Minor fold magnitude of a symmetric waterbomb base (radians in and out).

    Solves ``cos(π/n)(1 − cos x cos y) = sin x sin y`` (n = n_creases/2,
    x = |major|/2, y = |minor|/2) in closed form: the left side minus the right
    is ``c − A cos(y − φ)`` with A = √(c²cos²x + sin²x), φ = atan2(sin x, c cos x),
    so y = φ − arccos(c/A) (the smaller root). Valid on either branch
    (mountain-major or valley-major); at |major| = π the minor is π − 2π/n.
    With 4 creases the minor is always 0 (the vertex can only fold along a line).

    Parameters
    ----------
    n_creases : int
        Total number of creases (even, ≥ 4); sectors are 2π/n_creases.
    major : float or array_like
        Major fold magnitude in radians, in [0, π].
    """
    return _waterbomb_other(n_creases, major, sign=-1.0)


def waterbomb_major(n_creases: int, minor) -> np.ndarray:
    """Major fold magnitude for a given minor one (inverse of
    :func:`waterbomb_minor`; radians, minor in [0, π − 4π/n_creases])."""
    return _waterbomb_other(n_creases, minor, sign=1.0)


def _waterbomb_other(n_creases: int, fold, sign: float) -> np.ndarray:
    if n_creases < 4 or n_creases % 2:
        raise ValueError(f"a waterbomb base needs an even number ≥ 4 of creases, "
                         f"got {n_creases}")
    c = np.cos(2.0 * np.pi / n_creases)
    x = np.abs(np.asarray(fold, dtype=float)) / 2.0
    amp = np.hypot(c * np.cos(x), np.sin(x))
    phi = np.arctan2(np.sin(x), c * np.cos(x))
    return 2.0 * (phi + sign * np.arccos(np.clip(c / amp, -1.0, 1.0)))


def waterbomb_minor_deg(n_creases: int, major):
    """Degree wrapper of :func:`waterbomb_minor`."""
    return np.degrees(waterbomb_minor(n_creases, np.radians(major)))


def waterbomb_major_deg(n_creases: int, minor):
    """Degree wrapper of :func:`waterbomb_major`."""
    return np.degrees(waterbomb_major(n_creases, np.radians(minor)))


# ----------------------------------------------------------- numeric vertex
def solve_vertex(directions, rho_known: dict, guess) -> np.ndarray:
    """Fold angles closing one vertex, some of them prescribed (radians).

    A degree-n vertex has n − 3 degrees of freedom: prescribe at least n − 3
    angles in ``rho_known``; the rest are found by least squares on the closure
    matrix, starting from ``guess`` (the flat state is singular, so the guess
    picks the branch — e.g. the signs of the assignment).

    Parameters
    ----------
    directions : (n, 3) or (n, 2) array_like
        Crease directions, counter-clockwise.
    rho_known : dict of int to float
        Crease index (0-based) → fixed fold angle, radians.
    guess : (n,) array_like
        Starting fold angles, radians (entries in ``rho_known`` are ignored).

    Returns
    -------
    (n,) ndarray
        Fold angles in radians; check :func:`closure_residual` for success.
    """
    rho = np.asarray(guess, dtype=float).copy()
    for i, value in rho_known.items():
        rho[i] = value
    free = np.array([i for i in range(len(rho)) if i not in rho_known], dtype=int)
    if free.size == 0:
        return rho

    def residual(x):
        trial = rho.copy()
        trial[free] = x
        return (_closure_product(directions, trial) - np.eye(3)).ravel()

    rho[free] = least_squares(residual, rho[free], xtol=1e-15, ftol=1e-15, gtol=1e-15).x
    return rho


# ------------------------------------------------------- crease patterns
def crease_star(pattern, vertex: int) -> tuple:
    """Edges at a vertex of a :class:`~foldcore.pattern.CreasePattern`, CCW.

    Returns
    -------
    edge_ids : (k,) int ndarray
        Incident edges sorted counter-clockwise by angle (from −x, atan2 order).
    directions : (k, 3) ndarray
        Unit directions pointing away from ``vertex`` (z = 0).
    """
    edge_ids = np.flatnonzero((pattern.edges == vertex).any(axis=1))
    ends = pattern.edges[edge_ids]
    other = np.where(ends[:, 0] == vertex, ends[:, 1], ends[:, 0])
    d = pattern.vertices[other] - pattern.vertices[vertex]
    order = np.argsort(np.arctan2(d[:, 1], d[:, 0]), kind="stable")
    d = d[order] / np.hypot(d[order, 0], d[order, 1])[:, None]
    return edge_ids[order], np.column_stack([d, np.zeros(len(d))])


def vertex_closure_residuals(pattern, rho) -> dict:
    """Closure residual at every interior vertex of a crease pattern.

    Parameters
    ----------
    pattern : CreasePattern
    rho : (E,) array_like
        Fold angle per edge in radians, valley positive (boundary edges ignored).

    Returns
    -------
    dict of int to float
        Interior vertex id (all incident edges are creases) → residual.
    """
    rho = np.asarray(rho, dtype=float)
    out = {}
    for v in range(pattern.n_vertices):
        edge_ids, directions = crease_star(pattern, v)
        if np.all(pattern.assignments[edge_ids] != "B"):
            out[v] = closure_residual(directions, rho[edge_ids])
    return out
