"""The option groups of :func:`foldcore.simulate` (importable without numba).

``simulate(path, reading=..., thickening=..., solving=..., outputs=...)``: each
group is a frozen dataclass (or a dict of its fields), checked when made, so
a wrong value fails before any work with an :class:`OptionError` that names
it as ``group.field``. The command line maps its flags to these fields
(:data:`FLAGS`) and speaks of its flags in the messages it prints.
Units: mm for lengths, degrees for angles.
"""
from __future__ import annotations

import math
import os
from dataclasses import dataclass, fields

from .actuation import ACTUATIONS, BRANCH_FLOOR_DEG, DEFAULT_ACTUATION
from .errors import FoldcoreError
from .hinges import HINGE_MODELS
from .limits import MAX_ITERATIONS, SUBDIVISIONS, THICK_BUDGET, TOLERANCE
from .strategies import DEFAULT_SOLVER

MAX_FRAMES = 10_000
CONTACT_CHOICES = ("auto", "on", "off")
MAX_FPS = 100.0


class OptionError(FoldcoreError, ValueError):
    """An option's value is outside what it accepts; the message names it as
    ``group.field`` (the command line as its flag)."""


def _positive(value, name: str, optional: bool = True) -> None:
    if value is None and optional:
        return
    if isinstance(value, bool) or not isinstance(value, (int, float)) \
            or not (value > 0 and math.isfinite(value)):
        raise OptionError(f"{name} must be a positive finite number, got {value!r}")


def _within(value, low, high, name: str, unit: str = "") -> None:
    if isinstance(value, bool) or not isinstance(value, (int, float)) \
            or not (low <= value <= high):
        raise OptionError(f"{name} must be in [{low:g}, {high:g}]{unit}, got {value!r}")


def _count(value, low: int, high: int | None, name: str) -> None:
    if isinstance(value, bool) or not isinstance(value, int) or value < low \
            or (high is not None and value > high):
        span = f"≥ {low}" if high is None else f"in {low}..{high}"
        raise OptionError(f"{name} must be an integer {span}, got {value!r}")


@dataclass(frozen=True)
class Thickening:
    """How the crease pattern is thickened (:func:`foldcore.thicken`).

    Attributes
    ----------
    thickness : float, optional
        Sheet thickness H, mm (default: the file's ``foldcore:thickness``).
    hinge_width : float, optional
        Hinge width W of every crease, mm (default: the file's, else Eq. 7).
    subdivisions : int or "auto"
        Sub-strips per hinge, in 1..64 (:data:`foldcore.limits.SUBDIVISIONS`), or
        ``"auto"`` (2 … 16 from the hinge's largest angle).
    hinge : {"axis", "arc", "eq8", "slack"}, optional
        Hinge model of every crease (default: the file's, else axis).
    elastic_cells : float, optional
        Elastic panels: every face cut into rings of cells about this long, mm
        (default: rigid panels); 1e-4 … 1e4 × the sheet's extent
        (:data:`foldcore.limits.CELL_RATIO`, checked once the pattern is read).

    Thickness, hinge width and cell length are checked against the sheet's
    extent once the pattern is read (:func:`foldcore.limits.check_inputs`), and
    the thick mesh's vertex count against
    :data:`foldcore.limits.MAX_MESH_VERTICES` before it is built.
    """

    thickness: float | None = None
    hinge_width: float | None = None
    subdivisions: int | str = "auto"
    hinge: str | None = None
    elastic_cells: float | None = None

    def __post_init__(self):
        _positive(self.thickness, "thickening.thickness")
        _positive(self.hinge_width, "thickening.hinge_width")
        _positive(self.elastic_cells, "thickening.elastic_cells")
        if self.subdivisions != "auto":
            _count(self.subdivisions, *SUBDIVISIONS, "thickening.subdivisions")
        if self.hinge is not None and self.hinge not in HINGE_MODELS:
            raise OptionError(f"thickening.hinge must be one of {', '.join(HINGE_MODELS)}, "
                              f"got {self.hinge!r}")


@dataclass(frozen=True)
class Solving:
    """How the thick sheet is folded (:class:`foldcore.Simulation` and its ``run``).

    Attributes
    ----------
    fold_percent : float
        Every target angle × this / 100, in [−100, 100].
    solver : str
        Iteration strategy (``foldcore.strategies``), default ``"hybrid"``.
    tolerance : float
        Relative stopping threshold (× the pattern's size), in [1e-15, 1e-2]
        (:data:`foldcore.limits.TOLERANCE`): the run ends converged when its state is
        within tolerance × size of the equilibrium, so a looser one reads
        "converged" degrees short of it, and a tighter one cannot be resolved in
        float64.
    max_iterations : int, optional
        Iteration budget of the run (of each frame of a sweep), in 1..1 000 000
        (:data:`foldcore.limits.MAX_ITERATIONS`); None (default): the model's own,
        :data:`foldcore.limits.THICK_BUDGET` iterations of a thick sheet's strategy or
        :data:`foldcore.limits.SHEET_BUDGET` Newton steps of a thin sheet
        (:meth:`budget`).
    actuation : {"equal", "angle"}
    branch_floor : float
        Degrees ≥ 0 passive M/V creases are held on their assigned side while a
        fold leaves the flat sheet (0: off).
    strategy_options : dataclass, optional
        The strategy's own options (its ``Options`` class).
    contact : {"auto", "on", "off"}
        Whether panels no crease joins may pass through each other
        (:mod:`foldcore.contact`). ``"auto"`` (default): kept apart wherever the
        run can (a thick sheet of rigid panels without cuts, ``axis`` or
        ``slack`` hinges, a strategy with ``supports_contact``: ``hybrid``,
        ``rigid``, ``newton``, ``lbfgs``, and ipctk installed), else off;
        ``"on"``: kept apart, refused where it cannot be; ``"off"``: not
        checked. Obstacles turn it on.
    obstacles : tuple of str
        Mesh files (STL, OBJ, PLY, … in mm, the pattern's frame: the flat sheet's
        mid-surface is z = 0) of fixed obstacles the sheet touches but never passes.
    ground : float, optional
        Height z (mm) of a horizontal plane facing up that the sheet never passes;
        below −H/2, the flat sheet's bottom face, and |z| at most 1e4 × the
        sheet's extent (:data:`foldcore.limits.GROUND_RATIO`; both checked once
        the pattern is read).
    """

    fold_percent: float = 100.0
    solver: str = DEFAULT_SOLVER
    tolerance: float = 1e-8
    max_iterations: int | None = None
    actuation: str = DEFAULT_ACTUATION
    branch_floor: float = BRANCH_FLOOR_DEG
    strategy_options: object = None
    contact: str = "auto"
    obstacles: tuple = ()
    ground: float | None = None

    def budget(self, default: int = THICK_BUDGET) -> int:
        """The run's iteration budget: ``max_iterations`` when given, else ``default``
        (:data:`foldcore.limits.THICK_BUDGET` for a thick sheet's strategies,
        :data:`foldcore.limits.SHEET_BUDGET` for a thin sheet's Newton steps)."""
        return default if self.max_iterations is None else self.max_iterations

    @property
    def contact_asked(self) -> str:
        """The run's contact setting: ``"on"`` where obstacles need it, else
        ``contact``."""
        return "on" if self.obstacles or self.ground is not None else self.contact

    def __post_init__(self):
        _within(self.fold_percent, -100.0, 100.0, "solving.fold_percent")
        if self.contact not in CONTACT_CHOICES:
            raise OptionError(f"solving.contact must be one of {', '.join(CONTACT_CHOICES)}, "
                              f"got {self.contact!r}")
        if self.ground is not None and not (isinstance(self.ground, (int, float))
                                            and math.isfinite(self.ground)):
            raise OptionError(f"solving.ground must be a finite height in mm, got "
                              f"{self.ground!r}")
        if isinstance(self.obstacles, (str, bytes)) or not all(
                isinstance(o, (str, os.PathLike)) for o in self.obstacles):
            raise OptionError(f"solving.obstacles must be a sequence of file paths, got "
                              f"{self.obstacles!r}")
        object.__setattr__(self, "obstacles", tuple(str(o) for o in self.obstacles))
        _within(self.tolerance, *TOLERANCE, "solving.tolerance")
        if self.max_iterations is not None:
            _count(self.max_iterations, 1, MAX_ITERATIONS, "solving.max_iterations")
        if self.actuation not in ACTUATIONS:
            raise OptionError(f"solving.actuation must be one of {', '.join(ACTUATIONS)}, "
                              f"got {self.actuation!r}")
        _within(self.branch_floor, 0.0, 180.0, "solving.branch_floor", "°")


@dataclass(frozen=True)
class Outputs:
    """What is written (each checked before any work; the data files all or nothing,
    then the picture, whose failure does not take them with it).

    Attributes
    ----------
    fold : path, optional
        The result as FOLD: achieved angles and the folded solid.
    report : path, optional
        The JSON report.
    render : path, optional
        An offscreen PNG render (the ``render`` extra).
    animate : path, optional
        A GIF/MP4 of the fold from 0 to the fold percent (the last frame's run is
        the result).
    series : path, optional
        The same sweep as one FOLD file, a frame per fold percent.
    frames : int
        Frames of ``animate`` / ``series``, fold percents evenly from 0.
    fps : float
        Animation frames per second, in (0, 100].
    """

    fold: str | os.PathLike | None = None
    report: str | os.PathLike | None = None
    render: str | os.PathLike | None = None
    animate: str | os.PathLike | None = None
    series: str | os.PathLike | None = None
    frames: int = 20
    fps: float = 10.0

    def __post_init__(self):
        _count(self.frames, 2, MAX_FRAMES, "outputs.frames")
        _positive(self.fps, "outputs.fps", optional=False)
        if self.fps > MAX_FPS:
            raise OptionError(f"outputs.fps must be in (0, {MAX_FPS:g}], got {self.fps!r}")

    def paths(self) -> dict:
        """{``outputs.field``: path} of the files asked for (None entries skipped by
        the destination checks)."""
        return {f"outputs.{name}": getattr(self, name)
                for name in ("fold", "report", "render", "animate", "series")}


def as_group(cls, value, name: str):
    """``value`` as a ``cls`` option group: itself, ``cls(**value)`` for a dict, the
    defaults for None; OptionError otherwise or for an unknown field."""
    if value is None:
        return cls()
    if isinstance(value, cls):
        return value
    if isinstance(value, dict):
        known = {f.name for f in fields(cls)}
        unknown = sorted(set(value) - known)
        if unknown:
            raise OptionError(f"{name}: unknown option {unknown[0]!r} (known: "
                              f"{', '.join(sorted(known))})")
        try:
            return cls(**value)
        except ValueError as exc:
            raise OptionError(str(exc)) from None
    raise OptionError(f"{name} must be a {cls.__name__} or a dict of its fields, "
                      f"got {type(value).__name__}")


#: The command line's flag for each library option name (messages are translated
#: from the library's words to the flags by :func:`foldcore.cli`).
FLAGS = {
    "thickening.thickness": "--thickness",
    "thickening.hinge_width": "--hinge-width",
    "thickening.subdivisions": "--subdivisions",
    "thickening.hinge": "--hinge",
    "thickening.elastic_cells": "--elastic-cells",
    "solving.fold_percent": "--fold-percent",
    "solving.solver": "--solver",
    "solving.tolerance": "--tolerance",
    "solving.max_iterations": "--max-iterations",
    "solving.actuation": "--actuation",
    "solving.branch_floor": "--branch-floor",
    "solving.contact": "--contact",
    "solving.obstacles": "--obstacle",
    "solving.ground": "--ground",
    "outputs.fold": "-o",
    "outputs.report": "--report",
    "outputs.render": "--render",
    "outputs.animate": "--animate",
    "outputs.series": "--series",
    "outputs.frames": "--frames",
    "outputs.fps": "--fps",
    "reading.hinges": "--hinges",
    "reading.scale": "--scale",
    "reading.size": "--sheet-size",
    "reading.mv_without_angle='passive'": "--mv-passive",
    "reading.trust_assignment=True": "--trust-assignment",
    "reading.drive": "--drive",
}
