"""The rigid phase of a mesh whose elastic faces are all cut into rings.

Such a mesh has no rigid bodies for the rigid-body strategy; its rigid-panel
twin (the same pattern thickened with rigid panels, same widths, sub-strips,
hinge models and stiffness) does, and the rigid model is the elastic one's
limit of stiff panels. :class:`RigidStart` steps the twin from the rest state
through the run's stages; its state is then placed on the cells
(:func:`place_cells`), where the finishing strategy goes on. Why: a linear
step on free vertices turns a panel only by stretching it, so a fold through
large angles costs ``newton`` many steps: `docs/architecture.md#elastic-cells`.
"""
from __future__ import annotations

import numpy as np

from ...convergence import Progress
from ..rigid import Rigid
from ..rigid.twin import same_material, twin_model


def in_rings(mesh) -> bool:
    """Whether ``mesh`` has elastic cells, all of them faces cut into rings, and only
    panels and bending hinges (what :func:`rigid_twin_mesh` serves)."""
    return (set(mesh.groups) == {"rigid_panel", "bending_hinge"} and bool(mesh.elastic)
            and all(isinstance(n, tuple) and n[0] == "rings" for n in mesh.elastic.values()))


def rigid_twin_mesh(mesh, pattern):
    """The mesh thickened again with rigid panels (same widths, sub-strips, hinge
    models and stiffness factors), or None where it cannot serve: a mesh without
    elastic cells, one with bars or plates, or groups other than panels and
    bending hinges. Every face cut into rings keeps its strips whole and adds its
    ring points after the rigid mesh's, so the twin's points are the mesh's first
    ones (checked) and :func:`place_cells` maps a twin state onto it."""
    from ...thickening import thicken

    if not in_rings(mesh):
        return None
    twin = thicken(pattern, mesh.thickness, hinge_width=mesh.hinge_width,
                   subdivisions=mesh.subdivisions, **same_material(mesh, pattern))
    m = len(twin.points)
    if m > len(mesh.points) or not np.array_equal(twin.points, mesh.points[:m]):
        return None
    return twin
def place_cells(mesh, twin, twin_x: np.ndarray) -> np.ndarray:
    """(N, 3) mm: positions of ``mesh`` (elastic, in rings) at a state ``twin_x`` of
    its :func:`rigid_twin_mesh`: the twin's points as they are, every ring point
    moved with its face's panel (best-fit rotation and centroid), so the cells
    start at their rest shapes wherever the panels are rigid."""
    from ...measure import element_rotations

    m_twin, m = len(twin.points), len(mesh.points)
    twin_panels, cells = twin.groups["rigid_panel"], mesh.groups["rigid_panel"]
    rotations = element_rotations(twin_panels, twin_x)
    sizes = np.diff(twin_panels.indptr)
    starts = twin_panels.indptr[:-1]
    centres = np.add.reduceat(twin_x[twin_panels.indices], starts, axis=0) / sizes[:, None]
    rest = twin.rest_positions
    rest_centres = np.add.reduceat(rest[twin_panels.indices], starts, axis=0) / sizes[:, None]
    panel_of = np.full(m, -1, dtype=np.int64)  # each 2D point's face panel (in the twin)
    for c in range(len(cells)):
        ids = cells.indices[cells.slots(c)]
        panel_of[ids % m] = twin.panel_of_face[cells.source[c]]
    x = np.empty((2 * m, 3))
    x[:m_twin], x[m:m + m_twin] = twin_x[:m_twin], twin_x[m_twin:]
    new = np.arange(m_twin, m)
    for layer in (0, m):
        p = panel_of[new]
        local = mesh.rest_positions[new + layer] - rest_centres[p]
        x[new + layer] = np.einsum("nij,nj->ni", rotations[p], local) + centres[p]
    return x


class RigidStart:
    """The rigid-panel twin of a mesh in rings, stepped by the ``rigid`` strategy from
    the rest state through the run's stages (module docstring).

    Parameters
    ----------
    model : foldcore.model.Model
        The elastic mesh's model (targets, floors and stage are mirrored from it).
    progress : foldcore.convergence.Progress
    mesh : ThickMesh
        The rigid-panel twin's mesh (:func:`rigid_twin_mesh`).
    options : RigidOptions
    """

    def __init__(self, model, progress, mesh, options):
        self.model, self.progress, self.mesh = model, progress, mesh
        self.twin = twin_model(model, mesh)
        self.twin_progress = Progress()
        self.strategy = Rigid(self.twin, self.twin_progress, options, predictor=True)
        self.steps = 0

    def begin(self) -> None:
        self.twin.mirror_targets(self.model)
        self.twin_progress.stage = self.progress.stage
        self.strategy.begin_run()

    def step(self) -> tuple[float, float]:
        self.steps += 1
        energy, moved = self.strategy.step()
        self.twin_progress.record(energy)
        return energy, moved

    def settled(self, moved: float, limit: float) -> bool:
        self.twin_progress.stage = self.progress.stage
        return self.strategy.report(moved, limit).settled

    def positions(self) -> np.ndarray:
        """The mesh's positions at the twin's state, and the twin's run ended."""
        self.strategy.end_run()
        self.twin_progress.stage = None
        return place_cells(self.model.mesh, self.mesh, self.twin.x)
