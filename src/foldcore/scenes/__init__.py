"""The paper's scenes: each builds its pattern, folds it, and measures the quantities
the paper reports, beside the closed forms of :mod:`foldcore.kinematics` where they exist.

>>> from foldcore import scenes
>>> run = scenes.run("d4v", quick=True)          # doctest: +SKIP
>>> run.quantities["flat"]["fold_angles_deg"]     # doctest: +SKIP

Every scene module defines ``run(quick=False, solver=None, contact="auto") ->
SceneRun`` and ``headline(quantities) -> str`` (one line for the demo), and may
set ``CONTACT = True`` where contact is what it shows (on even where "auto"
would not be);
``quick`` lowers iteration budgets for tests, never the geometry. Which
scenes exist is known without importing them (``NAMES``), so the CLI's
``--help`` and this package stay light.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from importlib import import_module

import numpy as np

from ..errors import FoldcoreError

NAMES = {
    "d4v": "Pehrson's flat-foldable degree-4 vertex, intermediate and flat states",
    "waterbomb": "6-crease waterbomb base, its two stable positions (paper Table 1)",
    "miura": "Miura-ori sheet on its rigid-folding path",
    "hinge-study": "one hinge folded 180°: bend radius and angle error vs subdivisions",
    "groove-bar": "elastic bar with a 90° V-groove joint pulled past its limit",
    "chain": "linear chain of spherical mechanisms (Miura strip) pushed across one end",
    "box": "five-crease hexagonal box (reconstructed) folded at H = 1 and 4 mm: volumes",
    "gripper": "jaws of two coupled spherical mechanisms (reconstructed), squeezed shut "
               "and on a ball",
}


@dataclass
class SceneRun:
    """What a scene produced.

    Attributes
    ----------
    name : str
    pattern : CreasePattern
        The pattern as last actuated.
    mesh : ThickMesh
    thickness : float, mm
    result : Result
        The final state (what FOLD/PNG outputs show).
    quantities : dict
        The scene's own measurements (JSON-ready; angles in degrees, lengths mm).
    settings : dict
        Solver, tolerances and budgets used (JSON-ready).
    gallery : list of (title, pattern, mesh, positions)
        A scene of several runs (hinge-study): each run's folded state, drawn
        side by side in NAME.png (:func:`write`); empty: the PNG is ``result``.
    """

    name: str
    pattern: object
    mesh: object
    thickness: float
    result: object
    quantities: dict = field(default_factory=dict)
    settings: dict = field(default_factory=dict)
    gallery: list = field(default_factory=list)


def run(name: str, quick: bool = False, solver: str | None = None,
        contact: str | bool | None = None) -> SceneRun:
    """Run scene ``name`` (see ``NAMES``).

    Parameters
    ----------
    quick : bool
        Lower iteration budgets (tests); the geometry is unchanged.
    solver : str, optional
        Strategy (``foldcore.strategies.SOLVERS``); default: the scene's own.
    contact : {"auto", "on", "off"} or bool, optional
        Keep panels from passing through each other (:mod:`foldcore.contact`;
        ``Simulation``'s ``contact``); None: the scene's own choice (its
        ``CONTACT``, else ``"auto"``: on wherever its runs can).
    """
    module = _module(name)
    if contact is None:
        contact = getattr(module, "CONTACT", "auto")
    return module.run(quick=quick, solver=solver, contact=contact)


def headline(name: str, quantities: dict) -> str:
    """One short line of scene ``name``'s quantities (angles in degrees, lengths mm)."""
    return _module(name).headline(quantities)


def _module(name: str):
    if name not in NAMES:
        raise FoldcoreError(f"unknown scene {name!r} (available: {', '.join(NAMES)})")
    return import_module(f"{__name__}.{name.replace('-', '_')}")


def write(scene: SceneRun, out, png: bool = True) -> list:
    """Write ``NAME.fold``, ``NAME.json`` (report + quantities) and ``NAME.png`` to ``out``.

    Returns the paths written. The PNG needs the ``render`` extra (pyvista).
    """
    from pathlib import Path

    from ..outputs import write_result

    folder = Path(out)
    folder.mkdir(parents=True, exist_ok=True)
    base = folder / scene.name
    paths = {"fold": base.with_suffix(".fold"), "report": base.with_suffix(".json"),
             "png": base.with_suffix(".png") if png else None}
    picture = gallery_image(scene.gallery) if png and scene.gallery else None
    write_result(scene.result, scene.pattern, scene.mesh, scene.thickness,
                 {"scene": scene.name, **scene.settings}, quantities=scene.quantities,
                 picture=picture, **paths)
    return [p for p in paths.values() if p is not None]


#: Pixels of one gallery tile, and tiles per row.
TILE, TILES_PER_ROW = (320, 240), 6


def gallery_image(gallery: list) -> np.ndarray:
    """(H, W, 3) uint8: each (title, pattern, mesh, positions) rendered in a tile of
    ``TILE`` pixels, ``TILES_PER_ROW`` to a row (fewer: one row of them; white where
    the last row is short)."""
    from ..animate import render_frames

    tiles = [render_frames(pattern, mesh, [positions], size=TILE, titles=[title],
                           progress=False)[0] for title, pattern, mesh, positions in gallery]
    per_row = min(TILES_PER_ROW, len(tiles))  # a short gallery is one row of its own width
    rows = []
    for start in range(0, len(tiles), per_row):
        row = tiles[start:start + per_row]
        row += [np.full_like(tiles[0], 255)] * (per_row - len(row))
        rows.append(np.hstack(row))
    return np.vstack(rows)
