"""Contact for a strategy whose unknowns are the vertices themselves (``newton``).

The barrier C = κ Σ b of :class:`foldcore.contact.ContactModel` joins the
strategy's energy E = Σ w‖x − P(x)‖²: ½∇C adds to its gradient K x − b and
½∇²C (each term's PSD-projected block) to its Gauss–Newton matrix, in
blocks over each touching pair's vertices that the matrix's fixed pattern
takes in as they appear (a new pattern, so a new symbolic analysis, once per
new pair); every trial is shortened until the straight-line motion to it is
collision-free. Units: mm, energies mm⁵.
"""
from __future__ import annotations

import numpy as np

MAX_CUTS = 30  # shortenings of one trial toward a contact before it is not taken


class VertexContact:
    """The contact terms of a vertex-based strategy's steps.

    Parameters
    ----------
    model : foldcore.model.Model
        Its ``contact`` (a ContactModel) is used.
    """

    def __init__(self, model):
        self.model, self.contact = model, model.contact
        self._keys: dict = {}  # size m → {ids tuple: row}, every block the pattern holds
        self.version = 0  # grows when a block joins the pattern

    @property
    def holds_rigid_motion(self) -> bool:
        """Obstacles hold the sheet in space: its rigid motions cost energy."""
        return self.contact.obstacles is not None

    def state(self, x: np.ndarray, adapt: bool = True):
        """The contacts at x of panels no crease joins (panels a crease joins are its
        hinge's to hold: these panels are not exactly rigid, and at a pivot their
        faces meet within what a rigid check allows), κ first adapted to them
        (``ContactModel.stiffen``) where ``adapt``."""
        state = self.contact.state(x, joined=False)
        if adapt and self.contact.stiffen(state):
            state = self.contact.state(x, joined=False)
        return state

    def gradient(self, state) -> np.ndarray:
        """(3N,) ½∇C, mm⁴."""
        return 0.5 * self.contact.gradient(state).ravel()

    def blocks(self, state) -> tuple[list, list]:
        """([(n, m) ids per block size], [(n, 3m, 3m) values of ½∇²C]): every block the
        pattern holds (a touching pair's vertices), zero where it does not touch now."""
        found = {}
        for ids, block in self.contact.hessian_blocks(state):
            keys = self._keys.setdefault(len(ids), {})
            key = tuple(int(i) for i in ids)
            if key not in keys:
                keys[key] = len(keys)
                self.version += 1
            m = len(ids)
            values = found.setdefault(m, np.zeros((len(keys), 3 * m, 3 * m)))
            if len(values) < len(keys):
                values = found[m] = np.concatenate(
                    [values, np.zeros((len(keys) - len(values), 3 * m, 3 * m))])
            values[keys[key]] += 0.5 * block.toarray()
        runs, values = [], []
        for m, keys in sorted(self._keys.items()):
            runs.append(np.array(list(keys), dtype=np.int64).reshape(len(keys), m))
            values.append(found.get(m, np.zeros((len(keys), 3 * m, 3 * m))))
        return runs, values

    def collision_free(self, x: np.ndarray, trial: np.ndarray) -> np.ndarray:
        """``trial`` moved back toward x until the straight-line motion x → it brings no
        two panels (or a panel and an obstacle) into contact; x where that takes more
        than ``MAX_CUTS`` shortenings."""
        for _ in range(MAX_CUTS):
            fraction = self.contact.free_fraction(x, trial, joined=False)
            if fraction >= 1.0:
                return trial
            trial = x + fraction * (trial - x)
        return x
