"""Coarse twin of a thick mesh: the rigid-body strategy's first steps on one-strip hinges.

A fold from the flat sheet costs the rigid-body strategy most of its steps,
and each step factorises a normal matrix whose unknowns are mostly
hinge-interior vertices. With the axis and arc hinges, k sub-strips bent
alike form one arc of the crease's bend, the arc a single strip makes, so
the panels' equilibrium is the same for every k wherever the strips' energy
vanishes. The twin is the same pattern thickened with one sub-strip per
crease (same widths, hinge models and stiffness factors); its steps take the
run from the rest state to the twin's equilibrium, and the mesh's own engine
then starts there (:meth:`Twin.hand_over`: panels and crease angles copied,
hinge-interior vertices placed on their strips' bent shapes). Where the
sub-strips do change the equilibrium (binding, Eq. 8 trapezoids) the mesh's
own steps finish. Why and what it saves: `docs/architecture.md#the-coarse-twin`.
"""
from __future__ import annotations

import numpy as np

from ...convergence import Progress
from ...model import Model
from .engine import RigidBodySolver


def twin_mesh(mesh, pattern):
    """The mesh thickened again with one sub-strip per crease, or None where the twin
    cannot serve: every crease already one strip wide, a crease split along its
    length (elastic plates), groups other than rigid panels and bending hinges,
    or Eq. 8 hinges (k trapezoids in series are not one trapezoid)."""
    from ...thickening import thicken

    if set(mesh.groups) != {"rigid_panel", "bending_hinge"} or mesh.elastic:
        return None
    if mesh.hinge_model is None or (mesh.hinge_model == "eq8").any():
        return None  # Eq. 8 trapezoids in series are no single trapezoid
    creases = mesh.subdivisions > 0
    if not (mesh.subdivisions[creases] > 1).any() or (mesh.segments[creases] != 1).any():
        return None
    return thicken(pattern, mesh.thickness, hinge_width=mesh.hinge_width,
                   subdivisions=np.where(creases, 1, 0), **same_material(mesh, pattern))


def same_material(mesh, pattern) -> dict:
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


def twin_model(model, mesh) -> Model:
    """A model of ``mesh`` (another thickening of ``model``'s pattern) with ``model``'s
    actuation, stops and linear-solver backend."""
    return Model(mesh, model.pattern, backend=model.system.backend,
                 stop_stiffness=model.controls.stop_factor, actuation=model.actuation)


class Twin:
    """The coarse twin's model and rigid-body engine, mirroring a model's targets.

    Parameters
    ----------
    model : foldcore.model.Model
        The model whose run the twin starts.
    mesh : ThickMesh
        The twin's mesh (:func:`twin_mesh`).
    options : RigidOptions
    """

    def __init__(self, model, mesh, options):
        self.mesh = mesh
        self.model = twin_model(model, mesh)
        if model.contact is not None:  # the same panels, kept apart as the mesh's are
            self.model.contact = model.contact.twin(mesh, model.pattern)
        self.progress = Progress()
        self.engine = RigidBodySolver(self.model, self.progress, options)
        self.model.x = self.engine.x

    def mirror(self, model, progress) -> None:
        """The twin's stage, targets and floors from ``model``'s and ``progress``'s
        (crease by crease: a strip carries its crease's floor over its k strips)."""
        self.progress.stage = progress.stage  # a branch stage takes no extrapolation
        self.model.mirror_targets(model)

    def hand_over(self, engine) -> None:
        """Put ``engine`` (the fine mesh's) at the twin's state (:func:`hand_over`); its
        contact goes on from the twin's (κ, the pairs that cut the last step)."""
        hand_over(self.engine, engine)
        contact = engine.model.contact
        if contact is not None and self.model.contact is not None:
            panels = np.empty(len(self.mesh.panel_of_face), dtype=np.int64)
            panels[self.mesh.panel_of_face] = engine.model.mesh.panel_of_face
            contact.take_over(self.model.contact, panels)


def hand_over(source, target) -> None:
    """Put the engine ``target`` at the state of ``source``, an engine of another
    thickening of the same pattern: panels' rotations and centroids, passive creases'
    angles, hinge-interior vertices on their strips' bent shapes; the run's energy
    scale and damping carry over. A source that never stepped hands over nothing."""
    if not source.laid_out:
        return
    fine_faces = target.model.mesh.panel_of_face
    source_faces = source.model.mesh.panel_of_face
    rot_p, c_p = target.rot_p.copy(), target.c_p.copy()
    rot_p[fine_faces], c_p[fine_faces] = source.rot_p[source_faces], source.c_p[source_faces]
    fold_of_edge = np.full(source.model.pattern.n_edges, np.nan)
    fold_of_edge[source.fold_edges()] = source.folds()
    target.adopt(rot_p, c_p, fold_of_edge, energy_scale=source.energy_scale, lam=source.lam)
