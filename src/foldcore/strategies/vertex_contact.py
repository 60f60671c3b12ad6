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

    def state(self, x: np.ndarray):
        """The contacts at x of panels no crease joins (panels a crease joins are its
        hinge's to hold: these panels are not exactly rigid, and at a pivot their
        faces meet within what a rigid check allows)."""
        return self.contact.state(x, joined=False)

    def adapted(self, x: np.ndarray, state=None):
        """The contacts at x (``state``, if given, is theirs), κ first adapted to them
        (``ContactModel.stiffen``): the same ``state`` where κ held, else taken anew."""
        state = self.state(x) if state is None else state
        return self.state(x) if self.contact.stiffen(state) else state

    def gradient(self, state) -> np.ndarray:
        """(3N,) ½∇C, mm⁴."""
        return 0.5 * self.contact.gradient(state).ravel()

    def blocks(self, state) -> tuple[list, list]:
        """([(n, m) ids per block size], [(n, 3m, 3m) values of ½∇²C]): every block the
        pattern holds (a touching pair's vertices), zero where it does not touch now."""
        terms = [(tuple(int(i) for i in ids), block)
                 for ids, block in self.contact.hessian_blocks(state)]
        for key, _ in terms:
            keys = self._keys.setdefault(len(key), {})
            if key not in keys:
                keys[key] = len(keys)
                self.version += 1
        values = {m: np.zeros((len(keys), 3 * m, 3 * m)) for m, keys in self._keys.items()}
        for key, block in terms:
            values[len(key)][self._keys[len(key)][key]] += 0.5 * block.toarray()
        sizes = sorted(self._keys)
        return ([np.array(list(self._keys[m]), dtype=np.int64).reshape(-1, m) for m in sizes],
                [values[m] for m in sizes])

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
