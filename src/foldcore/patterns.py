"""Crease-pattern generators: Pehrson's degree-4 vertex, waterbomb, Miura-ori, hinge.

Every generator returns a validated :class:`~foldcore.pattern.CreasePattern`.
Units at this API: lengths in mm, angles in **degrees** (valley positive).
Each docstring states the vertex and edge ordering, so creases can be indexed.
Mountain/valley choices follow the closed forms of :mod:`foldcore.kinematics`
and are checked against its closure oracle by the tests.
"""
from __future__ import annotations

import math

import numpy as np

from . import kinematics
from .errors import PatternError
from .pattern import CreasePattern

__all__ = ["degree4_vertex", "single_vertex", "waterbomb", "miura", "miura_edge_kinds",
           "miura_fold_angles", "miura_flat_widths", "miura_one_crease", "single_hinge", "grid",
           "degree4_assignments", "wrapping_crease", "gripper", "gripper_leg_sector", "panel_row"]

PEHRSON_SECTORS = (135.0, 90.0, 45.0, 90.0)
PEHRSON_WIDTHS = (16.0, 4.0, 8.0, 4.0)
_MAX_ARC_STEP = 45.0  # deg: boundary chord step used on sectors wider than 90°
_TOL = 1e-9


# ------------------------------------------------------------ degree-4 vertex
def degree4_vertex(sectors=PEHRSON_SECTORS, radius: float = 76.2, widths="pehrson",
                   mode: str = "A", rho1=None, assignments=None,
                   flat_foldable: bool = True) -> CreasePattern:
    """A single degree-4 vertex on a polygonal disc (default: Pehrson's vertex).

    Pehrson et al. (paper §5.1): Ø152.4 mm, sectors 135/90/45/90°, hinge widths
    ≈ 16, 4, 8, 4 mm; the circular rim is replaced by straight chords.

    Parameters
    ----------
    sectors : 4 floats, degrees
        Sector α_i between crease i and crease i+1 (CCW); positive, each < 180,
        summing to 360. Crease 1 is at 0°, crease i at α_1 + … + α_{i−1}.
    radius : float, mm
        Distance from the vertex to each crease end (disc radius).
    widths : 4 floats or None, mm, or "pehrson"
        Hinge width per crease (NaN / None = auto). ``"pehrson"``: 16, 4, 8,
        4 mm from the wrapping crease on (:func:`wrapping_crease`; from crease
        1 where no crease's M/V differs from the other three's): folded
        flat, its two panels hold the other two between them, so it spans
        three layers where the others span one; 16 = 4 + 8 + 4 keeps the
        four layers apart with hinges that keep their width (an arc of
        width W holds its panels 2W/π apart).
    mode : {"A", "B"}
        Folding branch that sets M/V (:func:`foldcore.kinematics.degree4_mode_a`,
        :func:`~foldcore.kinematics.degree4_mode_b`): the crease whose
        assignment differs from the other three is in the opposite-sign pair
        ((2, 4) in mode A, (1, 3) in mode B). Pehrson mode A is V, V, V, M.
        A crease that stays flat in a degenerate mode is assigned ``F``.
    rho1 : float, degrees, optional
        Actuate crease 1 to this angle (others passive). The overall sign of
        the assignment follows it: crease 1 is a valley unless ``rho1 < 0``.
    assignments : 4 str, optional
        Override the M/V of the four creases.
    flat_foldable : bool
        Require α1 + α3 = α2 + α4 = 180°. With ``False`` a general vertex is
        allowed but ``assignments`` must be given.

    Returns
    -------
    CreasePattern
        Vertex 0 is the centre; vertex i+1 ends crease i+1; extra rim vertices
        (one chord per ≤ 45° on sectors wider than 90°) follow. Edges 0..3 are
        creases 1..4 (vertex 0 → vertex i+1); then the rim edges CCW from the
        end of crease 1. Faces: the four sectors.
    """
    sectors = _check_sectors(sectors, flat_foldable)
    _check_positive(radius=radius)
    if assignments is None:
        if not flat_foldable:
            raise PatternError("degree4_vertex: mode A/B is defined for flat-foldable "
                               "vertices only; pass assignments for a general vertex")
        assignments = degree4_assignments(sectors, mode, -1.0 if _neg(rho1) else 1.0)
    if isinstance(widths, str):
        if widths != "pehrson":
            raise PatternError(f"degree4_vertex: widths must be 4 numbers, None or "
                               f"'pehrson', got {widths!r}")
        odd = [a for a in assignments if list(assignments).count(a) == 1]
        widths = np.roll(PEHRSON_WIDTHS, wrapping_crease(assignments) if len(odd) == 1 else 0)
    return _vertex_pattern(sectors, radius, widths, assignments, [rho1, None, None, None],
                           "degree4_vertex")


def wrapping_crease(assignments) -> int:
    """Index (0-based) of the crease of a flat-folded degree-4 vertex whose panels
    hold the other two between them: the one opposite the crease whose M/V
    differs from the other three's. PatternError if no crease differs so."""
    signs = [a.upper() for a in assignments]
    odd = [i for i in range(4) if sum(s == signs[i] for s in signs) == 1]
    if len(signs) != 4 or len(odd) != 1:
        raise PatternError(f"wrapping crease: need 4 assignments with exactly one "
                           f"differing from the others, got {list(assignments)}")
    return (odd[0] + 2) % 4


def single_vertex(sectors, assignments, fold_angles=None, radius: float = 50.0,
                  widths=None) -> CreasePattern:
    """One vertex of any degree n ≥ 3 on a polygonal disc.

    Parameters
    ----------
    sectors : n floats, degrees
        Sector α_i between crease i and crease i+1 (CCW); each in (0, 180),
        summing to 360. Crease 1 is at 0°, crease i at α_1 + … + α_{i−1}.
    assignments : n str
        ``M``/``V``/``F``/``U`` of the creases.
    fold_angles : n floats or None, degrees, optional
        Target per crease (valley > 0); None = passive (default: all passive).
    radius : float, mm
    widths : n floats or None, mm, optional

    Returns
    -------
    CreasePattern
        Vertex 0 the centre, vertex i+1 the end of crease i+1, then extra rim
        vertices; edges 0..n−1 the creases, then the rim CCW; faces the sectors.
    """
    sectors = np.asarray(sectors, dtype=float)
    if sectors.ndim != 1 or len(sectors) < 3:
        raise PatternError(f"single_vertex: need at least 3 sector angles, got {sectors.size}")
    _check_sector_angles(sectors, "single_vertex")
    if len(assignments) != len(sectors):
        raise PatternError(f"single_vertex: {len(assignments)} assignments for "
                           f"{len(sectors)} creases")
    _check_positive(radius=radius)
    angles = list(fold_angles) if fold_angles is not None else [None] * len(sectors)
    return _vertex_pattern(sectors, radius, widths, assignments, angles, "single_vertex")


def _vertex_pattern(sectors, radius, widths, assignments, angles, source) -> CreasePattern:
    """Crease pattern of one vertex: creases from the centre, rim chords, sectors."""
    n = len(sectors)
    vertices, rim = _disc_vertices(sectors, radius)
    edges = [(0, i + 1) for i in range(n)] + list(zip(rim, np.roll(rim, -1)))
    n_rim = len(rim)
    return CreasePattern(
        vertices, edges, list(assignments) + ["B"] * n_rim,
        fold_angles=list(angles) + [None] * n_rim,
        widths=list(widths if widths is not None else [None] * n) + [None] * n_rim,
        source=source)


def degree4_assignments(sectors, mode: str = "A", sign: float = 1.0) -> list[str]:
    """M/V of a flat-foldable degree-4 vertex in a mode (from the closed form).

    Parameters
    ----------
    sectors : 4 floats, degrees
        Sectors (α, β, 180−α, 180−β).
    mode : {"A", "B"}
    sign : float
        +1: crease 1 is a valley; −1: mirror image (crease 1 mountain).

    Returns
    -------
    list of 4 str
        ``V``/``M`` per crease, ``F`` for a crease that stays flat.
    """
    if str(mode).upper() not in ("A", "B"):
        raise PatternError(f"degree4_vertex: mode must be 'A' or 'B', got {mode!r}")
    rho = kinematics.degree4_deg(sectors[0], sectors[1], 90.0 * np.sign(sign), str(mode))
    return ["F" if abs(r) < 1e-6 else ("V" if r > 0 else "M") for r in rho]


def _check_sectors(sectors, flat_foldable: bool) -> np.ndarray:
    s = np.asarray(sectors, dtype=float)
    if s.shape != (4,):
        raise PatternError(f"degree4_vertex: need 4 sector angles, got {s.size}")
    _check_sector_angles(s, "degree4_vertex")
    if flat_foldable and (abs(s[0] + s[2] - 180.0) > _TOL or abs(s[1] + s[3] - 180) > _TOL):
        raise PatternError(f"degree4_vertex: sectors {s.tolist()}° are not flat-foldable "
                           "(need α1 + α3 = α2 + α4 = 180°); pass flat_foldable=False")
    return s


def _check_sector_angles(s: np.ndarray, where: str) -> None:
    """Each sector in (0, 180)°, all of them summing to 360°."""
    if not (np.all(s > 0) and np.all(s < 180)):
        raise PatternError(f"{where}: sector angles {s.tolist()}° must each be in (0, 180)")
    if abs(s.sum() - 360.0) > _TOL:
        raise PatternError(f"{where}: sector angles {s.tolist()}° sum to {s.sum():g}°, "
                           "not 360°")


def _disc_vertices(sectors: np.ndarray, radius: float) -> tuple[np.ndarray, list[int]]:
    """Centre, crease ends (ids 1..n), extra rim points; rim loop ids CCW."""
    starts = np.concatenate([[0.0], np.cumsum(sectors)[:-1]])
    angles, rim = list(starts), []
    for i, (start, width) in enumerate(zip(starts, sectors)):
        rim.append(i + 1)
        steps = math.ceil(width / _MAX_ARC_STEP - _TOL) if width > 90.0 else 1
        for k in range(1, steps):
            angles.append(start + width * k / steps)
            rim.append(len(angles))
    phi = np.radians(angles)
    ring = radius * np.column_stack([np.cos(phi), np.sin(phi)])
    return np.vstack([[0.0, 0.0], ring]), rim


def _neg(angle) -> bool:
    return angle is not None and not np.isnan(angle) and angle < 0


def _check_positive(**values):
    for name, value in values.items():
        if not value > 0:
            raise PatternError(f"{name} must be > 0, got {value!r}")


# --------------------------------------------------------------- waterbomb
def waterbomb(n_creases: int = 6, radius: float = 50.0, major: str = "M",
              width: float = np.nan, major_angle=None) -> CreasePattern:
    """Symmetric waterbomb base: one vertex, equal sectors, alternating M/V.

    Parameters
    ----------
    n_creases : int
        Number of creases, even and ≥ 4 (paper: 6). Sectors are 360/n_creases°.
    radius : float, mm
        Crease length; the rim is the regular polygon through the crease ends.
    major : {"M", "V"}
        Family that folds further (mountain-major or valley-major branch). Only
        used with ``major_angle``.
    width : float, mm
        Hinge width of every crease (NaN = auto).
    major_angle : float, degrees, optional
        If given, the ``major`` creases are actuated to this magnitude (signed
        by their assignment) and the others are passive; the minor angle then
        follows :func:`foldcore.kinematics.waterbomb_minor_deg`.

    Returns
    -------
    CreasePattern
        Vertex 0 is the centre, vertex i+1 ends crease i at angle
        i·360/n_creases°. Edges 0..n−1: creases CCW from angle 0, crease i is
        ``M`` for even i and ``V`` for odd i. Edges n..2n−1: rim, edge n+i
        from the end of crease i to the end of crease i+1.
    """
    if int(n_creases) != n_creases or n_creases < 4 or n_creases % 2:
        raise PatternError(f"waterbomb: n_creases must be an even integer ≥ 4, got "
                           f"{n_creases!r}")
    if major not in ("M", "V"):
        raise PatternError(f"waterbomb: major must be 'M' or 'V', got {major!r}")
    _check_positive(radius=radius)
    n = int(n_creases)
    phi = 2.0 * np.pi * np.arange(n) / n
    vertices = np.vstack([[0.0, 0.0], radius * np.column_stack([np.cos(phi), np.sin(phi)])])
    rim = np.arange(1, n + 1)
    edges = [(0, i) for i in rim] + list(zip(rim, np.roll(rim, -1)))
    kinds = ["M" if i % 2 == 0 else "V" for i in range(n)]
    angles = [None] * (2 * n)
    if major_angle is not None:
        angles[:n] = [(abs(major_angle) * (1 if k == "V" else -1) if k == major else None)
                      for k in kinds]
    return CreasePattern(vertices, edges, kinds + ["B"] * n, fold_angles=angles,
                         widths=[width] * n + [None] * n, source="waterbomb")


# --------------------------------------------------------------- Miura-ori
def miura(n: int = 3, m: int = 3, a: float = 20.0, b: float = 20.0, gamma: float = 60.0,
          width: float = np.nan) -> CreasePattern:
    """Miura-ori with n × m parallelogram facets (sides a, b, acute angle γ).

    Straight crease lines run along x and are made of a-edges; zig-zag crease
    lines run along y and are made of b-edges. Vertex (i, j), i = 0..n,
    j = 0..m, has id ``j·(n+1) + i`` and sits at
    (i·a + [j odd]·b cos γ, j·b sin γ).

    M/V (checked by closure in the tests): zig-zag line i (0 < i < n) is ``M``
    for odd i and ``V`` for even i, the same along the line; the straight edge
    from (i, j) to (i+1, j) (0 < j < m) has the sign of zig-zag line i times
    (−1)^(j+1), so it alternates along its line. Every interior vertex is then
    a flat-foldable degree-4 vertex in mode B with (α, β) = (γ, 180° − γ), and
    |ρ| follows :func:`foldcore.kinematics.miura_angles`.

    Parameters
    ----------
    n, m : int
        Facets along x (a-direction) and along y (b-direction), ≥ 1.
    a, b : float, mm
        Straight (a) and zig-zag (b) edge lengths.
    gamma : float, degrees
        Acute facet angle, in (0, 90).
    width : float, mm
        Hinge width of every crease (NaN = auto).

    Returns
    -------
    CreasePattern
        Edges: first the a-edges row by row (for j in 0..m, for i in 0..n−1:
        (i, j)→(i+1, j)), then the b-edges column by column (for i in 0..n,
        for j in 0..m−1: (i, j)→(i, j+1)). :func:`miura_edge_kinds` gives the
        kind of each edge in this order. Faces: n·m parallelograms.
    """
    _check_lattice("miura", n, m)
    _check_positive(a=a, b=b)
    if not 0.0 < gamma < 90.0:
        raise PatternError(f"miura: gamma must be in (0, 90) degrees, got {gamma!r}")
    g = math.radians(gamma)
    i, j = np.meshgrid(np.arange(n + 1), np.arange(m + 1))
    x = i * a + (j % 2) * b * math.cos(g)
    vertices = np.column_stack([x.ravel(), (j * b * math.sin(g)).ravel()])
    kinds = miura_edge_kinds(n, m)
    return CreasePattern(vertices, _lattice_edges(n, m), _miura_assignments(n, m),
                         widths=np.where(kinds == "boundary", np.nan, width), source="miura")


def miura_edge_kinds(n: int, m: int) -> np.ndarray:
    """(E,) str: ``'straight'``, ``'zigzag'`` or ``'boundary'`` per edge of
    :func:`miura` ``(n, m)``, in the pattern's edge order."""
    _check_lattice("miura", n, m)
    row = np.arange(m + 1).repeat(n)  # a-edges: row j
    col = np.arange(n + 1).repeat(m)  # b-edges: column i
    straight = np.where((row > 0) & (row < m), "straight", "boundary")
    zigzag = np.where((col > 0) & (col < n), "zigzag", "boundary")
    return np.concatenate([straight, zigzag]).astype("<U8")


def miura_fold_angles(n: int, m: int, gamma: float, tilt: float) -> np.ndarray:
    """(E,) zero-thickness rigid-fold angle of every edge of :func:`miura` ``(n, m)``
    at facet tilt θ (degrees, signed by its M/V: valley positive; NaN on the
    boundary): zig-zag |ρ| = 2θ, straight tan(|ρ|/2) = cos γ tan θ
    (:func:`foldcore.kinematics.miura_angles_deg`).

    Parameters
    ----------
    n, m : int
        Facets along x and y.
    gamma, tilt : float, degrees
        Acute facet angle γ and facet tilt θ.
    """
    kinds = miura_edge_kinds(n, m)
    zigzag, straight = kinematics.miura_angles_deg(gamma, tilt)
    sign = np.where(np.array(_miura_assignments(n, m)) == "M", -1.0, 1.0)
    return sign * np.select([kinds == "zigzag", kinds == "straight"], [zigzag, straight], np.nan)


def miura_flat_widths(n: int, m: int, width: float) -> np.ndarray:
    """(E,) hinge widths (mm) with which a thick :func:`miura` ``(n, m)`` folds
    exactly flat with arc hinges (``thicken(..., hinge="arc")``); NaN on the boundary.
    Its angles reach flat, its strips then cross other parts: with contact the fold
    stops short (`docs/benchmarks.md#contact`).

    Folded flat, a degree-4 vertex stacks its four panels in four layers. The
    crease opposite its odd crease (the one whose M/V differs from the other
    three) wraps around the other three, so its arc radius must be the sum of
    theirs; an arc hinge of width W bent 180° has radius W / π (its panels 2W / π
    apart). With equal hinges the loop around the vertex misses by two layers
    (its first and third panel would share one) and the sheet stops short of
    flat (`docs/architecture.md#a-thick-miura-has-no-flat-state-with-equal-hinges`;
    ``bench/origami_simulator.py`` folds its graded-width row). In a Miura the
    odd crease is a straight one, and every straight edge is the wrapping
    crease at one of its ends and the odd one at the other, so along each
    straight line the widths grow by twice the zig-zag width per vertex:
    zig-zag edges get ``width``, the k-th edge of a straight line (k = 0 …
    n − 1, counted from the end where it wraps: the left end on odd rows, the
    right one on even rows) ``(1 + 2k) · width``.
    The axis hinge cannot use this: at 180° it pivots about its inner surface
    whatever its width (panels H apart).

    Parameters
    ----------
    n, m : int
        Facets along x and y.
    width : float, mm
        Zig-zag hinge width; at least π H / 2 (Eq. 7's width) so that an arc
        bent flat keeps a non-negative inner radius.

    Returns
    -------
    (E,) float, mm, in the pattern's edge order.
    """
    _check_lattice("miura", n, m)
    _check_positive(width=width)
    kinds = miura_edge_kinds(n, m)
    i, j = np.tile(np.arange(n), m + 1), np.arange(m + 1).repeat(n)  # a-edges (i, j)
    k = np.where(j % 2 == 1, i, n - 1 - i)
    straight = (1.0 + 2.0 * k) * width
    widths = np.concatenate([straight, np.full((n + 1) * m, float(width))])
    return np.where(kinds == "boundary", np.nan, widths)


def miura_one_crease(n: int, m: int, a: float = 20.0, b: float = 20.0, gamma: float = 60.0,
                     tilt: float = 30.0, width: float = np.nan) -> CreasePattern:
    """:func:`miura` driven by a single crease: the middle interior zig-zag edge
    (middle in the pattern's edge order) targets its rigid-fold angle at facet
    tilt θ (degrees, :func:`miura_fold_angles`), every other crease is passive.

    The 1-DOF sheet folded by one actuator: a rigid-foldable model must bring
    every crease to ``miura_fold_angles(n, m, gamma, tilt)``; the accuracy
    tests and benchmarks compare against exactly that.
    """
    expected = miura_fold_angles(n, m, gamma, tilt)
    zigzag = np.flatnonzero(miura_edge_kinds(n, m) == "zigzag")
    driven = int(zigzag[len(zigzag) // 2])
    angles = [None] * len(expected)
    angles[driven] = float(expected[driven])
    return miura(n, m, a=a, b=b, gamma=gamma, width=width).replace(fold_angles=angles)


def _miura_assignments(n: int, m: int) -> list[str]:
    i_a, j_a = np.tile(np.arange(n), m + 1), np.arange(m + 1).repeat(n)
    line_sign_a = np.where(i_a % 2 == 1, -1, 1)
    sign_a = line_sign_a * np.where(j_a % 2 == 1, 1, -1)
    col = np.arange(n + 1).repeat(m)
    sign_b = np.where(col % 2 == 1, -1, 1)
    kinds = miura_edge_kinds(n, m)
    signs = np.concatenate([sign_a, sign_b])
    return ["B" if k == "boundary" else ("V" if s > 0 else "M") for k, s in zip(kinds, signs)]


def _lattice_edges(n: int, m: int) -> np.ndarray:
    """(E, 2) int: row edges (j, then i) then column edges (i, then j)."""
    ids = np.arange((n + 1) * (m + 1)).reshape(m + 1, n + 1)
    rows = np.column_stack([ids[:, :-1].ravel(), ids[:, 1:].ravel()])
    cols = np.column_stack([ids[:-1, :].T.ravel(), ids[1:, :].T.ravel()])
    return np.vstack([rows, cols])


def _check_lattice(name: str, n, m):
    for label, value in (("n", n), ("m", m)):
        if int(value) != value or value < 1:
            raise PatternError(f"{name}: {label} must be an integer ≥ 1, got {value!r}")


# --------------------------------------------------------- simple patterns
def single_hinge(panel_length: float = 10.0, depth: float = 10.0, angle=None,
                 assignment: str = "V", width: float = np.nan,
                 max_angle: float = 180.0) -> CreasePattern:
    """Two rectangular panels sharing one crease along y at x = 0.

    Parameters
    ----------
    panel_length : float, mm
        Each panel's extent from the crease line to its far edge (along x).
    depth : float, mm
        Crease length (panel extent along y).
    angle : float, degrees, optional
        Target fold angle of the crease (None = passive), valley positive.
    assignment : {"V", "M", "U", "F"}
    width : float, mm
        Hinge width (NaN = auto).
    max_angle : float, degrees
        Largest fold magnitude, in (0, 180].

    Returns
    -------
    CreasePattern
        Vertices: 0 (0, 0), 1 (0, depth), 2 (L, 0), 3 (L, depth), 4 (−L, depth),
        5 (−L, 0). Edge 0 is the crease 0→1 (panel x < 0 on its left); edges 1..6
        the boundary. Faces: the panel x < 0, the panel x > 0.
    """
    _check_positive(panel_length=panel_length, depth=depth)
    length = panel_length
    vertices = [(0, 0), (0, depth), (length, 0), (length, depth), (-length, depth), (-length, 0)]
    edges = [(0, 1), (0, 2), (2, 3), (3, 1), (1, 4), (4, 5), (5, 0)]
    return CreasePattern(vertices, edges, [assignment] + ["B"] * 6,
                         fold_angles=[angle] + [None] * 6, widths=[width] + [None] * 6,
                         max_angles=[max_angle] + [180.0] * 6, source="single_hinge")


def panel_row(lengths, depth: float = 10.0, assignment: str = "V") -> CreasePattern:
    """Rectangular panels side by side along x, each crease between two of them (a
    letter fold: three panels, two creases).

    Parameters
    ----------
    lengths : k floats, mm
        Each panel's extent along x (k ≥ 2), left to right.
    depth : float, mm
        Crease length (the panels' extent along y).
    assignment : {"V", "M", "U", "F"}
        Of every crease; no target angles (passive).

    Returns
    -------
    CreasePattern
        Vertices 0 … k along y = 0 at the panels' sides (x = 0, L₁, L₁ + L₂, …),
        then k + 1 … 2k + 1 above them at y = ``depth``. Edges 0 … k − 2 the
        creases i+1 → i+k+2, then the boundary: bottom left to right, top left to
        right, left side, right side. Faces: the panels.
    """
    lengths = np.asarray(lengths, dtype=float)
    if lengths.ndim != 1 or len(lengths) < 2:
        raise PatternError(f"panel_row: need at least 2 panel lengths, got {lengths.size}")
    _check_positive(depth=depth, **{f"lengths[{i}]": v for i, v in enumerate(lengths)})
    xs = np.concatenate([[0.0], np.cumsum(lengths)])
    k = len(lengths)
    vertices = [(x, 0.0) for x in xs] + [(x, depth) for x in xs]
    creases = [(i, i + k + 1) for i in range(1, k)]
    bottom = [(i, i + 1) for i in range(k)]
    top = [(i + k + 1, i + k + 2) for i in range(k)]
    edges = creases + bottom + top + [(0, k + 1), (k, 2 * k + 1)]
    return CreasePattern(vertices, edges, [assignment] * len(creases) + ["B"] * (2 * k + 2),
                         source="panel_row")


def grid(n: int, m: int, size: float = 10.0, assignment: str = "U") -> CreasePattern:
    """n × m square grid of side ``size`` mm; every interior edge a crease.

    Vertex (i, j) has id ``j·(n+1) + i`` at (i·size, j·size). Edges: row edges
    (for j, for i) then column edges (for i, for j), as in :func:`miura`;
    interior edges get ``assignment``, the rim ``B``.
    """
    _check_lattice("grid", n, m)
    _check_positive(size=size)
    i, j = np.meshgrid(np.arange(n + 1), np.arange(m + 1))
    vertices = size * np.column_stack([i.ravel(), j.ravel()]).astype(float)
    interior = miura_edge_kinds(n, m) != "boundary"
    return CreasePattern(vertices, _lattice_edges(n, m),
                         np.where(interior, assignment, "B"), source="grid")


# ---------------------------------------------------------------- gripper
GRIPPER_SPINE_DEG, GRIPPER_LEG_DEG = 50.0, 110.0


def gripper_leg_sector(spine: float = GRIPPER_SPINE_DEG, leg: float = GRIPPER_LEG_DEG) -> float:
    """Sector γ (degrees) between a gripper vertex's valley spine and its legs for which
    the spine pair folds by ``spine`` exactly when the legs fold by ``leg`` (degrees).

    The vertex is a flat-foldable bird's foot, sectors (γ, 180−γ, 180−γ, γ), in
    mode B of :func:`foldcore.kinematics.degree4_mode_b`:
    tan(ρ_spine/2) = cos γ · tan(ρ_leg/2).
    """
    if not 0.0 < spine < leg < 180.0:
        raise PatternError(f"gripper: need 0 < spine fold ({spine}°) < leg fold ({leg}°) "
                           "< 180°")
    return math.degrees(math.acos(math.tan(math.radians(spine) / 2)
                                  / math.tan(math.radians(leg) / 2)))


def gripper(half_width: float = 12.0, half_length: float = 30.0, offset: float = 3.0,
            sector: float | None = None, spine_angle: float | None = GRIPPER_SPINE_DEG,
            width: float = np.nan) -> CreasePattern:
    """Two coupled bird's-foot vertices on a rectangle: a pop-up jaw mechanism.

    The vertices A = (0, ``offset``) and B = (0, −``offset``) share the mountain
    crease A–B (the *back*). From A a valley *spine* runs up the centre line to the
    top edge and two mountain *legs* leave at ±γ from it to the side edges; B is A's
    mirror image in y = 0. Folded, the two quadrilaterals above A's legs close on the
    top spine into the upper jaw, those below B's legs into the lower jaw, and the
    two *covers* between the legs turn about the back like the covers of a book:
    closing the covers closes the jaws (one degree of freedom).

    Parameters
    ----------
    half_width, half_length : float, mm
        The sheet is [−half_width, half_width] × [−half_length, half_length].
    offset : float, mm
        Distance of each vertex from the sheet's centre (half the back's length).
    sector : float, degrees, optional
        γ between a spine and a leg, in (0, 90); default
        :func:`gripper_leg_sector` (spines 50°, legs 110°).
    spine_angle : float or None, degrees
        Target fold magnitude of the spines and the back (None: passive); the legs'
        target follows from the closed form (mode B), so the targets are compatible.
    width : float, mm
        Hinge width of every crease (NaN: auto).

    Returns
    -------
    CreasePattern
        Vertices 0 A, 1 B, 2 top spine end, 3 bottom spine end, 4/5 A's left/right
        leg ends, 6/7 B's left/right leg ends, 8–11 the corners (+,+), (−,+), (−,−),
        (+,−). Edges 0 top spine (V), 1 bottom spine (V), 2 back A–B (M), 3/4 A's
        left/right legs (M), 5/6 B's left/right legs (M), then the boundary.
        Faces: left and right halves of each jaw, left and right covers.
    """
    _check_positive(half_width=half_width, half_length=half_length, offset=offset)
    gamma = gripper_leg_sector() if sector is None else float(sector)
    if not 0.0 < gamma < 90.0:
        raise PatternError(f"gripper: sector must be in (0, 90)°, got {gamma}")
    rise = offset + half_width / math.tan(math.radians(gamma))
    if not rise < half_length:
        raise PatternError(f"gripper: legs at {gamma:.4g}° from the spines reach the "
                           f"sides at |y| = {rise:.4g} mm, beyond half_length {half_length}")
    w, h = half_width, half_length
    vertices = [(0, offset), (0, -offset), (0, h), (0, -h), (-w, rise), (w, rise),
                (-w, -rise), (w, -rise), (w, h), (-w, h), (-w, -h), (w, -h)]
    creases = [(0, 2), (1, 3), (0, 1), (0, 4), (0, 5), (1, 6), (1, 7)]
    ring = [2, 9, 4, 6, 10, 3, 11, 7, 5, 8]
    boundary = list(zip(ring, ring[1:] + ring[:1]))
    angles = [None] * 7
    if spine_angle is not None:
        rho = kinematics.degree4_deg(gamma, 180.0 - gamma, float(spine_angle), "B")
        spine, leg = float(rho[0]), float(rho[1])
        angles = [spine, spine, -spine, leg, leg, leg, leg]
    return CreasePattern(vertices, creases + boundary, ["V", "V", "M"] + ["M"] * 4 + ["B"] * 10,
                         fold_angles=angles + [None] * 10,
                         widths=[width] * 7 + [None] * 10, source="gripper")
