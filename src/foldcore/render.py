"""Offscreen renders of a folded thick mesh (pyvista, imported only inside functions).

What a picture shows
--------------------
* Only the outer surface of the prism mesh (a face shared by two prisms is
  inside the solid and is not drawn), with polygon edges, so the sub-strips of
  every hinge stay visible.
* Panels light grey; hinge sub-strips coloured by their crease's assignment:
  valley blue, mountain red, unassigned amber, flat grey, with a legend.
* Or, with ``scalars``, hinge sub-strips coloured by one value per sub-strip
  (per-crease values spread with :func:`per_strip`: fold angle in degrees,
  strain, …) through a colour map, with
  a labelled colour bar; panels stay grey. Signed values get the diverging map
  ``RdBu`` with symmetric limits, so valleys (> 0) are blue and mountains red
  as in the assignment colours.

Cameras
-------
Orthographic (parallel projection; true lengths in the top/front/side views),
looking at the solid from:

* ``iso``: +x +y +z (isometric), z up;
* ``top``: +z, looking down, x right, y up;
* ``front``: −y, looking along +y, x right, z up;
* ``side``: +x, looking along −x, y right, z up;
* or any (3,) direction vector (from the solid toward the camera).

The orthographic camera is fitted to the solid: the projected bounding box
fills the free part of the picture (the colour bar, legend and title strips
are kept clear) with ``padding`` around it (an animation, :class:`Renderer`,
fits once to every frame with :meth:`Renderer.fit`).
"""
from __future__ import annotations

import os

import numpy as np

from . import files
from .errors import FoldcoreError
from .files import ExportError
from .mesh import surface_polygons
from .surface import surface_edges, surface_triangles

HINGE_COLOURS = {"V": (0.20, 0.40, 0.85), "M": (0.85, 0.25, 0.20),
                 "U": (0.95, 0.65, 0.10), "F": (0.60, 0.60, 0.60)}
HINGE_LABELS = {"V": "valley", "M": "mountain", "U": "unassigned", "F": "flat"}
PANEL_COLOUR = (0.88, 0.88, 0.86)
EDGE_COLOUR = (0.12, 0.12, 0.12)
BACKGROUND = "white"
#: Camera direction (solid → camera) and view-up of each preset.
VIEWS = {"iso": ((1.0, 1.0, 1.0), (0.0, 0.0, 1.0)),
         "top": ((0.0, 0.0, 1.0), (0.0, 1.0, 0.0)),
         "front": ((0.0, -1.0, 0.0), (0.0, 0.0, 1.0)),
         "side": ((1.0, 0.0, 0.0), (0.0, 0.0, 1.0))}
MAX_SIZE_PX = 8192
#: Picture strips (fractions of its height/width) kept clear of the solid.
_BAR_STRIP = 0.20      # bottom: horizontal colour bar


class RenderError(FoldcoreError, ValueError):
    """A render was asked with bad options (size, view, scalars) or without pyvista."""


# ---------------------------------------------------------------- options
def parse_size(text: str) -> tuple[int, int]:
    """``"WIDTHxHEIGHT"`` (pixels, e.g. ``"1200x900"``) → ``(width, height)``.

    Raises
    ------
    RenderError
        Not two integers in 16..8192 joined by ``x``.
    """
    parts = str(text).lower().split("x")
    try:
        size = tuple(int(p) for p in parts)
    except ValueError:
        size = ()
    if len(size) != 2:
        raise RenderError(f"size must be WIDTHxHEIGHT in pixels (e.g. 1200x900), got {text!r}")
    return check_size(size)


def check_size(size) -> tuple[int, int]:
    """``(width, height)`` in pixels as ints, each in 16..``MAX_SIZE_PX``."""
    try:
        w, h = (int(v) for v in size)
        ok = all(float(v) == int(v) for v in size)
    except (TypeError, ValueError):
        raise RenderError(f"size must be (width, height) in pixels, got {size!r}") from None
    if not ok or not (16 <= w <= MAX_SIZE_PX and 16 <= h <= MAX_SIZE_PX):
        raise RenderError(f"size must be two whole numbers of pixels in 16..{MAX_SIZE_PX}, "
                          f"got {w}x{h}")
    return w, h


def view_vectors(view) -> tuple[np.ndarray, np.ndarray]:
    """Unit camera direction (solid → camera) and view-up of a preset or a (3,) vector."""
    if isinstance(view, str):
        if view not in VIEWS:
            raise RenderError(f"unknown view {view!r} (available: {', '.join(VIEWS)})")
        direction, up = (np.array(v, dtype=float) for v in VIEWS[view])
    else:
        direction = np.asarray(view, dtype=float)
        if direction.shape != (3,) or not np.isfinite(direction).all() or \
                not np.linalg.norm(direction) > 0:
            raise RenderError(f"view must be one of {', '.join(VIEWS)} or a nonzero 3-vector, "
                              f"got {view!r}")
        up = np.array([0.0, 0.0, 1.0])
        if np.linalg.norm(np.cross(direction, up)) < 1e-6 * np.linalg.norm(direction):
            up = np.array([0.0, 1.0, 0.0])   # looking along z: y up, as "top"
    direction = direction / np.linalg.norm(direction)
    up = up - (up @ direction) * direction
    return direction, up / np.linalg.norm(up)


# ---------------------------------------------------------------- scalars
def hinge_values(pattern, mesh, scalars) -> np.ndarray:
    """Validated per-strip values, (S,) float, S = ``len(mesh.groups["bending_hinge"])``.

    Per-crease values (e.g. ``Result.fold_angles_deg``) must be spread first
    with :func:`per_strip`: the length alone cannot tell them apart (S may
    equal the number of edges).
    """
    hinges = mesh.groups.get("bending_hinge")
    n_strips = 0 if hinges is None else len(hinges)
    values = np.asarray(scalars, dtype=float).ravel()
    if values.shape != (n_strips,):
        raise RenderError(f"scalars must have one value per hinge sub-strip ({n_strips}), "
                          f"got {values.size}; spread per-crease values with per_strip()")
    return values.copy()


def per_strip(mesh, crease_values) -> np.ndarray:
    """(S,) per-sub-strip copy of per-crease values (E,) (each strip takes its crease's)."""
    hinges = mesh.groups.get("bending_hinge")
    if hinges is None:
        return np.zeros(0)
    return np.asarray(crease_values, dtype=float)[hinges.source]


def colour_limits(values, signed: bool | None = None) -> tuple[float, float]:
    """Colour-map limits of the finite ``values``.

    ``signed`` True (angles: valley > 0, mountain < 0) gives ±max|v|, so 0
    is the middle of a diverging map; False gives (0, max) for values ≥ 0,
    else (min, max); None (default) is True when any value is < 0.
    """
    v = np.asarray(values, dtype=float)
    v = v[np.isfinite(v)]
    if not len(v):
        return -1.0, 1.0
    if signed is None:
        signed = bool(v.min() < 0)
    top = float(np.abs(v).max())
    if signed:
        return (-top, top) if top > 0 else (-1.0, 1.0)
    lo, hi = min(0.0, float(v.min())), float(v.max())
    return (lo, hi) if hi > lo else (lo, lo + 1.0)


def default_cmap(clim) -> str:
    """``RdBu`` (valley blue, mountain red) for signed limits, else ``viridis``."""
    return "RdBu" if clim[0] < 0 < clim[1] else "viridis"


def strip_bend_angles(mesh, positions) -> np.ndarray:
    """Bend angle of every hinge sub-strip measured on the solid, (S,) degrees, valley > 0.

    The angle between the planes of a sub-strip's two long side faces (the
    faces across the sheet at its two lines), signed about the crease
    direction. Rest: 0. The angles of a crease's sub-strips add up to its
    fold angle when the panels are flat.

    Parameters
    ----------
    mesh : ThickMesh
    positions : (N, 3) float, mm
    """
    hinges = mesh.groups.get("bending_hinge")
    if hinges is None or not len(hinges):
        return np.zeros(0)
    x = np.asarray(positions, dtype=float)
    ids = hinges.indices.reshape(len(hinges), 8)   # top a_j, a_j+1, b_j+1, b_j; bottom same
    top, bot = x[ids[:, :4]], x[ids[:, 4:]]
    mid = 0.5 * (top + bot)
    thick = top - bot
    # side j: points 0 (a) and 3 (b); side j+1: points 1 (a) and 2 (b)
    along_j, along_k = mid[:, 3] - mid[:, 0], mid[:, 2] - mid[:, 1]
    n_j = np.cross(thick[:, 0] + thick[:, 3], along_j)
    n_k = np.cross(thick[:, 1] + thick[:, 2], along_k)
    axis = along_j + along_k
    axis /= np.linalg.norm(axis, axis=1)[:, None]
    sin = np.einsum("ij,ij->i", np.cross(n_j, n_k), axis)
    return np.degrees(np.arctan2(-sin, np.einsum("ij,ij->i", n_j, n_k)))


# ---------------------------------------------------------------- geometry
def surface_polydata(mesh, positions=None, hinges: bool | None = None):
    """The outer surface of ``mesh`` as a ``pyvista.PolyData`` of triangles.

    The one mesh-to-PyVista conversion: the renders, animations and the viewer
    draw it (``.save(path)`` writes any format PyVista knows). Faces are
    triangulated on the flat footprint (:func:`foldcore.surface.surface_triangles`,
    no slivers at the collinear points panels share with strips).

    Parameters
    ----------
    mesh : ThickMesh
    positions : (N, 3) float, optional
        Vertex positions, mm (default: rest); the PolyData holds a copy.
    hinges : bool, optional
        Only the hinge faces (True) or only the panel faces (False); default all.

    Returns
    -------
    pyvista.PolyData or None
        None when no face is chosen. Cell data per triangle: ``is_hinge`` (bool),
        ``strip`` (the element index of its prism in its group), ``edge`` (the
        pattern item the prism came from: face for panels, edge for hinges) and
        ``bending`` (uint8, 1 on bending-hinge sub-strips).
    """
    x = mesh.rest_positions if positions is None else np.asarray(positions, dtype=float)
    surf = surface_polygons(mesh)
    tris, face = surface_triangles(mesh, surf, return_faces=True)
    chosen = np.arange(len(tris)) if hinges is None else \
        np.flatnonzero(surf.is_hinge[face] == hinges)
    return _polydata(x, surf, tris, face, chosen)


def _polydata(x, surf, tris, face, chosen):
    """PolyData of the triangles ``tris[chosen]`` over a copy of ``x`` (N, 3) mm, with the
    cell data of :func:`surface_polydata`; None when ``chosen`` is empty."""
    if not len(chosen):
        return None
    pv = require_pyvista(offscreen=False)
    poly = pv.PolyData(x.copy(), np.column_stack([np.full(len(chosen), 3),
                                                  tris[chosen]]).ravel())
    owner = face[chosen]
    poly.cell_data["strip"] = surf.element[owner]
    poly.cell_data["edge"] = surf.source[owner]
    poly.cell_data["bending"] = (surf.group[owner] == "bending_hinge").astype(np.uint8)
    poly.cell_data["is_hinge"] = surf.is_hinge[owner]
    return poly


def _surface_parts(mesh, positions, source: str | None = None):
    """(panels, hinges, edge lines) of the outer surface at ``positions`` (N, 3) mm: the
    panel and hinge triangles as :func:`surface_polydata` (None when there are none)
    and every polygon edge as a line; ``source``: the file named in errors."""
    pv = require_pyvista()
    surf = surface_polygons(mesh)
    tris, face = surface_triangles(mesh, surf, return_faces=True, source=source)
    x = np.asarray(positions, dtype=float)
    panels, hinges = (_polydata(x, surf, tris, face,
                                np.flatnonzero(surf.is_hinge[face] == is_hinge))
                      for is_hinge in (False, True))
    edges = surface_edges(surf)
    lines = pv.PolyData(x.copy(), lines=np.column_stack([np.full(len(edges), 2),
                                                         edges]).ravel()) if len(edges) else None
    return panels, hinges, lines


def behind_lines(actor) -> None:
    """Push an actor's polygons back in depth so edge lines on them stay visible."""
    mapper = actor.GetMapper()
    mapper.SetResolveCoincidentTopologyToPolygonOffset()
    mapper.SetRelativeCoincidentTopologyPolygonOffsetParameters(2.0, 2.0)


def fit_camera(camera, points, direction, up, aspect, box, padding) -> None:
    """Orthographic camera looking along −direction, fitting ``points`` into ``box``.

    ``box`` = (x0, x1, y0, y1), the free part of the picture in normalised
    coordinates; ``aspect`` = width / height in pixels.
    """
    p = np.asarray(points, dtype=float).reshape(-1, 3)
    right = np.cross(-direction, up)
    u, v, w = p @ right, p @ up, p @ direction
    x0, x1, y0, y1 = box
    half_w = 0.5 * max(np.ptp(u), 1e-9) / (x1 - x0)
    half_h = 0.5 * max(np.ptp(v), 1e-9) / (y1 - y0)
    scale = max(half_h, half_w / aspect) * (1.0 + 2.0 * padding)
    # shift so the solid's projected centre lands on the centre of the free box
    cu = 0.5 * (u.min() + u.max()) - (0.5 * (x0 + x1) - 0.5) * 2.0 * scale * aspect
    cv = 0.5 * (v.min() + v.max()) - (0.5 * (y0 + y1) - 0.5) * 2.0 * scale
    focal = cu * right + cv * up + 0.5 * (w.min() + w.max()) * direction
    distance = 2.0 * float(np.linalg.norm(p - p.mean(axis=0), axis=1).max()) + 1.0
    camera.parallel_projection = True
    camera.focal_point = tuple(focal)
    camera.position = tuple(focal + distance * direction)
    camera.up = tuple(up)
    camera.parallel_scale = scale
    camera.clipping_range = (1e-3 * distance, 4.0 * distance + np.ptp(w))


# ---------------------------------------------------------------- renderer
class Renderer:
    """An offscreen picture of one thick mesh; move it and take frames.

    Parameters
    ----------
    pattern : CreasePattern
    mesh : ThickMesh
    size : (int, int)
        Width, height in pixels.
    view : str or (3,) array
        Camera preset (``iso``, ``top``, ``front``, ``side``) or direction from
        the solid to the camera; see the module docstring.
    scalars : (S,) array_like, optional
        Colour hinge sub-strips by these values, one per sub-strip (spread
        per-crease values with :func:`per_strip`);
        None: colour by assignment (M/V) with a legend.
    scalar_name : str
        Colour-bar title, with its unit, e.g. ``"fold angle (deg)"``.
    cmap : str, optional
        matplotlib colour map; default :func:`default_cmap`.
    clim : (float, float), optional
        Colour limits; default :func:`colour_limits` of ``scalars``.
    legend : bool
        Show the M/V legend (assignment colouring only).
    padding : float
        Margin around the fitted solid, fraction of its extent.
    title : str, optional
        Text in the upper-left corner.

    Use as a context manager, or call :meth:`close`.
    """

    def __init__(self, pattern, mesh, size=(1024, 768), view="iso", *, scalars=None,
                 scalar_name="value", cmap=None, clim=None, legend=True, padding=0.04,
                 title=None):
        self.size = check_size(size)
        self.direction, self.up = view_vectors(view)
        self.pattern, self.mesh = pattern, mesh
        self.padding = float(padding)
        pv = require_pyvista()
        self.plotter = pv.Plotter(off_screen=True, window_size=list(self.size))
        self.plotter.set_background(BACKGROUND)
        self._box = [0.0, 1.0, 0.0, 1.0]
        self._title = None
        try:
            self._add_scene(scalars, scalar_name, cmap, clim, legend)
            self._add_title(title)
        except BaseException:
            self.close()
            raise

    # -- scene
    def _add_scene(self, scalars, scalar_name, cmap, clim, legend):
        """The solid's surfaces, at rest (:meth:`update` moves them)."""
        self.panels, self.hinges, self.lines = _surface_parts(
            self.mesh, self.mesh.rest_positions, getattr(self.pattern, "source", None))
        self.moving = (self.panels, self.hinges, self.lines)
        self.n_points = self.mesh.n_vertices
        self._add_panels()
        self._add_edges()
        if scalars is None:
            self._add_assignment_hinges(legend)
        else:
            self._add_scalar_hinges(scalars, scalar_name, cmap, clim)

    def _add_panels(self):
        if self.panels is not None:
            behind_lines(self.plotter.add_mesh(self.panels, color=PANEL_COLOUR))

    def _add_edges(self):
        if self.lines is not None:
            self.plotter.add_mesh(self.lines, color=EDGE_COLOUR, line_width=1)

    def _add_assignment_hinges(self, legend: bool):
        if self.hinges is None:
            return
        kinds = np.asarray(self.pattern.assignments)[self.hinges.cell_data["edge"]]
        rgb = np.array([HINGE_COLOURS.get(k, HINGE_COLOURS["U"]) for k in kinds])
        self.hinges.cell_data["colour"] = (255 * rgb).astype(np.uint8)
        behind_lines(self.plotter.add_mesh(self.hinges, scalars="colour", rgb=True))
        present = [k for k in HINGE_COLOURS if k in set(kinds)]
        if legend and present:
            entries = [[HINGE_LABELS[k], HINGE_COLOURS[k]] for k in present]
            entry = max(0.055 * self.size[1], 16.0)     # pixels per legend line
            width = min(0.5, 4.85 * entry / self.size[0])
            height = min(0.5, entry * (len(entries) + 0.5) / self.size[1])
            legend = self.plotter.add_legend(entries, bcolor="white", border=True,
                                             face="rectangle", loc=None)
            # placed by hand: pyvista 0.49's "lower right" uses the height for x
            legend.SetPosition(1.0 - width - 0.02, 0.02)
            legend.SetPosition2(width, height)
            self._box[1] = 1.0 - width - 0.02

    def _add_scalar_hinges(self, scalars, name, cmap, clim):
        strips = hinge_values(self.pattern, self.mesh, scalars)
        if self.hinges is None:
            return
        self.clim = tuple(float(c) for c in (clim or colour_limits(strips)))
        self.hinges.cell_data["value"] = self._strip_cells(strips)
        behind_lines(self.add_scalars(self.hinges, name, cmap))

    def add_scalars(self, poly, name: str, cmap, **options):
        """Add ``poly`` coloured by its cell data ``value`` within :attr:`clim`, with a
        horizontal colour bar titled ``name`` at the bottom; the actor."""
        bar = dict(title=name, color="black", vertical=False, position_x=0.2,
                   position_y=0.03, width=0.6, height=0.09, n_labels=5, fmt="%.3g",
                   title_font_size=self._font(18), label_font_size=self._font(16),
                   unconstrained_font_size=True)
        self._box[2] = _BAR_STRIP
        return self.plotter.add_mesh(poly, scalars="value", cmap=cmap or default_cmap(self.clim),
                                     clim=self.clim, nan_color=(0.5, 0.5, 0.5),
                                     scalar_bar_args=bar, **options)

    def _strip_cells(self, strips: np.ndarray) -> np.ndarray:
        """Per-cell values of the hinge surface: bending sub-strips take theirs, other
        hinge-like prisms (stretch hinges) NaN."""
        bending = self.hinges.cell_data["bending"].astype(bool)
        return np.where(bending, strips[np.where(bending, self.hinges.cell_data["strip"], 0)]
                        if len(strips) else np.nan, np.nan)

    def _add_title(self, title):
        if title is None:
            return
        size = self._font(18)
        self._title = self.plotter.add_text(str(title), font_size=size, color="black",
                                            position=(size // 2, self.size[1] - 2 * size))
        self._title.GetTextProperty().SetFontSize(size)   # pyvista may rescale it
        self._box[3] = 1.0 - 2.5 * size / self.size[1]

    def _font(self, at_768: int) -> int:
        """A font size (points) for this picture: ``at_768`` on a 768-px-high one."""
        return max(10, round(at_768 * min(self.size[1] / 768, self.size[0] / 1024)))

    # -- per frame
    def update(self, positions, scalars=None, title=None) -> None:
        """Move the solid to ``positions`` (N, 3) mm; optionally new scalars / title."""
        x = np.asarray(positions, dtype=float)
        if x.shape != (self.n_points, 3) or not np.isfinite(x).all():
            raise RenderError(f"positions must be a finite ({self.n_points}, 3) array "
                              f"of mm, got shape {x.shape}")
        for poly in self.moving:
            if poly is not None:
                poly.points = x.copy()
        if scalars is not None and self.hinges is not None and "value" in self.hinges.cell_data:
            strips = hinge_values(self.pattern, self.mesh, scalars)
            self.hinges.cell_data["value"] = self._strip_cells(strips)
        if title is not None and self._title is not None:
            self._title.SetInput(str(title))   # a vtkTextActor: fixed size in pixels

    def fit(self, points=None) -> None:
        """Fit the camera to ``points`` (M, 3) mm, default the current solid."""
        if points is None:
            points = np.vstack([p.points for p in self.moving if p is not None])
        w, h = self.size
        fit_camera(self.plotter.camera, points, self.direction, self.up, w / h,
                    self._box, self.padding)

    def image(self) -> np.ndarray:
        """The current picture, (height, width, 3) uint8 RGB."""
        self.plotter.render()
        return np.asarray(self.plotter.screenshot(None, return_img=True))[..., :3].copy()

    def save(self, path) -> None:
        """Write the current picture as PNG at ``path``, atomically."""
        files.check_folder(path, ExportError)
        self.plotter.render()
        with files.atomic_path(path, suffix=".png") as tmp:
            self.plotter.screenshot(tmp)

    def close(self) -> None:
        self.plotter.close()

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()


# ---------------------------------------------------------------- one picture
def render_image(pattern, mesh, positions, size=(1024, 768), view="iso",
                 **options) -> np.ndarray:
    """Render the thick mesh at ``positions`` (N, 3) mm; returns (height, width, 3) uint8.

    ``options`` are those of :class:`Renderer` (``scalars``, ``scalar_name``,
    ``cmap``, ``clim``, ``legend``, ``padding``, ``title``).
    """
    with Renderer(pattern, mesh, size, view, **options) as r:
        r.update(positions)
        r.fit()
        return r.image()


def render_png(pattern, mesh, positions, path, size=(1024, 768), view="iso",
               **options) -> None:
    """Render the thick mesh at ``positions`` (N, 3) mm to a PNG file, offscreen, atomically.

    Parameters
    ----------
    pattern : CreasePattern
    mesh : ThickMesh
    positions : (N, 3) float, mm
    path : str or os.PathLike
        The PNG written (appears only when complete).
    size : (int, int)
        Width, height in pixels (default 1024×768).
    view : {"iso", "top", "front", "side"} or (3,) array
        Camera preset or direction (module docstring).
    **options
        :class:`Renderer` keywords: ``scalars`` (one per sub-strip, e.g.
        ``result.strip_angles_deg`` or ``per_strip(mesh, result.fold_angles_deg)``),
        ``scalar_name`` (colour-bar title with unit), ``cmap``, ``clim``,
        ``legend``, ``padding``, ``title``.

    Examples
    --------
    >>> render_png(pattern, mesh, result.positions, "fold.png", view="top",
    ...            scalars=result.strip_angles_deg,
    ...            scalar_name="strip bend (deg)")          # doctest: +SKIP
    """
    with Renderer(pattern, mesh, size, view, **options) as r:
        r.update(positions)
        r.fit()
        r.save(path)


def _caches_where_writable() -> None:
    """Without a writable home (a read-only install, a service account) matplotlib
    (which pyvista imports) and Mesa's OpenGL each print lines about their caches:
    give matplotlib a temporary folder and turn Mesa's shader cache off there. A
    folder the user set (``MPLCONFIGDIR``, ``MESA_SHADER_CACHE_DIR``) is kept."""
    import tempfile

    home = os.path.expanduser("~")
    config = os.environ.get("XDG_CONFIG_HOME") or os.path.join(home, ".config")
    cache = os.environ.get("XDG_CACHE_HOME") or os.path.join(home, ".cache")
    if "MPLCONFIGDIR" not in os.environ and not _writable(config):
        import atexit
        import shutil

        folder = tempfile.mkdtemp(prefix="foldcore-matplotlib-")
        atexit.register(shutil.rmtree, folder, ignore_errors=True)
        os.environ["MPLCONFIGDIR"] = folder
    if "MESA_SHADER_CACHE_DIR" not in os.environ and not _writable(cache):
        os.environ.setdefault("MESA_SHADER_CACHE_DISABLE", "true")


def _writable(folder: str) -> bool:
    """Whether ``folder`` exists or can be made, and can be written (made as the
    library would make it anyway)."""
    try:
        os.makedirs(folder, exist_ok=True)
    except OSError:
        return False
    return os.access(folder, os.W_OK | os.X_OK)


def require_pyvista(offscreen: bool = True):
    """pyvista (RenderError naming the extra when missing); ``offscreen``: set up for
    offscreen rendering, EGL directly when there is no display."""
    if offscreen and not os.environ.get("DISPLAY"):
        # without this VTK first tries X, fails with a warning, then falls back to EGL
        os.environ.setdefault("VTK_DEFAULT_OPENGL_WINDOW", "vtkEGLRenderWindow")
    _caches_where_writable()
    try:
        import pyvista as pv
    except ImportError:
        raise RenderError("rendering needs pyvista: pip install 'foldcore[render]'") from None
    if offscreen:
        pv.OFF_SCREEN = True
    return pv
