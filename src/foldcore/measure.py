"""Measurements on a deformed thick mesh: panel rotations and fold angles; and a thin
sheet's facet strains (:func:`facet_strains`).

Fold angle of a crease = signed dihedral between the mid-planes of its two
panels, valley positive (FOLD), measured from panel geometry, not from hinges.
"""
from __future__ import annotations

import numpy as np


def best_rotations(covs: np.ndarray) -> np.ndarray:
    """(n, 3, 3) rotations R (det = +1) maximising tr(Rᵀ cov) for (n, 3, 3) covariances.

    ``cov`` = Σ p tᵀ over an element's vertices (p current, centred; t target,
    centred): Kabsch/Procrustes U·diag(1, 1, det(U Vᵀ))·Vᵀ, batched.
    """
    u, _, vt = np.linalg.svd(covs)
    flip = np.linalg.det(u) * np.linalg.det(vt) < 0
    u[flip, :, 2] *= -1
    return u @ vt


def element_rotations(group, positions: np.ndarray) -> np.ndarray:
    """(n, 3, 3) best-fit rotation of each element's rest shape onto its current shape.

    All elements at once (segment sums over the slots), because a Python loop over
    the panels was a tenth of a fold path's time
    (docs/architecture.md#panel-rotations-in-one-pass)."""
    starts = group.indptr[:-1]
    sizes = np.diff(group.indptr)
    p = positions[group.indices]
    means = np.add.reduceat(p, starts, axis=0) / sizes[:, None]
    centred = p - np.repeat(means, sizes, axis=0)
    covs = np.add.reduceat(centred[:, :, None] * group.rest[:, None, :], starts, axis=0)
    return best_rotations(covs)


def fold_angles(pattern, mesh, positions: np.ndarray) -> np.ndarray:
    """(E,) fold angle of every edge in degrees, valley positive; NaN for ``B`` edges.

    Uses the best-fit rotations R_L, R_R of the panels left and right of each
    crease a→b (:meth:`ThickMesh.measuring_panels`: on an elastic face, its cell
    nearest the crease): with normals n = R·ẑ and crease direction d = R·(b − a)
    averaged over both panels, ρ = atan2((n_R × n_L)·d, n_L·n_R).
    """
    panels = mesh.groups[mesh.panel_group]
    rot = element_rotations(panels, positions)
    out = np.full(pattern.n_edges, np.nan)
    crease = pattern.creases
    left_panels, right_panels = mesh.measuring_panels(pattern, crease)
    left, right = rot[left_panels], rot[right_panels]
    d2 = pattern.vertices[pattern.edges[crease, 1]] - pattern.vertices[pattern.edges[crease, 0]]
    d_rest = np.column_stack([d2, np.zeros(len(crease))])
    d = np.einsum("nij,nj->ni", left + right, d_rest)
    out[crease] = dihedral_deg(left[:, :, 2], right[:, :, 2], d)
    return on_assigned_side(out, pattern.assignments)


def on_assigned_side(angles: np.ndarray, assignments: np.ndarray) -> np.ndarray:
    """(E,) fold angles (degrees) with an M crease past −180° written below −180°
    and a V crease past +180° above it, instead of wrapped to the other sign.

    A dihedral angle is measured in (−180°, 180°]: a mountain folded 0.54° past
    flat reads +179.46°, which contradicts its assignment (and colours it as a
    valley). Within 90° of its assigned side's ±180° an M or V crease keeps that
    side's sign (−180.54°); ``U`` and ``F`` creases are left as measured."""
    out = np.array(angles, dtype=np.float64)
    with np.errstate(invalid="ignore"):
        out[(assignments == "M") & (out > 90.0)] -= 360.0
        out[(assignments == "V") & (out < -90.0)] += 360.0
    return out


def wrapped_deg(angles) -> np.ndarray:
    """Angles or angle differences (degrees) wrapped into [−180, 180)."""
    return (np.asarray(angles, dtype=float) + 180.0) % 360.0 - 180.0


def dihedral_deg(n_left: np.ndarray, n_right: np.ndarray, d: np.ndarray) -> np.ndarray:
    """(n,) fold angles, degrees, valley positive: ρ = atan2((n_R × n_L)·d̂, n_L·n_R)
    for unit face normals n_L, n_R (n, 3) left and right of creases along d (n, 3)."""
    d_hat = d / np.linalg.norm(d, axis=1)[:, None]
    sin = np.einsum("ni,ni->n", np.cross(n_right, n_left), d_hat)
    return np.degrees(np.arctan2(sin, np.einsum("ni,ni->n", n_left, n_right)))


def crease_overlaps(pattern, mesh, positions: np.ndarray) -> np.ndarray:
    """(E,) how deep (mm) the two panels of each crease pass into each other; NaN on B.

    For each crease and each ordering (A, B) of its panels: the vertices B shares
    with the crease's hinge strips (its hinge edge, top and bottom) are tested
    against A's slab — inside it (closer to A's mid-plane than H/2) and over A
    (on A's side of A's hinge edge, in A's plane) means B's edge is inside A,
    by its distance to A's face on the fold's inner side. The deepest of either
    ordering is the crease's overlap (0: the panels at most touch). Local to
    each crease: panels that meet elsewhere (far collisions) are not looked at.
    """
    panels = mesh.groups[mesh.panel_group]
    strips = mesh.groups.get("bending_hinge")
    rot = element_rotations(panels, positions)
    half = 0.5 * mesh.thickness
    out = np.full(pattern.n_edges, np.nan)
    for e in pattern.creases:
        e = int(e)
        pair = [int(p[0]) for p in mesh.measuring_panels(pattern, [e])]
        ids = [panels.indices[panels.slots(p)] for p in pair]
        own = np.zeros(0, dtype=np.int64)
        if strips is not None and e in mesh.strips_of_crease:
            own = np.concatenate([strips.indices[strips.slots(int(s))]
                                  for s in mesh.strips_of_crease[e]])
        edge = [i[np.isin(i, own)] for i in ids]
        if not all(len(x) for x in edge):
            out[e] = 0.0
            continue
        depth = 0.0
        for a, b in ((0, 1), (1, 0)):
            depth = max(depth, _depth_into(positions, ids[a], edge[a], rot[pair[a]],
                                           positions[edge[b]], half))
        out[e] = depth
    return out


def _depth_into(positions, panel_ids, hinge_ids, rotation, points, half) -> float:
    """Deepest of ``points`` (n, 3) mm inside the slab of one panel (vertex ids
    ``panel_ids``, hinge-edge vertex ids ``hinge_ids``, best-fit rotation) and over
    it — past its hinge edge toward its centre, within the edge's span; 0 when
    none is."""
    normal = rotation[:, 2]
    centre = positions[panel_ids].mean(axis=0)
    edge = positions[hinge_ids]
    along = edge[np.argmax(np.linalg.norm(edge - edge[0], axis=1))] - edge[0]
    along -= (along @ normal) * normal
    along /= np.linalg.norm(along)
    start = edge.mean(axis=0)
    inward = centre - start
    inward -= (inward @ normal) * normal + (inward @ along) * along
    inward /= np.linalg.norm(inward)
    span = (edge - start) @ along
    height = (points - centre) @ normal
    reach = (points - start) @ along
    chosen = ((points - start) @ inward > 0.0) & (np.abs(height) < half) \
        & (reach >= span.min()) & (reach <= span.max())
    if not chosen.any():
        return 0.0
    return float((half - np.abs(height[chosen])).max())


#: Facet strains are reported up to this (a degenerate facet's would be unbounded).
MAX_SHOWN_STRAIN = 1e6


def facet_strains(pattern, triangles: np.ndarray, positions: np.ndarray) -> np.ndarray:
    """(T,) the largest |L − L₀| / L₀ of each triangle's three sides (dimensionless),
    L₀ in the flat ``pattern``, L at ``positions`` (N, 3) mm; at most
    :data:`MAX_SHOWN_STRAIN`."""
    t = np.asarray(triangles)
    ends = (t, np.roll(t, -1, axis=1))
    rest = np.linalg.norm(pattern.vertices[ends[1]] - pattern.vertices[ends[0]], axis=2)
    now = np.linalg.norm(positions[ends[1]] - positions[ends[0]], axis=2)
    with np.errstate(divide="ignore", invalid="ignore"):
        strain = np.abs(now - rest) / rest
    return np.minimum(np.nan_to_num(strain, nan=0.0, posinf=MAX_SHOWN_STRAIN),
                      MAX_SHOWN_STRAIN).max(axis=1, initial=0.0)
