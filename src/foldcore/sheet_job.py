"""A fold of a file with no thickness: the thin sheet, from the file to its outputs.

With no thickness (no ``thickening.thickness``, no ``foldcore:thickness`` in
the file) :func:`foldcore.simulate` folds the pattern as Origami Simulator
does: a thin sheet of triangles whose facets bend and stretch a little, its
creases springs toward their targets (:mod:`foldcore.sheet`), settled to
equilibrium by Newton's method. One line says so. A series or an animation
folds it from flat through the fold percents of the sweep, each frame from
the last (:func:`sweep_thin`). The options of a thick sheet (hinges,
strategies, obstacles) have no meaning here: each one set is refused, naming
it, before any work. ``solving.contact`` ``"on"`` keeps the sheet's triangles
from passing through each other (:mod:`foldcore.contact.sheet`); ``"auto"``
and ``"off"`` fold Origami Simulator's model, which lets them.
"""
from __future__ import annotations

import time
import warnings

from .errors import RunWarning
from .limits import SHEET_BUDGET
from .options import OptionError, Solving, Thickening

#: The line a thin-sheet run says first.
THIN_NOTE = ("no thickness given: folded as a thin sheet (Origami Simulator's model: "
             "facets bend, creases are springs toward their targets); give "
             "thickening.thickness (mm) for a thick sheet")
#: Options of a thick sheet only: (group, field) with the defaults of its class.
THICK_ONLY = (("thickening", Thickening, ("hinge_width", "subdivisions", "hinge",
                                          "elastic_cells")),
              ("solving", Solving, ("solver", "actuation", "branch_floor", "strategy_options",
                                    "obstacles", "ground")))


def thick_options_set(job) -> list[str]:
    """``group.field`` of every option of a thick sheet only that ``job`` sets."""
    out = []
    for group, cls, names in THICK_ONLY:  # a dataclass's attribute is its field's default
        values = getattr(job, group)
        out += [f"{group}.{n}" for n in names if getattr(values, n) != getattr(cls, n)]
    return out


def check_thin(job) -> None:
    """OptionError naming the first thick-sheet option ``job`` sets."""
    named = thick_options_set(job)
    if named:
        raise OptionError(f"{job.source}: {named[0]} is an option of a thick sheet, and this "
                          "pattern has no thickness, so it is folded as a thin sheet: give "
                          "thickening.thickness (mm), or leave it out")


def run_thin(job, loaded, on_start=None, callback=None):
    """(sheet, solver, result, interrupted, sweep): ``job``'s pattern (``loaded``, the
    file read) folded as a thin sheet. Ctrl-C ends a single run with its last
    iterate (``interrupted`` True, ``result.reason == "interrupted"``). With a
    series or an animation asked for, ``sweep`` is :func:`sweep_thin`'s, the
    result its last frame and the solver that frame's (an interrupted sweep writes
    nothing, as a thick one); else None."""
    from .sheet import build_sheet

    warnings.warn(f"{job.source}: {THIN_NOTE}", RunWarning, stacklevel=3)
    s, pattern = job.solving, loaded.pattern
    t0 = time.perf_counter()
    drawing = loaded.drawing
    sheet = build_sheet(pattern, merge_straight=drawing is not None, drawn=drawing)
    if len(sheet.merged):
        count = len(sheet.merged)
        which = "1 vertex" if count == 1 else f"{count} vertices"
        warnings.warn(f"{job.source}: {which} of degree 2 on straight lines left out of "
                      f"the thin sheet, their edges merged, as Origami Simulator reads a "
                      f"drawing (each follows its merged edge)", RunWarning, stacklevel=3)
    sweeping = bool(job.outputs.series or job.outputs.animate)
    solver = None if sweeping else thin_solver(job, sheet, pattern, s.fold_percent)
    setup = time.perf_counter() - t0
    if on_start is not None:
        on_start()
    sweep, interrupted = None, False
    if sweeping:
        sweep, solver = sweep_thin(job, sheet, pattern)
        result = sweep[-1][1]
        result.timings_s["solve"] = sum(r.timings_s["solve"] for _, r in sweep)
    else:
        try:
            result = solver.run(s.tolerance, s.budget(SHEET_BUDGET), _callback(callback))
        except KeyboardInterrupt:
            result, interrupted = solver.result("interrupted"), True
    result.timings_s.update(setup=setup, total=setup + result.timings_s["solve"])
    return sheet, solver, result, interrupted, sweep


def sweep_thin(job, sheet, pattern) -> tuple[list, object]:
    """([(fold percent, SheetFold)], the last frame's SheetSolver): the sheet folded
    from flat to ``job``'s fold percent in ``outputs.frames`` even steps, each from
    the last frame's positions (each frame's ``iterations`` counted from the sweep's
    start, as a thick sweep's); with ``outputs.animate`` the frames rendered
    (:func:`foldcore.sheet_render.render_sheet_frames`, one camera for all) and
    written as the animation."""
    from .animate import frame_titles, percent_schedule, write_animation

    s, out = job.solving, job.outputs
    sweep, start, steps = [], None, 0
    for percent in percent_schedule(out.frames, s.fold_percent):
        solver = thin_solver(job, sheet, pattern, float(percent), start)
        fold = solver.run(s.tolerance, s.budget(SHEET_BUDGET))
        steps = fold.iterations = steps + fold.iterations  # from the sweep's start, as thick
        sweep.append((float(percent), fold))
        start = fold.positions
    if out.animate:
        from .sheet_render import render_sheet_frames

        frames = render_sheet_frames(pattern, sheet.pattern_triangles,
                                     [f.positions for _, f in sweep],
                                     titles=frame_titles(p for p, _ in sweep))
        write_animation(out.animate, frames, out.fps)
    return sweep, solver


def thin_summary(job, pattern, result) -> str:
    """The run's one-line summary; the warnings it calls for are issued."""
    from .outputs import run_summary
    from .sheet.kernels import SLIVER

    summary, said = run_summary(result, pattern, job.source, job.solving.fold_percent,
                                model="sheet")
    if result.sliver_corners:
        n = result.sliver_corners
        said.append(f"{job.source}: {n} facet corner{'s are' if n > 1 else ' is'} held open "
                    f"by the sliver barrier (closed to {SLIVER:g} of the rest angle): the "
                    "facets there would collapse; Origami Simulator switches their creases "
                    "off instead, so its shape differs there")
    for text in said:
        warnings.warn(text, RunWarning, stacklevel=3)
    return summary


def write_thin(job, pattern, sheet, result, settings: dict, partial: bool,
               sweep=None) -> None:
    """The outputs ``job`` asks for (:func:`foldcore.sheet_outputs.write_sheet_result`),
    ``settings`` (:func:`thin_settings`) recorded in the report; ``sweep``: the
    frames of the series (:func:`run_thin`)."""
    from .sheet_outputs import write_sheet_result

    out = job.outputs
    write_sheet_result(result, pattern, sheet, settings, fold_path=out.fold,
                       report=out.report, png=out.render, partial=partial,
                       series=out.series, sweep=sweep)


def _callback(callback):
    """The job's ``callback(sim, moved_mm)`` as the solver's ``callback(solver)``."""
    if callback is None:
        return None
    last = {}

    def step(solver):
        x = solver.x * solver.sheet.radius
        moved = float(abs(x - last["x"]).max()) if "x" in last else float("nan")
        last["x"] = x
        return callback(solver, moved)
    return step


def thin_solver(job, sheet, pattern, percent: float, start=None):
    """The :class:`foldcore.sheet.SheetSolver` of ``job``'s sheet at ``percent`` (from
    ``start``, mm, or flat); a contact it cannot keep is refused naming the file."""
    from .errors import SimulationError
    from .sheet import SheetSolver

    try:
        return SheetSolver(sheet, percent, start=start, pattern_edges=pattern.n_edges,
                           contact=thin_contact(job))
    except SimulationError as exc:
        raise SimulationError(f"{job.source}: {exc}") from None


def thin_contact(job) -> bool:
    """Whether ``job``'s thin sheet keeps its triangles apart: only where contact is
    asked for (``"on"``); ``"auto"`` folds Origami Simulator's model."""
    return job.solving.contact == "on"


def thin_settings(job) -> dict:
    """What the report records of a thin-sheet run's settings."""
    s = job.solving
    return {"pattern": job.source, "model": "sheet", "fold_percent": s.fold_percent,
            "tolerance": s.tolerance, "max_iterations": s.budget(SHEET_BUDGET),
            "thickness_mm": None, "contact": "on" if thin_contact(job) else "off"}
