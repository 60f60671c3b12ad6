"""The thin sheet settles where Origami Simulator settles, on its own files.

Ground truth: Origami Simulator's own states (tests/data/origami_simulator/,
recorded by bench/os_library.py from its page: node positions once its
dynamics are still, at 30, 60 and 90 %). The sheet is built on Origami
Simulator's own mesh (its triangulated FOLD data in the state: same vertices,
triangles and creases), so the models and solvers alone are compared; the
angles are measured by an independent numpy dihedral (Origami Simulator's
formula: atan2 of the normals' cross and dot products about the crease).

Tolerance: Origami Simulator calls a state still when no node moves more than
1e-7 (unit bounding radius) over 1 000 steps; with its damping (ratio 0.45)
the slowest modes of these sheets take 10⁴–10⁵ steps to decay, so its nodes
can sit up to ~1e-5 from equilibrium, ~1e-4 rad (0.006°) on a facet 0.1
high. The angles must agree within 0.01°.
"""
from __future__ import annotations

import gzip
import json
from pathlib import Path

import numpy as np
import pytest

from foldcore.pattern import CreasePattern
from foldcore.sheet import build_sheet, fold_sheet

STATES = Path(__file__).parent / "data" / "origami_simulator"
SMALL = ("Bases__birdBase", "Bases__waterbombBase", "Bases__squareBase", "Bases__frogBase",
         "Origami__flappingBird", "SimpleFolds__simpleVertex", "SimpleFolds__mapfold",
         "SimpleFolds__russianTriangle", "Origami__singlesquaretwist")
TOLERANCE_DEG = 0.01


def load(name: str) -> dict:
    with gzip.open(STATES / f"{name}.json.gz", "rt") as fh:
        state = json.load(fh)
    fold = state["fold"]
    fold.setdefault("edges_vertices", state["beams"])   # stored once when equal
    fold.setdefault("faces_vertices", state["faces"])
    return state


def mesh_pattern(state: dict) -> CreasePattern:
    """Origami Simulator's triangulated FOLD data as a pattern in foldcore's plane
    (x, −z): vertex i is its node i."""
    fold = state["fold"]
    xy = np.array(fold["vertices_coords"], dtype=float)[:, [0, 2]] * [1.0, -1.0]
    angles = [np.nan if a is None else a for a in fold["edges_foldAngle"]]
    return CreasePattern(xy, fold["edges_vertices"], fold["edges_assignment"],
                         fold_angles=angles, faces=[np.array(f) for f in fold["faces_vertices"]],
                         source=state["svg"])


def os_angles_deg(state: dict, positions: np.ndarray) -> np.ndarray:
    """Origami Simulator's signed fold angle of every M/V crease (its type 1), degrees,
    at positions (N, 3) in its axes."""
    creases = np.array([c for c in state["creases"] if c[5] == 1])
    a, b, c, d = (positions[creases[:, k].astype(int)] for k in range(4))
    axis = (b - a) / np.linalg.norm(b - a, axis=1)[:, None]
    n1 = np.cross(c - a, b - a)
    n2 = np.cross(b - a, d - a)
    n1 /= np.linalg.norm(n1, axis=1)[:, None]
    n2 /= np.linalg.norm(n2, axis=1)[:, None]
    x = np.einsum("ij,ij->i", n1, n2)
    y = np.einsum("ij,ij->i", np.cross(n1, axis), n2)
    return np.degrees(np.arctan2(y, x))


def in_os_axes(positions: np.ndarray) -> np.ndarray:
    """foldcore's (x, −z, y) positions back in Origami Simulator's (x, y, z)."""
    return np.column_stack([positions[:, 0], positions[:, 2], -positions[:, 1]])


@pytest.mark.parametrize("name", SMALL)
def test_the_sheet_settles_where_origami_simulator_settles(name):
    state = load(name)
    pattern = mesh_pattern(state)
    sheet = build_sheet(pattern)
    # the sheet cut no face of its own: the mesh is Origami Simulator's
    assert sorted(map(sorted, sheet.triangles.tolist())) == sorted(map(sorted, state["faces"]))
    compared = 0
    for entry in state["folds"]:
        if not entry.get("settled"):
            continue
        fold = fold_sheet(sheet, entry["percent"], pattern_edges=pattern.n_edges)
        assert fold.converged, (name, entry["percent"], fold.reason)
        theirs = os_angles_deg(state, np.array(entry["positions_b"], dtype=float))
        mine = os_angles_deg(state, in_os_axes(fold.positions))
        delta = np.abs((mine - theirs + 180.0) % 360.0 - 180.0)
        assert delta.max() < TOLERANCE_DEG, (name, entry["percent"], delta.max())
        compared += 1
    assert compared >= 1, f"{name}: no settled state to compare"


def test_the_states_say_where_they_come_from():
    sources = (STATES / "SOURCES.md").read_text()
    assert "github.com/amandaghassaei/OrigamiSimulator" in sources and "MIT" in sources
    state = load(SMALL[0])
    assert len(state["origami_simulator_commit"]) == 40
    assert state["settings"]["axialStiffness"] == 20 and state["settings"]["faceStiffness"] == 0.2
