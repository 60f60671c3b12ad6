"""The rigid-body configuration and how an increment of the unknowns moves it.

A :class:`State` is the panels' rotations and centroids, the hinge-interior
vertices, the strips' target rotations and bend angles, and the positions
they give. :class:`Kinematics` applies an increment (exponential maps for
rotations; hinge interiors carried by their crease's panels). Units: mm, rad.
"""
from __future__ import annotations

from typing import NamedTuple

import numpy as np
import scipy.sparse as sp

from ...measure import best_rotations
from . import normal


class State(NamedTuple):
    """Configuration: positions (N, 3) mm, panel rotations (P, 3, 3) and centroids
    (P, 3) mm, free vertices (F, 3) mm, strip target rotations (S, 3, 3), strip
    bend angles (S,) rad."""

    x: np.ndarray
    rot_p: np.ndarray
    c_p: np.ndarray
    y: np.ndarray
    rot_e: np.ndarray
    phi: np.ndarray


def skew(v: np.ndarray) -> np.ndarray:
    """(..., 3, 3) cross-product matrices [v]× of (..., 3) vectors."""
    out = np.zeros(v.shape[:-1] + (3, 3))
    out[..., 0, 1], out[..., 0, 2] = -v[..., 2], v[..., 1]
    out[..., 1, 0], out[..., 1, 2] = v[..., 2], -v[..., 0]
    out[..., 2, 0], out[..., 2, 1] = -v[..., 1], v[..., 0]
    return out


def exp_so3(w: np.ndarray) -> np.ndarray:
    """(..., 3, 3) rotations exp([w]×) of (..., 3) rotation vectors (Rodrigues)."""
    angle = np.linalg.norm(w, axis=-1)[..., None, None]
    small = angle < 1e-8
    safe = np.where(small, 1.0, angle)
    a = np.where(small, 1.0 - angle ** 2 / 6.0, np.sin(safe) / safe)
    b = np.where(small, 0.5 - angle ** 2 / 24.0, (1.0 - np.cos(safe)) / safe ** 2)
    k = skew(w)
    return np.eye(3) + a * k + b * (k @ k)


def log_so3(rot: np.ndarray) -> np.ndarray:
    """(..., 3) rotation vectors of (..., 3, 3) rotations (angles below π)."""
    cos = np.clip((np.trace(rot, axis1=-2, axis2=-1) - 1.0) / 2.0, -1.0, 1.0)
    angle = np.arccos(cos)
    axis = np.stack([rot[..., 2, 1] - rot[..., 1, 2], rot[..., 0, 2] - rot[..., 2, 0],
                     rot[..., 1, 0] - rot[..., 0, 1]], axis=-1)
    small = angle < 1e-8
    scale = np.where(small, 0.5 + angle ** 2 / 12.0, angle / (2.0 * np.sin(np.where(small, 1.0,
                                                                                      angle))))
    return axis * scale[..., None]


def procrustes(current: np.ndarray, target: np.ndarray) -> np.ndarray:
    """(n, 3, 3) rotations R minimising Σ‖(p − p̄) − R t‖² for centred targets.

    Parameters
    ----------
    current : (n, m, 3) current positions of each element's m vertices
    target : (n, m, 3) centred target shapes in their local frames
    """
    centred = current - current.mean(axis=1, keepdims=True)
    return best_rotations(np.einsum("nki,nkj->nij", centred, target))


class Kinematics:
    """How the unknowns of one :class:`.layout.UnknownLayout` move a :class:`State`.

    Parameters
    ----------
    layout : UnknownLayout
    """

    def __init__(self, layout):
        self.layout = layout

    def positions(self, rot_p, c_p, y) -> np.ndarray:
        """(N, 3) mm: panel vertices placed by their panels, free vertices ``y``."""
        lay = self.layout
        x = np.empty((lay.n_vertices, 3))
        normal.place_on_panels(rot_p, c_p, lay.on_panel, lay.panel_of, lay.body, x)
        x[lay.free] = y
        return x

    def fit_panels(self, x: np.ndarray):
        """Rotations (P, 3, 3) and centroids (P, 3) mm of the panels' best rigid fit
        to ``x``, batched by panel size (this arithmetic, not another fit equal up to
        rounding: the step's accept test compares energies at rounding level)."""
        lay, panels = self.layout, self.layout.panels
        sizes = np.diff(panels.indptr)
        rot, c = np.zeros((len(panels), 3, 3)), np.zeros((len(panels), 3))
        for m in np.unique(sizes):
            sel = np.flatnonzero(sizes == m)
            ids = np.stack([panels.indices[panels.slots(p)] for p in sel])
            body = lay.body[np.searchsorted(lay.on_panel, ids)]
            rot[sel] = procrustes(x[ids], body)
            c[sel] = x[ids].mean(axis=1)
        return rot, c

    def apply(self, state: State, delta: np.ndarray, lo, hi) -> State:
        """``state`` moved by an increment ``delta`` (n_unknowns,) of the unknowns
        (exponential maps for rotations; crease angles clamped to [lo, hi])."""
        lay = self.layout
        moving = lay.panel_col >= 0
        w = np.zeros((len(state.rot_p), 6))
        w[moving] = delta[:6 * moving.sum()].reshape(-1, 6)
        rot_p, c_p = self.move_panels(state, w)
        y = self.carry(state, rot_p, c_p)
        if len(lay.free):
            y += delta[lay.free_col[0]:lay.rot_col].reshape(-1, 3)
        s = len(lay.ids)
        rot_e = np.empty_like(state.rot_e)
        normal.rotate_by(delta[lay.rot_col:lay.phi_col].reshape(s, 3), state.rot_e, rot_e)
        phi = state.phi.copy()
        lay.set_folds(np.clip(lay.folds(phi) + delta[lay.phi_col:], lo, hi), phi)
        return State(self.positions(rot_p, c_p, y), rot_p, c_p, y, rot_e, phi)

    def carry(self, state: State, rot_p, c_p) -> np.ndarray:
        """Free vertices moved by the blend of their panels' rigid motions (old → new)."""
        lay = self.layout
        y = np.empty_like(state.y)
        normal.carry_free(lay.carry_slot, lay.carry_panel, lay.carry_weight, state.y,
                          state.c_p, state.rot_p, rot_p, c_p, y)
        return y

    def move_panels(self, state: State, w):
        """Rigid update of the panels that keeps their hinge vertices where the linear
        step put them: the shift matches the linear prediction in the least-squares
        sense at the panel's joints, not at its centroid (an O(|a| ω²) gap on long
        panels otherwise)."""
        lay = self.layout
        rot_p, c_p = np.empty_like(state.rot_p), np.empty_like(state.c_p)
        normal.move_panels(state.rot_p, state.c_p, w, lay.panel_of, lay.body,
                           lay.joint_weight, rot_p, c_p)
        return rot_p, c_p

    def position_map(self, state: State):
        """P = ∂x/∂(panel, free-vertex unknowns) at a state, sparse (3N, n_q)."""
        lay = self.layout
        a = state.x[lay.m_vert] - state.c_p[lay.m_panel]
        w = lay.m_weight
        minus_skew = -skew(a) * w[:, None, None]
        p_vals = []
        for d in range(3):
            p_vals += [minus_skew[:, d, c] for c in range(3)] + [w]
        p_vals += [np.ones(len(lay.free))] * 3
        return sp.csr_matrix((np.concatenate(p_vals), (lay.p_rows, lay.p_cols)),
                             shape=(3 * lay.n_vertices, lay.n_q))
