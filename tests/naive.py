"""Slow, obviously-correct NumPy twins of every element kernel (STUMPY style).

Written from the equations (paper §4, the element modules' docstrings), not from
the numba code: the tests compare each registered kernel against the twin of the
same name.
Units: mm, radians.
"""
import numpy as np

HINGE_PARAMS = ("width", "height", "target", "sign", "max_angle", "floor", "model", "strips",
                "series")
EQ8, ARC, AXIS = 0, 1, 2  # values of the "model" column


def kabsch(p, t):
    """Rotation R (det +1) minimising Σ‖p_k − R t_k‖² for centred (m, 3) p, t."""
    return kabsch_of(p.T @ t)


def kabsch_of(cov):
    """Rotation R (det +1) maximising tr(Rᵀ cov): U·diag(1, 1, det(U Vᵀ))·Vᵀ."""
    u, _, vt = np.linalg.svd(cov)
    d = np.sign(np.linalg.det(u @ vt))
    return u @ np.diag([1.0, 1.0, d]) @ vt


def fit(x_elem, target):
    """Centre both shapes, rotate the target onto x: (out (m, 3), energy mm²)."""
    p = x_elem - x_elem.mean(axis=0)
    t = target - target.mean(axis=0)
    out = t @ kabsch(p, t).T
    return out, float(np.sum((p - out) ** 2))


def rigid_panel(x_elem, rest):
    """Rigid panel: the rest shape rotated onto the current one."""
    return fit(np.asarray(x_elem, float), np.asarray(rest, float))


# ------------------------------------------------------------ bending hinge
def strip_measures(x):
    """(W_t, W_b, H_p) of an (8, 3) strip, vertex order 0-1-2-3 top, 4-7 below."""
    n = lambda i, j: np.linalg.norm(x[i] - x[j])
    w_top = (n(0, 1) + n(3, 2)) / 2
    w_bot = (n(4, 5) + n(7, 6)) / 2
    h_p = (n(0, 4) + n(1, 5) + n(2, 6) + n(3, 7)) / 4
    return w_top, w_bot, h_p


def estimate_angle(x, arc_like):
    """Eq. 9 with the trapezoid's perpendicular height; asin form for arcs."""
    w_top, w_bot, h_p = strip_measures(x)
    d = (w_bot - w_top) / 2
    if arc_like:
        return 2 * np.arcsin(np.clip(d / h_p, -1.0, 1.0))
    h_perp = np.sqrt(max(h_p ** 2 - d ** 2, 0.0))
    if h_perp == 0.0:
        return np.copysign(np.pi, d)
    return 2 * np.arctan(d / h_perp)


def clamp(phi, sign, floor, max_angle):
    """Allowed interval: valley [floor, max], mountain [−max, −floor], else ±max."""
    lo, hi = {1: (floor, max_angle), -1: (-max_angle, -floor)}.get(
        int(np.sign(sign)), (-max_angle, max_angle))
    return float(min(max(phi, lo), hi))


def trapezoid(rest, width, phi):
    """Eq. 8: x ← x·(1 − 2y/W·tan(φ/2))."""
    out = rest.copy()
    out[:, 0] = rest[:, 0] * (1 - 2 * rest[:, 1] / width * np.tan(phi / 2))
    return out


def arc(rest, width, phi, length=None):
    """Points on a circular arc of the neutral axis turning by φ over the width W,
    of neutral-axis length ``length`` (default W), radius length/φ (φ = 0: rest)."""
    if phi == 0.0:
        return rest.copy()
    r = (width if length is None else length) / phi
    x, y, z = rest.T
    psi = phi * x / width
    # 1 − cos ψ written as 2 sin²(ψ/2): no cancellation for small ψ
    return np.column_stack([(r - y) * np.sin(psi), 2 * r * np.sin(psi / 2) ** 2
                            + y * np.cos(psi), z])


def axis_length(width, height, phi, strips, theta=None):
    """Neutral-axis length of an axis-true sub-strip: the chord W·cos(θ/2) of a
    rotation by θ (default kφ) about the crease's mid-line, as an arc of angle θ
    (length chord·(θ/2)/sin(θ/2)), per sub-strip; never below H|φ|/2 (inner
    radius 0)."""
    theta = strips * phi if theta is None else theta
    chord = strips * width * np.cos(theta / 2)
    length = chord if theta == 0 else chord * (theta / 2) / np.sin(theta / 2)
    axis, pivot = length / strips, height * abs(phi) / 2
    band = 0.05 * width  # the switch is rounded: a parabola tangent to both lines
    if abs(axis - pivot) >= band:
        return max(axis, pivot)
    return (axis + pivot) / 2 + (axis - pivot) ** 2 / (4 * band) + band / 4


def bent_target(rest, width, phi, model, height=None, strips=1, theta=None):
    """The strip bent by φ (rad), centred, in its local frame (``model``: EQ8/ARC/AXIS;
    ``theta``: its crease's bend, default kφ)."""
    rest = np.asarray(rest, float)
    if model == EQ8:
        out = trapezoid(rest, width, phi)
    elif model == ARC:
        out = arc(rest, width, phi)
    else:
        out = arc(rest, width, phi, axis_length(width, height, phi, strips, theta))
    return out - out.mean(axis=0)


def hinge_angle(x_elem, params):
    """Bend angle used by a strip: its target, or the clamped Eq. 9 estimate."""
    p = dict(zip(HINGE_PARAMS, params))
    if not np.isnan(p["target"]):
        return float(p["target"])
    phi = estimate_angle(x_elem, p["model"] != EQ8)
    return clamp(phi, p["sign"], p["floor"], p["max_angle"])


def bending_hinge(x_elem, rest, params, theta=None):
    """(out (8, 3), energy mm², angle rad) of one hinge sub-strip; ``theta`` its
    crease's bend (default: k × its own angle)."""
    x_elem = np.asarray(x_elem, float)
    phi = hinge_angle(x_elem, params)
    p = dict(zip(HINGE_PARAMS, params))
    target = bent_target(rest, p["width"], phi, int(p["model"]), p["height"], int(p["strips"]),
                         theta)
    out, energy = fit(x_elem, target)
    return out, energy, phi


# ----------------------------------------------------------------- drivers
def _rigid_panel_element(x_elem, rest, params):
    out, energy = rigid_panel(x_elem, rest)
    return out, energy, ()


def bending_hinge_element(x_elem, rest, params, theta=None):
    out, energy, phi = bending_hinge(x_elem, rest, params, theta)
    return out, energy, (phi,)


# ------------------------------------------------------------ stretch hinge
def _stretch_hinge_element(x_elem, rest, params):
    """Rest strip scaled by (λ, 1, λ^(−ν)) in its local frame, rotated onto x.

    λ = params[2], or for NaN the mean of the strip's four width edges over W.
    """
    x_elem = np.asarray(x_elem, float)
    width, _, ratio, poisson = params
    if np.isnan(ratio):
        ratio = np.mean([np.linalg.norm(x_elem[i] - x_elem[j])
                         for i, j in ((0, 1), (3, 2), (4, 5), (7, 6))]) / width
    target = np.asarray(rest, float) * np.array([ratio, 1.0, ratio ** -poisson])
    out, energy = fit(x_elem, target)
    return out, energy, (ratio,)


# ------------------------------------------------- bar (examples/plugin_bar)
def _bar_element(x_elem, rest, params):
    """Segment of the rest length along the current direction, about the midpoint."""
    p = np.asarray(x_elem, float) - np.mean(x_elem, axis=0)
    length = np.linalg.norm(rest[1] - rest[0])
    d = p[1] - p[0]
    n = np.linalg.norm(d)
    u = d / n if n > 0 else (rest[1] - rest[0]) / length
    out = np.array([-0.5 * length * u, 0.5 * length * u])
    return out, float(np.sum((p - out) ** 2)), ()


NAIVE = {"rigid_panel": _rigid_panel_element, "bending_hinge": bending_hinge_element,
         "stretch_hinge": _stretch_hinge_element, "bar": _bar_element}


def crease_bends(x, group_like, params):
    """(S,) each hinge strip's crease bend: k × its target when actuated, else the
    sum of the angles of the k strips of its series (``series`` = its place)."""
    ptr = group_like.indptr
    phi = np.array([hinge_angle(np.asarray(x[group_like.indices[ptr[e]:ptr[e + 1]]], float),
                                params[e]) for e in range(len(ptr) - 1)])
    theta = np.empty_like(phi)
    for e, row in enumerate(params):
        p = dict(zip(HINGE_PARAMS, row))
        k, first = int(p["strips"]), e - int(p["series"])
        theta[e] = k * phi[e] if not np.isnan(p["target"]) else phi[first:first + k].sum()
    return theta


def project_group(etype_name, x, group_like, params=None):
    """Loop a group's elements in Python with the twin of ``etype_name``.

    Parameters
    ----------
    etype_name : str
        Registered element type name (a key of ``NAIVE``).
    x : (N, 3) current positions, mm
    group_like : object with ``indptr``, ``indices``, ``rest``, ``params``
    params : (n, p) array, optional
        Overrides ``group_like.params``.

    Returns
    -------
    out (nnz, 3), energy (n,), state (n, s)
    """
    element = NAIVE[etype_name]
    params = group_like.params if params is None else params
    ptr = group_like.indptr
    # a hinge strip's target also depends on its crease's bend
    extra = [(t,) for t in crease_bends(x, group_like, params)] \
        if etype_name == "bending_hinge" else [()] * (len(ptr) - 1)
    out = np.zeros((len(group_like.indices), 3))
    energy = np.zeros(len(ptr) - 1)
    state = []
    for e in range(len(ptr) - 1):
        s = slice(ptr[e], ptr[e + 1])
        out[s], energy[e], st = element(x[group_like.indices[s]], group_like.rest[s], params[e],
                                        *extra[e])
        state.append(st)
    return out, energy, np.array(state, dtype=float).reshape(len(energy), -1)


# ------------------------------------------------- planar graphs (planar.py's twins)
# One-item-at-a-time reference versions of foldcore.planar's vectorised functions.
def trace_faces(vertices, edges):
    """Face cycles by walking each directed edge once (the face on its left)."""
    nbrs = [[] for _ in range(len(vertices))]
    for u, v in edges:
        nbrs[u].append(v)
        nbrs[v].append(u)
    rings = []
    for u, nb in enumerate(nbrs):
        nb = np.asarray(nb, dtype=np.int64)
        d = vertices[nb] - vertices[u]
        rings.append(nb[np.argsort(np.arctan2(d[:, 1], d[:, 0]), kind="stable")])
    position = [{int(w): i for i, w in enumerate(nb)} for nb in rings]
    seen, cycles = set(), []
    for a, b in np.concatenate([edges, edges[:, ::-1]]):
        start = (int(a), int(b))
        if start in seen:
            continue
        cycle, (u, v) = [], start
        while (u, v) not in seen:
            seen.add((u, v))
            cycle.append(u)
            around = rings[v]
            w = int(around[(position[v][u] - 1) % len(around)])
            u, v = v, w
        cycles.append(np.asarray(cycle, dtype=np.int64))
    return cycles


def derive_faces(vertices, edges, boundary):
    """Positive cycles that are not holes (all-boundary, no side on the outer face);
    None when more than one cycle is negative (not connected)."""
    from foldcore.planar import signed_area

    cycles = trace_faces(vertices, edges)
    areas = [signed_area(vertices[c]) for c in cycles]
    if sum(a < 0 for a in areas) > 1:
        return None
    key = {(int(u), int(v)): i for i, (u, v) in enumerate(edges)}
    key.update({(int(v), int(u)): i for i, (u, v) in enumerate(edges)})
    sides = lambda c: [key[(int(u), int(v))] for u, v in zip(c, np.roll(c, -1))]
    outer = {i for c, a in zip(cycles, areas) if a < 0 for i in sides(c)}
    return [c for c, a in zip(cycles, areas) if a > 0 and not (
        all(boundary[i] for i in sides(c)) and not any(i in outer for i in sides(c)))]


def crossing_pairs(vertices, edges):
    """Every pair of edges tested with GEOS: (i, j), i < j, that meet other than at a
    shared end (brute force, O(E²))."""
    import shapely

    lines = shapely.linestrings(vertices[edges])
    bad = []
    for i in range(len(edges)):
        for j in range(i + 1, len(edges)):
            if not shapely.intersects(lines[i], lines[j]):
                continue
            if set(edges[i].tolist()) & set(edges[j].tolist()) and \
                    shapely.get_type_id(shapely.intersection(lines[i], lines[j])) == 0:
                continue
            bad.append((i, j))
    return bad
