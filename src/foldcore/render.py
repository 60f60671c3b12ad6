"""Offscreen PNG renders of a folded thick mesh (pyvista, imported only here).

Panels are drawn light grey; hinge sub-strips are coloured by their crease's
assignment: valley blue, mountain red, other creases amber.
"""
from __future__ import annotations

import os

import numpy as np

HINGE_COLOURS = {"V": (0.20, 0.40, 0.85), "M": (0.85, 0.25, 0.20),
                 "U": (0.95, 0.65, 0.10), "F": (0.60, 0.60, 0.60)}
PANEL_COLOUR = (0.88, 0.88, 0.86)


def _element_surface(group, chosen, positions):
    """PolyData of the prisms ``chosen`` (element indices) of a group at ``positions``."""
    import pyvista as pv

    faces = []
    for i in chosen:
        ids = group.indices[group.slots(i)]
        n = len(ids) // 2
        top, bot = ids[:n], ids[n:]
        faces += [np.r_[n, top], np.r_[n, bot[::-1]]]
        faces += [np.r_[4, top[(j + 1) % n], top[j], bot[j], bot[(j + 1) % n]] for j in range(n)]
    return pv.PolyData(np.asarray(positions), np.concatenate(faces))


def render_png(pattern, mesh, positions, path, size=(1024, 768), view="iso") -> None:
    """Render the thick mesh at ``positions`` (N, 3) mm to a PNG file, offscreen.

    Parameters
    ----------
    view : {"iso", "top", "side"}
        Camera preset.
    """
    pv = _pyvista()
    plotter = pv.Plotter(off_screen=True, window_size=list(size))
    plotter.set_background("white")
    panels = mesh.groups[mesh.panel_group]
    plotter.add_mesh(_element_surface(panels, range(len(panels)), positions),
                     color=PANEL_COLOUR,
                     show_edges=True, edge_color=(0.35, 0.35, 0.35), line_width=1)
    hinges = mesh.groups.get("bending_hinge")
    if hinges is not None and len(hinges):
        kinds = pattern.assignments[hinges.source]
        for kind, colour in HINGE_COLOURS.items():
            chosen = np.flatnonzero(kinds == kind)
            if len(chosen):
                plotter.add_mesh(_element_surface(hinges, chosen, positions), color=colour,
                                 show_edges=True, edge_color=(0.2, 0.2, 0.2), line_width=1)
    getattr(plotter, {"iso": "view_isometric", "top": "view_xy", "side": "view_xz"}[view])()
    folder, name = os.path.split(os.path.abspath(os.fspath(path)))
    tmp = os.path.join(folder, f".{name}.{os.getpid()}.tmp.png")  # no half-written PNG
    try:
        plotter.screenshot(tmp)
        os.replace(tmp, path)
    finally:
        plotter.close()
        if os.path.exists(tmp):
            os.unlink(tmp)


def _pyvista():
    """pyvista set up for offscreen rendering; EGL directly when there is no display."""
    if not os.environ.get("DISPLAY"):
        # without this VTK first tries X, fails with a warning, then falls back to EGL
        os.environ.setdefault("VTK_DEFAULT_OPENGL_WINDOW", "vtkEGLRenderWindow")
    import pyvista as pv

    pv.OFF_SCREEN = True
    return pv

