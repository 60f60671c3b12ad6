"""Hand-over between a rigid-body engine and another model of the same pattern.

A coarse twin (:mod:`.twin`) folds the pattern with one sub-strip per crease;
its equilibrium is handed to the mesh's own engine by :meth:`HandOver.adopt`:
panels and passive crease angles copied, hinge-interior vertices placed on
their strips' bent shapes (:meth:`HandOver.place_interiors`), after which
:meth:`HandOver.strips_placed_within` says whether the twin's verdict holds
for the mesh. Units: mm, rad.
"""
from __future__ import annotations

import numpy as np

from . import normal


class HandOver:
    """Adopting another model's state into an engine.

    Parameters
    ----------
    engine : RigidBodySolver
    """

    def __init__(self, engine):
        self.engine = engine
        self._chains = None  # place_interiors' batches, built on first use

    def adopt(self, rot_p, c_p, fold_of_edge, energy_scale: float, lam: float) -> None:
        """Continue from panels at rotations ``rot_p`` (P, 3, 3) and centroids ``c_p``
        (P, 3) mm, passive creases bent by ``fold_of_edge`` (E,) rad (per pattern
        edge; clamped to their intervals), hinge-interior vertices placed on their
        strips' bent shapes: the state another model of the same pattern reached.
        ``energy_scale`` (mm⁵) is the run's largest energy so far, ``lam`` its
        damping."""
        engine = self.engine
        engine.residual.sync_weights()
        engine.read_targets()  # the column layout and the angles' intervals
        engine.rot_p, engine.c_p = np.asarray(rot_p, float), np.asarray(c_p, float)
        folds = np.asarray(fold_of_edge, float)[engine.layout.fold_edges()]
        engine.layout.set_folds(np.clip(folds, engine.lo, engine.hi), engine.phi)
        engine.y = self.place_interiors()
        engine.x = engine.kinematics.positions(engine.rot_p, engine.c_p, engine.y)
        engine.fitted, engine.ends = False, []
        lm = engine.lm
        lm.contraction, lm.accepted_move = np.nan, None
        lm.forget()
        engine.stopping.energy_scale = max(engine.stopping.energy_scale, float(energy_scale))
        lm.lam = min(float(lam), engine.options.lambda_start)

    def strips_placed_within(self, limit: float) -> bool:
        """Whether every strip vertex lies within ``limit`` mm of its strip's bent shape
        (strip rotations fitted; the strips' rows over √w): the state is then an
        equilibrium of this model to that distance in every strip — for a handed-over
        state, where the other model's verdict then holds for this one. Leaves the
        strip rotations fitted."""
        engine = self.engine
        residual_model = engine.residual
        residual_model.update_shapes(engine.phi)
        residual_model.fit_rotations(engine.x, engine.rot_e)
        engine.fitted = True
        residual = residual_model.strip_rows(engine.x, engine.rot_e)
        sqrt_w = residual_model.sqrt_w
        scale = np.where(sqrt_w > 0, sqrt_w, 1.0)
        return bool(np.abs(residual / scale[:, None, None]).max(initial=0.0) <= limit)

    def place_interiors(self) -> np.ndarray:
        """(n_free, 3) mm: hinge-interior vertices where the strips' bent shapes put
        them, strip after strip across each crease from the panel its first strip
        touches (each strip's known side fitted rigidly to its bent shape, the
        other side taken from it). Exact where the crease's strips meet its far
        panel too; the steps correct the rest. Vertices no chain reaches keep their
        current positions."""
        engine = self.engine
        lay = engine.layout
        engine.residual.update_shapes(engine.phi)
        shape = engine.residual.shape.reshape(-1, 8, 3)
        x = engine.kinematics.positions(engine.rot_p, engine.c_p, engine.y)
        for batch, known, unknown in self._interior_chains():
            ids, bent = lay.ids[batch], shape[batch]
            src, dst = (np.take_along_axis(ids, side, 1) for side in (known, unknown))
            t_src = np.take_along_axis(bent, known[:, :, None], 1)
            t_dst = np.take_along_axis(bent, unknown[:, :, None], 1)
            centre = t_src.mean(axis=1, keepdims=True)
            normal.place_sides(x, src, dst, t_src - centre, t_dst - centre)
        return x[lay.free]

    def _interior_chains(self) -> list:
        """[(strips (b,), known local vertices (b, 4), unknown ones (b, 4))] per place
        in the creases' series of strips; built once."""
        if self._chains is not None:
            return self._chains
        lay = self.engine.layout
        known = lay.owner >= 0
        chains = [np.asarray(c) for c in self.engine.model.mesh.strips_of_crease.values()]
        self._chains = []
        for j in range(max((len(c) for c in chains), default=1) - 1):
            batch = np.array([c[j] for c in chains if len(c) > j + 1], dtype=np.int64)
            mask = known[lay.ids[batch]]
            fit = mask.sum(axis=1) == 4  # a side known, the other to place
            batch, mask = batch[fit], mask[fit]
            order = np.argsort(~mask, axis=1, kind="stable")
            self._chains.append((batch, order[:, :4], order[:, 4:]))
            known[lay.ids[batch]] = True
        return self._chains
