"""Animations of a fold: a fold-percent sweep, rendered offscreen, encoded as GIF or MP4.

Three steps, usable on their own so a scene can pass its own schedule:

1. :func:`fold_sweep` drives a :class:`~foldcore.simulation.Simulation`
   through a list of fold percents; each frame continues from the previous
   state (``set_fold_percent`` then ``run``), as a sheet folded slowly would;
2. :func:`render_frames` renders a list of positions of one pattern + mesh
   with one fixed camera, fitted to every frame at once (the solid does not
   jump or zoom between frames);
3. :func:`write_animation` encodes the frames with imageio: GIF through
   Pillow (with the ``render`` extra), MP4 (H.264) through imageio-ffmpeg
   (the ``video`` extra; a clear :class:`~foldcore.render.RenderError` names
   it when missing).

:func:`animate` does all three. Progress bars (tqdm) appear on a terminal
only, unless ``progress`` says otherwise. Units: mm, degrees, percent.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from . import files
from .files import ExportError
from .render import RenderError

FORMATS = (".gif", ".mp4")
MAX_FRAMES = 10_000
COLOR_BY = ("assignment", "angle", "strip-angle")


@dataclass
class Animation:
    """What :func:`animate` produced.

    Attributes
    ----------
    percents : (F,) float
        Fold percent of each frame.
    results : list of Result
        The simulation state after each frame's run (``results[-1]`` is final).
    frames : list of (height, width, 3) uint8
        The rendered pictures.
    """

    percents: np.ndarray
    results: list
    frames: list = field(default_factory=list)


def percent_schedule(frames: int, stop: float = 100.0, start: float = 0.0) -> np.ndarray:
    """``frames`` fold percents evenly from ``start`` to ``stop`` (both included), (F,) float."""
    if not (isinstance(frames, (int, np.integer)) and 2 <= frames <= MAX_FRAMES):
        raise RenderError(f"an animation needs 2..{MAX_FRAMES} frames, got {frames!r}")
    return np.linspace(float(start), float(stop), int(frames))


def frame_titles(percents) -> list[str]:
    """The title of each frame of a sweep through ``percents`` (fold percent)."""
    return [f"fold {p:.4g} %" for p in percents]


def check_output(path) -> str:
    """The animation format of ``path`` (``".gif"`` or ``".mp4"``); checks its encoder.

    Call before simulating, so a missing encoder fails before any work.

    Raises
    ------
    RenderError
        Unknown suffix, or pyvista or the package that encodes it is not installed.
    ExportError
        The folder of ``path`` does not exist.
    """
    import os

    suffix = os.path.splitext(os.fspath(path))[1].lower()
    files.check_folder(path, ExportError)
    if suffix not in FORMATS:
        raise RenderError(f"{os.fspath(path)}: animation must be .gif or .mp4, "
                          f"got {suffix or 'no suffix'!r}")
    try:
        import imageio  # noqa: F401
        if suffix == ".gif":
            import PIL  # noqa: F401
    except ImportError:
        raise RenderError("animations need imageio and Pillow: pip install "
                          "'foldcore[render]'") from None
    from .render import require_pyvista

    require_pyvista()  # the frames are rendered with it: fail now, not after the sweep
    if suffix == ".mp4":
        try:
            import imageio_ffmpeg  # noqa: F401
        except ImportError:
            raise RenderError("MP4 animations need the package 'imageio-ffmpeg' (pip install "
                              "'foldcore[video]'); .gif works without it") from None
    return suffix


def _progress(iterable, progress, desc: str, total: int | None = None):
    """``iterable`` wrapped in a tqdm bar: None = on a terminal only, True/False = always/never."""
    try:
        from tqdm.auto import tqdm
    except ImportError:  # tqdm comes with the render extra; no bar without it
        return iterable
    return tqdm(iterable, desc=desc, total=total, unit="frame", leave=False,
                disable=None if progress is None else not progress)


def fold_sweep(sim, percents, *, tolerance: float = 1e-8, max_iterations: int = 10_000,
               progress=None, callback=None, predict: bool = True) -> list:
    """Run ``sim`` to each fold percent in turn, continuing from the previous state.

    After two converged frames each run starts from the extrapolation of the
    last two (:meth:`Simulation.predict`; rigid-body strategies), so a fine
    path costs a few steps per frame.

    Parameters
    ----------
    sim : Simulation
    percents : sequence of float
        Fold percent of each frame, −100…100 (e.g. :func:`percent_schedule`).
    tolerance, max_iterations
        Per frame, as :meth:`Simulation.run`.
    progress : bool or None
        tqdm bar; None: on a terminal only.
    callback : callable(frame_index, percent, result), optional
        Called after each frame (e.g. to render it at once).
    predict : bool
        Start each frame from the extrapolation of the previous two (default).

    Returns
    -------
    list of Result, one per frame (``iterations`` counts from the simulation's start).
    """
    results, done = [], []  # done: the percents of the converged frames in a row
    for i, percent in enumerate(_progress(list(percents), progress, "simulate")):
        sim.set_fold_percent(float(percent))
        if predict and len(done) >= 2 and done[-1] != done[-2]:
            sim.predict((float(percent) - done[-1]) / (done[-1] - done[-2]))
        result = sim.run(tolerance=tolerance, max_iterations=max_iterations)
        results.append(result)
        done = done[-1:] + [float(percent)] if result.converged else []
        if callback is not None:
            callback(i, float(percent), result)
    return results


def render_frames(pattern, mesh, positions, *, size=(640, 480), view="iso", scalars=None,
                  scalar_name="value", clim=None, titles=None, progress=None) -> list:
    """Render each of ``positions`` with one camera fitted to all of them.

    Parameters
    ----------
    pattern, mesh : the CreasePattern and ThickMesh
    positions : sequence of (N, 3) float, mm
    size : (int, int)
        Pixels, width × height.
    view : str or (3,) array
        As :func:`foldcore.render.render_png`.
    scalars : sequence of (S,) arrays, optional
        One per frame, one value per sub-strip; the colour limits are
        those of all frames together unless ``clim`` is given.
    scalar_name : str
        Colour-bar title with unit.
    titles : sequence of str, optional
        Text in the upper-left corner of each frame.
    progress : bool or None
        tqdm bar; None: on a terminal only.

    Returns
    -------
    list of (height, width, 3) uint8
    """
    from .render import Renderer, colour_limits, hinge_values

    positions, titles = checked_frames(positions, titles)
    options = {}
    if scalars is not None:
        scalars = [hinge_values(pattern, mesh, s) for s in scalars]
        if len(scalars) != len(positions):
            raise RenderError(f"{len(scalars)} scalar arrays for {len(positions)} frames")
        options.update(scalars=scalars[0], scalar_name=scalar_name,
                       clim=colour_limits(np.concatenate(scalars)) if clim is None else clim)
    renderer = Renderer(pattern, mesh, size, view, title=titles[0] if titles else None,
                        **options)
    return take_frames(renderer, positions, titles, scalars, progress)


def checked_frames(positions, titles=None) -> tuple[list, list | None]:
    """``positions`` as a list of float arrays and ``titles`` as a list (or None);
    RenderError when there is no frame or not one title per frame."""
    positions = [np.asarray(p, dtype=float) for p in positions]
    if not positions:
        raise RenderError("no frames to render")
    titles = None if titles is None else list(titles)
    if titles is not None and len(titles) != len(positions):
        raise RenderError(f"{len(titles)} titles for {len(positions)} frames")
    return positions, titles


def take_frames(renderer, positions: list, titles=None, scalars=None, progress=None) -> list:
    """The pictures of ``renderer`` (a :class:`foldcore.render.Renderer`, closed after)
    moved to each of ``positions`` (:func:`checked_frames`) in turn, with the camera
    fitted to all of them at once; each frame's title and scalars when given."""
    frames = []
    with renderer as r:
        r.update(positions[0])
        r.fit(np.vstack(positions))
        for i, x in enumerate(_progress(positions, progress, "render")):
            r.update(x, None if scalars is None else scalars[i],
                     None if titles is None else titles[i])
            frames.append(r.image())
    return frames


def write_animation(path, frames, fps: float = 10.0) -> None:
    """Encode ``frames`` ((h, w, 3) uint8 each) as GIF or MP4 at ``path``, atomically.

    GIF: Pillow, looping, frame time 1000/fps ms (Pillow merges identical
    consecutive frames). MP4: H.264 via imageio-ffmpeg, yuv420p; frames are
    padded with white to even sizes (the codec's requirement).
    """
    suffix = check_output(path)
    if not (np.isfinite(fps) and 0 < fps <= 100):
        raise RenderError(f"fps must be in (0, 100], got {fps!r}")
    if not len(frames):
        raise RenderError("no frames to write")
    stack = np.stack([np.asarray(f, dtype=np.uint8)[..., :3] for f in frames])
    with files.atomic_path(path, suffix=suffix) as tmp:
        if suffix == ".gif":
            import imageio.v3 as iio

            iio.imwrite(tmp, stack, plugin="pillow", extension=".gif",
                        duration=round(1000.0 / fps), loop=0)
        else:
            import imageio.v2 as iio2

            pad = ((0, 0), (0, stack.shape[1] % 2), (0, stack.shape[2] % 2), (0, 0))
            stack = np.pad(stack, pad, constant_values=255)
            iio2.mimwrite(tmp, list(stack), format="FFMPEG", fps=float(fps), codec="libx264",
                          pixelformat="yuv420p", macro_block_size=1, quality=8)


def animate(sim, percents, path=None, *, fps: float = 10.0, size=(640, 480), view="iso",
            color_by: str = "assignment", tolerance: float = 1e-8,
            max_iterations: int = 10_000, progress=None) -> Animation:
    """Fold ``sim`` through ``percents``, render every state and (optionally) encode it.

    Parameters
    ----------
    sim : Simulation
        Its current state is the start; it ends in the last frame's state.
    percents : sequence of float
        Fold percent per frame, −100…100 (e.g. ``percent_schedule(30)``).
    path : str or os.PathLike, optional
        ``.gif`` or ``.mp4`` to write; None: only return the frames.
    fps : float
        Frames per second of the file.
    size, view
        Picture size (pixels) and camera, as :func:`foldcore.render.render_png`.
    color_by : {"assignment", "angle", "strip-angle"}
        Hinge colours: M/V, each crease's fold angle (degrees, from the
        panels), or each sub-strip's bend angle (degrees, the solver's).
    tolerance, max_iterations
        Per frame, as :meth:`Simulation.run`.
    progress : bool or None
        tqdm bars; None: on a terminal only.

    Returns
    -------
    Animation
    """
    if color_by not in COLOR_BY:
        raise RenderError(f"color_by must be one of {', '.join(COLOR_BY)}, got {color_by!r}")
    if path is not None:
        check_output(path)
    percents = np.asarray(percents, dtype=float).ravel()
    if not len(percents):
        raise RenderError("no fold percents to animate")
    results = fold_sweep(sim, percents, tolerance=tolerance, max_iterations=max_iterations,
                         progress=progress)
    scalars, name, clim = None, "value", None
    if color_by != "assignment":   # signed angles: valley > 0 blue, mountain < 0 red
        from .render import colour_limits, per_strip

        scalars = [per_strip(sim.mesh, r.fold_angles_deg) if color_by == "angle"
                   else r.strip_angles_deg for r in results]
        name = "fold angle (deg)" if color_by == "angle" else "strip bend (deg)"
        every = np.concatenate(scalars)
        clim = colour_limits(every, signed=True)
    frames = render_frames(sim.pattern, sim.mesh, [r.positions for r in results], size=size,
                           view=view, scalars=scalars, scalar_name=name, clim=clim,
                           titles=frame_titles(percents), progress=progress)
    if path is not None:
        write_animation(path, frames, fps)
    return Animation(percents, results, frames)
