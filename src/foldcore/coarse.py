"""Coarse twin of a thick mesh: the rigid-body strategy's first steps on one-strip hinges.

Why: a fold from the flat sheet costs the rigid-body strategy most of its
steps (a thin Miura 20 × 20 leaves flat in ~65 Levenberg–Marquardt steps
whatever its target), and each step factorises a normal matrix whose
unknowns are mostly hinge-interior vertices: with the default 4 sub-strips
per crease 27 360 of the 39 633 unknowns. The rigid-body model's panels do
not see the sub-strips: with the axis and arc hinges, k sub-strips bent
alike form one arc of the crease's bend, the arc a single strip makes (the
axis length is homogeneous in the width, :func:`elements.bending_hinge.axis_length`),
so the panels' equilibrium is the same for every k wherever the strips'
energy vanishes (measured: thin Miura 5 × 5 folded with k = 1 and k = 4,
panels equal to 6e-10 mm). The twin is the same pattern thickened with one
sub-strip per crease (same widths, hinge models and stiffness factors). Its
steps take the run from the rest state to the twin's equilibrium; the mesh's
own engine then starts there (:meth:`Twin.hand_over`: panels and crease
angles copied, hinge-interior vertices placed on their strips' bent shapes),
where its first step typically confirms it. Where the sub-strips do change
the equilibrium (binding, Eq. 8 trapezoids) the mesh's own steps finish
from the twin's state.

Measured (2-core Xeon guest, 2026-12-02, hybrid, tolerance 1e-8): see
:mod:`foldcore.strategies.rigid` and the README's time-to-solution table.
"""
from __future__ import annotations

import numpy as np

from elements.bending_hinge import FLOOR


def twin_mesh(mesh, pattern):
    """The mesh thickened again with one sub-strip per crease, or None where the twin
    cannot serve: every crease already one strip wide, a crease split along its
    length (elastic plates), groups other than rigid panels and bending hinges
    (the rigid-body strategy takes no others), or Eq. 8 hinges (k trapezoids in
    series are not one trapezoid: the twin's equilibrium is another, and the
    hinge study's Eq. 8 strips ended farther from Eq. 7's radius at k = 8 than at
    k = 4 when started from it, tests/test_scenes.py)."""
    from .thickening import thicken

    if set(mesh.groups) != {"rigid_panel", "bending_hinge"} or mesh.elastic:
        return None
    if mesh.hinge_model is None or (mesh.hinge_model == "eq8").any():
        return None  # Eq. 8 trapezoids in series are no single trapezoid
    creases = mesh.subdivisions > 0
    if not (mesh.subdivisions[creases] > 1).any() or (mesh.segments[creases] != 1).any():
        return None
    return thicken(pattern, mesh.thickness, hinge_width=mesh.hinge_width,
                   subdivisions=np.where(creases, 1, 0), **_same_material(mesh, pattern))


def _same_material(mesh, pattern) -> dict:
    """thicken()'s ``hinge`` models and ``stiffness`` factors that rebuild ``mesh``'s
    (factors read back from its weights over its volumes)."""
    strips = mesh.groups["bending_hinge"]
    panels = mesh.groups["rigid_panel"]
    hinge_factor = np.ones(pattern.n_edges)
    hinge_factor[strips.source] = strips.weights / strips.volumes
    panel_factor = np.ones(len(pattern.faces))
    panel_factor[panels.source] = panels.weights / panels.volumes
    models = np.where(mesh.hinge_model == "", None, mesh.hinge_model)  # "" on boundaries
    return {"hinge": models, "stiffness": {"hinge": hinge_factor, "panel": panel_factor}}


class Twin:
    """A coarse twin Simulation (rigid strategy) that mirrors a Simulation's targets.

    Parameters
    ----------
    sim : Simulation
        The simulation whose run the twin starts; its pattern, actuation, stop
        stiffness and linear-solver backend are the twin's.
    mesh : ThickMesh
        The twin's mesh (:func:`twin_mesh`).
    """

    def __init__(self, sim, mesh):
        from .simulation import Simulation

        self.mesh = mesh
        self.sim = Simulation(mesh, sim.pattern, solver="rigid",
                              backend=sim.system.backend,
                              stop_stiffness=sim._stop_factor,
                              actuation=sim.actuation, branch_floor_deg=0.0)
        self.engine = self.sim.strategy.engine
        self._edge_of_fine = sim._hinges.group.source
        self._k_fine = sim.mesh.subdivisions[self._edge_of_fine].astype(float)
        self._edge = self.sim._hinges.group.source
        self._k = mesh.subdivisions[self._edge].astype(float)

    def mirror(self, sim) -> None:
        """The twin's stage, targets (``sim``'s fold targets and fold percent, through its own
        :meth:`Simulation._apply_fold_targets`) and floors (crease by crease: a strip
        carries its crease's floor over its k sub-strips) from ``sim``'s."""
        twin = self.sim
        twin.stage = sim.stage  # the stage too (a branch stage takes no extrapolation)
        twin._fold_targets, twin._percent = sim._fold_targets.copy(), sim._percent
        twin._apply_fold_targets()  # strip targets, passive flags, weights
        floor = np.full(sim.pattern.n_edges, np.nan)
        floor[self._edge_of_fine] = sim._hinges.params[:, FLOOR] * self._k_fine
        twin._hinges.set_params(slice(None), FLOOR, floor[self._edge] / self._k)

    def hand_over(self, engine) -> None:
        """Put ``engine`` (the fine mesh's :class:`~foldcore.rigid_body.RigidBodySolver`)
        at the twin's state: panels' rotations and centroids, passive creases'
        angles, hinge-interior vertices on their strips' bent shapes
        (:meth:`~foldcore.rigid_body.RigidBodySolver.place_interiors`); the run's
        energy scale and damping carry over. A twin that never stepped hands over
        nothing."""
        twin = self.engine
        if not twin.laid_out:
            return
        fine_faces, twin_faces = engine.sim.mesh.panel_of_face, self.mesh.panel_of_face
        rot_p, c_p = engine.rot_p.copy(), engine.c_p.copy()
        rot_p[fine_faces], c_p[fine_faces] = twin.rot_p[twin_faces], twin.c_p[twin_faces]
        fold_of_edge = np.full(self.sim.pattern.n_edges, np.nan)
        fold_of_edge[twin.fold_edges()] = twin.folds()
        engine.adopt(rot_p, c_p, fold_of_edge, energy_scale=twin.energy_scale, lam=twin.lam)


def in_rings(mesh) -> bool:
    """Whether ``mesh`` has elastic cells, all of them faces cut into rings, and only
    panels and bending hinges (what :func:`rigid_twin_mesh` serves)."""
    return (set(mesh.groups) == {"rigid_panel", "bending_hinge"} and bool(mesh.elastic)
            and all(isinstance(n, tuple) and n[0] == "rings" for n in mesh.elastic.values()))


def rigid_twin_mesh(mesh, pattern):
    """The mesh thickened again with rigid panels (same widths, sub-strips, hinge
    models and stiffness factors), or None where it cannot serve: a mesh without
    elastic cells, one with bars or plates (their strips are split or their
    points come first), or groups other than panels and bending hinges. Every
    face of an elastic mesh cut into rings keeps its strips whole and adds its
    ring points after the rigid mesh's, so the twin's points are the mesh's
    first ones (checked) and :func:`place_cells` maps a twin state onto it."""
    from .thickening import thicken

    if not in_rings(mesh):
        return None
    twin = thicken(pattern, mesh.thickness, hinge_width=mesh.hinge_width,
                   subdivisions=mesh.subdivisions, **_same_material(mesh, pattern))
    m = len(twin.points)
    if m > len(mesh.points) or not np.array_equal(twin.points, mesh.points[:m]):
        return None
    return twin


def place_cells(mesh, twin, twin_x: np.ndarray) -> np.ndarray:
    """(N, 3) mm: positions of ``mesh`` (elastic, in rings) at a state ``twin_x`` of
    its :func:`rigid_twin_mesh`: the twin's points as they are, every ring point
    moved with its face's panel (best-fit rotation and centroid), so the cells
    start at their rest shapes wherever the panels are rigid."""
    from .measure import element_rotations

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
