"""Run-time arrays of the element groups: parameters, projections, state."""
from __future__ import annotations

import numpy as np

import elements

from ..errors import SimulationError


class GroupState:
    """Run-time arrays of one element group: parameters, residuals, state.

    For a type with a ``prepare`` kernel (:class:`elements.ElementType`) it also
    keeps the prepared target shapes, recomputed on the first projection after
    :meth:`set_params` changed the parameters (write them only through it).

    Parameters
    ----------
    group : foldcore.mesh.ElementGroup
    offset : int
        First slot of this group in the model's stacked slot targets.

    Attributes
    ----------
    params : (n, p) float
        The group's parameters (a copy: the mesh is never changed).
    energy : (n,) float
        Each element's residual at the last projection, mm².
    state : (n, s) float
        Each element's state columns at the last projection.
    slots : slice
        This group's rows of the model's slot targets.
    """

    def __init__(self, group, offset: int):
        self.group = group
        self.etype = elements.get(group.kind)
        self.params = np.array(group.params, dtype=np.float64, order="C")
        self.energy = np.zeros(len(group))
        self.state = np.zeros((len(group), len(self.etype.state)))
        self.slots = slice(offset, offset + len(group.indices))
        self._shapes = None  # prepared target shapes (nnz, 3), mm, allocated on first use
        self._prepared = False  # whether _shapes matches params

    def set_params(self, rows, column: int, values) -> None:
        """``params[rows, column] = values``; the prepared shapes follow on next use."""
        self.params[rows, column] = values
        self._prepared = False

    def project(self, x: np.ndarray, targets: np.ndarray, weights: np.ndarray) -> float:
        """Project every element at ``x`` (N, 3) mm into this group's rows of
        ``targets``; returns the weighted energy Σ w·residual, mm⁵."""
        self.project_into(x, targets[self.slots], self.energy, self.state)
        return float(self.energy @ weights)

    def project_into(self, x, out, energy, state) -> None:
        """Project every element at ``x`` into the given arrays (this group's
        target rows (nnz, 3) mm, residuals (n,) mm², state), with the kernel the
        iterations use (``prepared_batch`` when the type has one)."""
        g, etype = self.group, self.etype
        if etype.prepared_batch is None:
            etype.batch(x, g.indptr, g.indices, g.rest, self.params, out, energy, state)
            return
        if not self._prepared:
            if self._shapes is None:
                self._shapes = np.zeros_like(g.rest)
            etype.prepare(g.indptr, g.rest, self.params, self._shapes)
            self._prepared = True
        etype.prepared_batch(x, g.indptr, g.indices, g.rest, self._shapes, self.params, out,
                             energy, state)


def group_states(mesh) -> tuple[list[GroupState], int]:
    """A :class:`GroupState` per non-empty group of ``mesh`` and the total slot count."""
    states, offset = [], 0
    for g in mesh.groups.values():
        if len(g):
            states.append(GroupState(g, offset))
            offset += len(g.indices)
    return states, offset


def check_every_vertex_used(states, n_vertices: int) -> None:
    """A vertex in no element has no equation: K would be singular there."""
    used = np.zeros(n_vertices, dtype=bool)
    for state in states:
        used[state.group.indices] = True
    if not used.all():
        raise SimulationError(f"vertex {int(np.argmin(used))} belongs to no element "
                              f"({int((~used).sum())} such vertices): the mesh's groups "
                              "must cover every vertex")
