"""Measurements on a deformed thick mesh: panel rotations and fold angles.

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
    """(n, 3, 3) best-fit rotation of each element's rest shape onto its current shape."""
    covs = np.zeros((len(group), 3, 3))
    for e in range(len(group)):
        s = group.slots(e)
        p = positions[group.indices[s]]
        covs[e] = (p - p.mean(axis=0)).T @ group.rest[s]
    return best_rotations(covs)


def fold_angles(pattern, mesh, positions: np.ndarray) -> np.ndarray:
    """(E,) fold angle of every edge in degrees, valley positive; NaN for ``B`` edges.

    Uses the panels' best-fit rotations R_L, R_R of the faces left and right of
    each crease a→b: with normals n = R·ẑ and crease direction d = R·(b − a)
    averaged over both panels, ρ = atan2((n_R × n_L)·d, n_L·n_R).
    """
    panels = mesh.groups[mesh.panel_group]
    rot = element_rotations(panels, positions)
    out = np.full(pattern.n_edges, np.nan)
    crease = pattern.creases
    left = rot[mesh.panel_of_face[pattern.edge_faces[crease, 0]]]
    right = rot[mesh.panel_of_face[pattern.edge_faces[crease, 1]]]
    d2 = pattern.vertices[pattern.edges[crease, 1]] - pattern.vertices[pattern.edges[crease, 0]]
    d_rest = np.column_stack([d2, np.zeros(len(crease))])
    d = np.einsum("nij,nj->ni", left + right, d_rest)
    out[crease] = dihedral_deg(left[:, :, 2], right[:, :, 2], d)
    return out


def dihedral_deg(n_left: np.ndarray, n_right: np.ndarray, d: np.ndarray) -> np.ndarray:
    """(n,) fold angles, degrees, valley positive: ρ = atan2((n_R × n_L)·d̂, n_L·n_R)
    for unit face normals n_L, n_R (n, 3) left and right of creases along d (n, 3)."""
    d_hat = d / np.linalg.norm(d, axis=1)[:, None]
    sin = np.einsum("ni,ni->n", np.cross(n_right, n_left), d_hat)
    return np.degrees(np.arctan2(sin, np.einsum("ni,ni->n", n_left, n_right)))
