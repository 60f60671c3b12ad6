"""Hinge models: how a thick hinge strip turns the two panels it joins.

A crease of width W in a sheet of thickness H becomes k sub-strips, each a
prism bent by φ (θ = kφ for the crease). Where the panels go is decided by
the bent shape of the strip's end faces — a modelling choice, and one that
decides whether thick vertices can fold at all. Four models
(``thicken(..., hinge=...)``, ``--hinge``, FOLD ``foldcore:edges_hinge``);
measured figures for each: docs/architecture.md#hinge-models-in-numbers.

``"axis"`` (default) — the panels turn about the crease's mid-line.
    The strip is an arc whose neutral axis has the length W·f(θ),
    f(θ) = (θ/2)/tan(θ/2): then its end faces are exactly those of a
    rotation by θ about the crease's mid-line (chord W·cos(θ/2), same
    directions), so the panels move as in rigid origami at any thickness:
    the hinge axes of a vertex meet at the vertex and every rigid-foldable
    pattern folds without strain. The price is that the strip shortens as
    it bends (1 − f: 21 % at 90°), and that f → 0 at 180°, where
    flat-folded panels would share their mid-line and overlap by H.
    So the neutral axis is never shorter than H·|φ|/2, the length at which
    the strip's inner surface has radius 0: from θ* = 2·atan(W/H) on —
    exactly where the panels' inner edges touch (tan(θ*/2) = W/H) — the
    strip pivots about its inner surface instead, and flat panels stack H
    apart, face to face, without overlapping. Past θ* the panels turn about
    their touching inner edges, a line off the crease's mid-line, so a
    vertex whose creases fold past their θ* binds like the arc model does:
    the report lists those creases (``hinges.pivoting_edges``) and how far
    the strips miss their shapes (``hinges.largest_misfit_mm``).

    The k sub-strips of a crease are a series: each is shortened for the
    crease's total bend θ (the sum of their angles), not k times its own
    (:func:`elements.bending_hinge.series_bend`). Where they bend alike —
    actuated creases, and passive creases under the rigid strategy — the
    crease's end faces are exactly those of the rotation; passive strips
    under the local/global strategies may bend unequally, and their
    composite is then close to, not exactly, the rotation.

``"arc"`` — the paper's hinge (§4, Eq. 7): a circular arc of constant
    neutral-axis length W. It keeps flat panels 2(r + H/2) apart (thickness
    accommodation) but turns the panels about an axis that drifts off the
    crease (≈ W·θ²/12 at small θ, 0.12 W at 70°), so the hinges around a
    vertex do not meet and every closed loop must strain to fold.

``"slack"`` — a compliant joint whose length is free within bounds: each
    sub-strip bends on an arc of the length it has (the chord between its
    end faces' centres, ℓ = c·(φ/2)/sin(φ/2)), kept between the axis hinge's
    (the shortest: panels turning about the crease's mid-line) and max(W,
    H·|θ|/2) (no longer than its width unless its inner surface would need a
    negative radius). Where the axis path is compatible it is one of its
    states, so the hinge folds like the axis hinge; where that path binds, a
    strip lengthens up to W — flat, a crease of width W can hold its panels
    from H to 2W/π apart — which lets a thick vertex fold flat with its
    wrapping crease three layers wide (``scenes.d4v``). The freedom makes
    some states a family (the stack of a flat vertex may open up to what its
    widths allow); ``rigid`` refuses these hinges (its strips have the length
    their angle sets), ``hybrid`` takes its rigid steps as a predictor and
    finishes with ``newton``, whose steps move along the strips' lengths too.

``"eq8"`` — the paper's Eq. 8 trapezoid: the arc's linear approximation
    (end faces sheared, error O(φ²)), with the arc's drift.

Units: mm, degrees at this API.
"""
from __future__ import annotations

#: Hinge model names, in the order of the kernels' ``model`` codes (see
#: :mod:`elements.bending_hinge`): ``eq8`` 0, ``arc`` 1, ``axis`` 2, ``slack`` 3.
HINGE_MODELS = ("eq8", "arc", "axis", "slack")
DEFAULT_HINGE = "axis"
PIVOT_BLEND = 0.05  # = elements.bending_hinge.PIVOT_BLEND (× W; a test keeps them equal)


def neutral_length(model: str, width, thickness: float, theta):
    """Neutral-axis length (mm) of a crease's strip of width W bent by θ (rad) in total.

    ``axis``: max(W·f(θ), H·|θ|/2), f(θ) = (θ/2)/tan(θ/2), rounded within
    ``PIVOT_BLEND`` × W of the switch; ``slack``: the same, its shortest (its
    length at a state is measured: :func:`foldcore.strain.strains_at`);
    ``arc`` and ``eq8``: W. Each of k equal
    sub-strips has 1/k of it (the kernels'
    :func:`elements.bending_hinge.axis_length` with w = W/k, φ = θ/k).
    """
    import numpy as np  # here: the names above are read by the command line, kept light

    width, theta = np.asarray(width, dtype=float), np.asarray(theta, dtype=float)
    if model not in ("axis", "slack"):
        return np.broadcast_to(width, np.broadcast(width, theta).shape).copy()
    half = 0.5 * theta
    small = np.abs(half) < 1e-4
    safe = np.where(small, 1.0, half)
    f = np.where(small, 1.0 - half ** 2 / 3.0, safe * np.cos(safe) / np.sin(safe))
    a, b = width * f, 0.5 * thickness * np.abs(theta)
    delta = PIVOT_BLEND * width  # rounded switch (elements.bending_hinge.smooth_max)
    return np.where(np.abs(a - b) >= delta, np.maximum(a, b),
                    0.5 * (a + b) + (a - b) ** 2 / (4.0 * delta) + 0.25 * delta)


def pivot_angle_deg(width, thickness: float):
    """θ* = 2·atan(W/H) in degrees: where an axis hinge's panels' inner edges touch
    and it starts to pivot about its inner surface (W and H in mm)."""
    import numpy as np  # here: the names above are read by the command line, kept light

    return np.degrees(2.0 * np.arctan(np.asarray(width, dtype=float) / thickness))
