"""The rigid-body step's sparse Jacobian, formed explicitly: the reference the
engine's assembled normal equations (strategies/rigid/normal.py) are tested
against. Not used by the engine, which never forms J."""
from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from foldcore.strategies.rigid.state import skew


def strip_position_jacobian(engine):
    """Constant (24 S, 3 N) Jacobian of the strip residuals w.r.t. positions: √w·C ⊗ I₃."""
    ids, sqrt_w = engine.layout.ids, engine.residual.sqrt_w
    s = len(ids)
    e, k, j, d = np.meshgrid(np.arange(s), np.arange(8), np.arange(8), np.arange(3),
                             indexing="ij")
    rows = e * 24 + k * 3 + d
    cols = 3 * ids[e, j] + d
    vals = sqrt_w[e] * ((k == j) - 1.0 / 8.0)
    n = engine.layout.n_vertices
    return sp.csr_matrix((vals.ravel(), (rows.ravel(), cols.ravel())), shape=(24 * s, 3 * n))


def jacobian(engine, state):
    """Sparse J (rows: strip residuals, pins, M/V rows) and r at ``state``."""
    lay, model = engine.layout, engine.residual
    lay.build_columns()
    residual = model.residuals(state)
    rot_e = state.rot_e
    targets = np.einsum("sij,skj->ski", rot_e, model.shape.reshape(-1, 8, 3))
    s = len(lay.ids)
    jr = (model.sqrt_w[:, None, None, None] * skew(targets)).reshape(s, 24, 3)
    rows_r = np.arange(24 * s).reshape(s, 24)
    rot_block = sp.csr_matrix((jr.ravel(),
                               (np.repeat(rows_r.ravel(), 3),
                                np.broadcast_to(3 * np.arange(s)[:, None, None]
                                                + np.arange(3), (s, 24, 3)).ravel())),
                              shape=(24 * s, 3 * s))
    pas = lay.passive_ids
    d_t = model.angle_columns(rot_e)[pas] * model.sqrt_w[pas, None, None]
    phi_block = sp.csr_matrix((d_t.ravel(), (rows_r[pas].ravel(), np.repeat(lay.passive_of, 24))),
                              shape=(24 * s, lay.n_folds))
    strips = sp.hstack([strip_position_jacobian(engine) @ engine.kinematics.position_map(state),
                        rot_block, phi_block])
    extra = model.extra_rows(state)
    jac = strips if extra is None else sp.vstack([strips, extra])
    return jac.tocsc(), residual


def apply(engine, state, delta):
    """``state`` moved by an increment of the unknowns."""
    return engine.kinematics.apply(state, delta, engine.lo, engine.hi)
