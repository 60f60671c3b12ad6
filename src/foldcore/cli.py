"""Command line: ``foldcore simulate PATTERN [options]``, ``foldcore render RESULT.fold -o
OUT.png [options]``, ``foldcore export RESULT.fold --svg/--dxf/--stl OUT``,
``foldcore view RESULT.fold -o OUT.html`` (:mod:`foldcore.view`),
``foldcore scene NAME [--out DIR] [--render]`` (the paper's scenes, :mod:`foldcore.scenes`),
``foldcore sweep`` / ``optimize`` (design studies on Dask, :mod:`foldcore.study.commands`).

``simulate --animate OUT.gif|OUT.mp4`` also encodes the fold from 0 to ``--fold-percent``
in ``--frames`` steps (:mod:`foldcore.animate`). ``render`` and ``export`` rebuild the
thick mesh of a FOLD written by ``simulate -o`` (:func:`foldcore.fabrication.read_result`).

Exit codes: 0 success (a run that ends unconverged — stalled or at --max-iterations — is
a result: exit 0, ``converged: false`` with its ``reason`` in the report and a warning
line on stderr); 2 bad input, with one line on stderr naming the problem and no output
file written (every output path is checked before the run, :mod:`foldcore.destinations`);
130 / 143 interrupted by SIGINT / SIGTERM, one line, no half-written file. Warnings are
one line per kind, with a count of the repeats. A negative number is a value, also in
exponent form (``--ground -1e2``).
"""
from __future__ import annotations

import argparse
import logging
import math
import re
import sys
import warnings

from .hinges import DEFAULT_HINGE, HINGE_MODELS
from .actuation import ACTUATIONS, BRANCH_FLOOR_DEG, DEFAULT_ACTUATION
from .destinations import check_destinations
from .errors import FoldcoreError
from . import interrupts, result_commands
from .limits import (CELL_RATIO, GROUND_RATIO, LENGTH_MM, MARGIN_RATIO, MAX_ELASTIC_VERTICES,
                     MAX_DRIVEN, MAX_ITERATIONS, MAX_MESH_VERTICES, SHEET_BUDGET, STROKE_RATIO,
                     SUBDIVISIONS, THICK_BUDGET, THICKNESS_RATIO, TOLERANCE,
                     UNITLESS_SHEET_MM, WIDTH_RATIO)
from .options import CONTACT_CHOICES, MAX_FPS, MAX_FRAMES
from .study import commands as study_commands
from .strategies import DEFAULT_SOLVER, SOLVERS

EXIT_BAD_INPUT = 2


class _Parser(argparse.ArgumentParser):
    """argparse that reports a usage error as one line and exit code 2."""

    def __init__(self, *args, **kwargs):
        super().__init__(*args, **kwargs)
        self._negative_number_matcher = re.compile(r"^-(\d+\.?\d*|\.\d+)([eE][-+]?\d+)?$")

    def error(self, message):
        self.exit(EXIT_BAD_INPUT, f"foldcore: error: {message} (see --help)\n")


def _subdivisions(text: str):
    if text == "auto":
        return "auto"
    lo, hi = SUBDIVISIONS
    try:
        value = int(text)
    except ValueError:
        value = None
    if value is None or not lo <= value <= hi:
        raise argparse.ArgumentTypeError(f"expected an integer in {lo}..{hi} or 'auto', "
                                         f"got {text!r}")
    return value


def _number(text: str) -> float:
    try:
        return float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a number, got {text!r}")


def _positive(text: str) -> float:
    value = _number(text)
    if not value > 0 or value == float("inf"):
        raise argparse.ArgumentTypeError(f"expected a positive finite number, got {text}")
    return value


def _non_negative(text: str) -> float:
    value = _number(text)
    if not 0 <= value < float("inf"):
        raise argparse.ArgumentTypeError(f"expected a finite number ≥ 0, got {text}")
    return value


def _size(text: str) -> tuple[int, int]:
    from .render import RenderError, parse_size

    try:
        return parse_size(text)
    except RenderError as exc:
        raise argparse.ArgumentTypeError(str(exc))


def _edge_ids(text: str) -> tuple:
    """Edge ids from ``"3,7,10-12"`` (ranges inclusive), at most MAX_DRIVEN of them."""
    ids = []
    for item in text.split(","):
        lo, _, hi = item.strip().partition("-")
        try:
            first, last = int(lo), int(hi or lo)
        except ValueError:
            first, last = -1, -1
        if not 0 <= first <= last:
            raise argparse.ArgumentTypeError(
                f"expected edge ids like 3,7,10-12 (integers ≥ 0, ranges low-high), "
                f"got {item.strip()!r}")
        if len(ids) + last - first + 1 > MAX_DRIVEN:
            raise argparse.ArgumentTypeError(f"at most {MAX_DRIVEN:,} edge ids, got more "
                                             f"({item.strip()!r})")
        ids.extend(range(first, last + 1))
    return tuple(ids)


def _frames(text: str) -> int:
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected an integer ≥ 2, got {text!r}")
    if not 2 <= value <= MAX_FRAMES:
        raise argparse.ArgumentTypeError(f"expected an integer in 2..{MAX_FRAMES}, got {value}")
    return value


def _fps(text: str) -> float:
    value = _positive(text)
    if value > MAX_FPS:
        raise argparse.ArgumentTypeError(f"expected frames per second in (0, {MAX_FPS:g}], "
                                         f"got {text}")
    return value


def _add_rebuild_options(parser) -> None:
    """Options of render/export that rebuild the thick mesh of a result file."""
    parser.add_argument("--hinge-width", type=_positive,
                        help="hinge width W in mm given to simulate (default: the file's widths)"
                             f"; {WIDTH_RATIO[0]:g} … {WIDTH_RATIO[1]:g} × the sheet's extent")
    parser.add_argument("--subdivisions", type=_subdivisions, default=None,
                        help=f"sub-strips per hinge given to simulate, {SUBDIVISIONS[0]}.."
                             f"{SUBDIVISIONS[1]} (default: found from the folded frame)")


def build_parser() -> argparse.ArgumentParser:
    from . import __version__

    parser = _Parser(prog="foldcore", description="Thick-origami simulation.")
    parser.add_argument("--version", action="version", version=f"foldcore {__version__}")
    sub = parser.add_subparsers(dest="command", required=True, parser_class=_Parser)
    _add_simulate(sub)
    _add_render(sub)
    _add_export(sub)
    view = sub.add_parser("view", help="an interactive HTML page of a result FOLD")
    view.add_argument("result", help="FOLD file written by foldcore simulate -o / --series")
    view.add_argument("-o", "--output", required=True, help="HTML page to write")
    _add_scene(sub)
    study_commands.add_to(sub)
    for command in sub.choices.values():
        command.add_argument("-v", "--verbose", action="count", default=0,
                             help="log what the run does (stages, phase hand-overs, "
                                  "refactorisations, thread choices) on stderr; -vv: more")
    return parser


def _add_simulate(sub) -> None:
    sim = sub.add_parser("simulate", help="fold a crease pattern (FOLD, SVG, .cp, .opx, "
                                          "or OBJ/STL + hinges)")
    sim.add_argument("pattern", help="crease pattern: .fold, .svg, .cp, .opx, or .obj/.stl "
                                     "with a .hinges file")
    _add_reading(sim)
    _add_thickening(sim)
    _add_solving(sim)
    sim.add_argument("-q", "--quiet", action="store_true",
                     help="no progress bar and no summary line on stderr (warnings and "
                          "errors are still said); the bar shows only on a terminal, "
                          f"after {PROGRESS_DELAY:g} s")
    _add_outputs(sim)


def _add_reading(sim) -> None:
    sim.add_argument("--hinges", help="hinge file of an OBJ/STL pattern (default: PATTERN.hinges)")
    sim.add_argument("--mv-passive", action="store_true",
                     help="in a FOLD file without edges_foldAngle, M/V creases stay passive "
                          "(default: they fold to -/+180 degrees x the fold percent, as in "
                          "Origami Simulator)")
    sim.add_argument("--drive", type=_edge_ids, metavar="EDGES",
                     help="drive only these creases (edge ids as read, e.g. 3,7,10-12): "
                          "every other crease with a target is left passive (F edges "
                          "keep 0 degrees); default: every crease with a target")
    sim.add_argument("--trust-assignment", action="store_true",
                     help="an angle whose sign contradicts its M/V assignment takes the "
                          "assignment's sign (default: refused, naming the edge)")
    size = sim.add_mutually_exclusive_group()
    size.add_argument("--scale", type=_positive, metavar="FACTOR",
                      help="multiply every length of the pattern file (after its "
                           "frame_unit) by FACTOR; the sheet's larger extent must then be "
                           f"{LENGTH_MM[0]:g} … {LENGTH_MM[1]:g} mm, as every length")
    size.add_argument("--sheet-size", type=_positive, metavar="MM",
                      help="scale the pattern so that its larger extent is MM millimetres, "
                           f"{LENGTH_MM[0]:g} … {LENGTH_MM[1]:g} (a FOLD file that declares "
                           f"no unit is otherwise {UNITLESS_SHEET_MM:g} mm across)")


def _add_thickening(sim) -> None:
    extent, lo, hi = "× the sheet's extent", *THICKNESS_RATIO
    sim.add_argument("--thickness", type=_positive,
                     help="sheet thickness H in mm (default: the file's foldcore:thickness; "
                          f"none: a thin sheet), {lo:g} … {hi:g} {extent}")
    sim.add_argument("--hinge-width", type=_positive,
                     help="hinge width W in mm for every crease (default: the file's widths, "
                          f"else Eq. 7 with r = 0), {WIDTH_RATIO[0]:g} … {WIDTH_RATIO[1]:g} "
                          f"{extent}")
    sim.add_argument("--subdivisions", type=_subdivisions, default="auto",
                     help=f"sub-strips per hinge, {SUBDIVISIONS[0]}..{SUBDIVISIONS[1]}, or "
                          "'auto' (default: 2..16 from each hinge's largest angle)")
    sim.add_argument("--elastic-cells", type=_positive, metavar="MM",
                     help="elastic panels: cut every face into rings of cells about MM mm "
                          "long, so panels bend and stretch where the targets ask for it "
                          "(non-rigidly-foldable patterns), MM "
                          f"{CELL_RATIO[0]:g} … {CELL_RATIO[1]:g} {extent}; default: rigid "
                          f"panels. A thick mesh may have {MAX_MESH_VERTICES:,} vertices, "
                          f"{MAX_ELASTIC_VERTICES:,} of them in elastic cells (checked before "
                          "it is built)")
    sim.add_argument("--hinge", choices=HINGE_MODELS,
                     help="hinge model of every crease: axis (panels turn about the crease, "
                          "rigid-origami kinematics at any thickness), arc (the paper's "
                          "constant-length arc), eq8 (the paper's Eq. 8 trapezoid) or slack "
                          "(compliant joints: an arc of free length between axis's and the "
                          "width; solvers hybrid and newton); default: "
                          f"the file's foldcore:edges_hinge, else {DEFAULT_HINGE}")
    sim.add_argument("--eq8", dest="hinge", action="store_const", const="eq8",
                     help="same as --hinge eq8")


def _add_solving(sim) -> None:
    sim.add_argument("--fold-percent", type=float, default=100.0,
                     help="scale all target angles, -100…100 (default 100)")
    sim.add_argument("--solver", default=DEFAULT_SOLVER, choices=SOLVERS,
                     help="iteration strategy: hybrid (default: rigid-body steps, then "
                          "newton where they cannot finish), rigid (panels as rigid bodies, "
                          "Levenberg-Marquardt), newton (Gauss-Newton on every vertex), "
                          "paper (the paper's local/global map), anderson or lbfgs (the "
                          "same map accelerated)")
    sim.add_argument("--tolerance", type=_positive, default=1e-8,
                     help="stop when the state is this × the pattern size from its "
                          f"equilibrium, {TOLERANCE[0]:g} … {TOLERANCE[1]:g} (default 1e-8): "
                          "looser, a run reads converged degrees short of it; tighter, float64 "
                          "cannot resolve it")
    sim.add_argument("--max-iterations", type=int, default=None,
                     help=f"iteration budget, 1 … {MAX_ITERATIONS:,} (default {THICK_BUDGET:,} "
                          f"for a thick sheet, {SHEET_BUDGET:,} Newton steps for a thin one)")
    sim.add_argument("--actuation", choices=ACTUATIONS, default=DEFAULT_ACTUATION,
                     help="equal (an actuated hinge weighs what a passive one does, the "
                          "paper's) or angle (actuated hinges 1000x stiffer: their angles are "
                          f"met where the model binds); default {DEFAULT_ACTUATION}")
    sim.add_argument("--branch-floor", type=_non_negative, default=BRANCH_FLOOR_DEG, metavar="DEG",
                     help="from a flat sheet, first fold with passive M/V creases held at "
                          "least DEG degrees (0 … 180) on their assigned side, then release "
                          "them (branch selection; 0 turns it off; default "
                          f"{BRANCH_FLOOR_DEG:g})")
    sim.add_argument("--contact", choices=CONTACT_CHOICES, default="auto",
                     help="panels no crease joins never pass through each other (IPC "
                          "barrier and collision-checked steps; solvers hybrid, rigid, "
                          "newton, lbfgs; needs the ipctk package): auto (default) wherever "
                          "the run can (thick rigid panels, no cuts, axis or slack hinges), "
                          "on (refused where it cannot be; a thin sheet's triangles never "
                          "pass through each other), off; on with --obstacle or --ground")
    sim.add_argument("--obstacle", action="append", default=[], metavar="MESH",
                     help="a fixed obstacle the sheet touches but never passes: a mesh file "
                          "(STL, OBJ, PLY, ... read by meshio) in mm in the pattern's frame "
                          "(the flat sheet's mid-surface is z = 0); repeatable; turns contact "
                          "on")
    sim.add_argument("--ground", type=float, default=None, metavar="Z",
                     help="a horizontal plane at height Z mm, facing up, the sheet never "
                          "passes (the flat sheet's bottom face is at -H/2; |Z| at most "
                          f"{GROUND_RATIO:g} × the sheet's extent); turns contact on")


def _add_outputs(sim) -> None:
    sim.add_argument("-o", "--output", help="write the result as FOLD (achieved angles + "
                                            "folded solid in file_frames)")
    sim.add_argument("--report", help="write the JSON report here")
    sim.add_argument("--render", help="write an offscreen PNG render of the folded solid "
                                      "(needs the 'render' extra: pyvista)")
    sim.add_argument("--animate", metavar="OUT.gif|OUT.mp4",
                     help="also write an animation of the fold from 0 to --fold-percent "
                          "(needs the 'render' extra; MP4 the 'video' extra: imageio-ffmpeg)")
    sim.add_argument("--series", metavar="OUT.fold",
                     help="also write the fold from 0 to --fold-percent as one FOLD file, a "
                          "frame per fold percent (achieved angles and the folded solid)")
    sim.add_argument("--frames", type=_frames, default=20,
                     help="frames of --animate / --series, fold percents evenly from 0, "
                          f"2..{MAX_FRAMES} (default 20)")
    sim.add_argument("--fps", type=_fps, default=10.0,
                     help=f"animation frames per second, (0, {MAX_FPS:g}] (default 10)")


def _add_render(sub) -> None:
    ren = sub.add_parser("render", help="render a result FOLD (simulate -o) to PNG")
    ren.add_argument("result", help="FOLD file written by foldcore simulate -o")
    ren.add_argument("-o", "--output", required=True, help="PNG to write")
    ren.add_argument("--view", default="iso", choices=("iso", "top", "side", "front"),
                     help="camera: iso (default), top, side (from +x), front (from -y)")
    ren.add_argument("--size", type=_size, default=(1024, 768),
                     help="picture size WIDTHxHEIGHT in pixels, each 16..8192 (default "
                          "1024x768)")
    ren.add_argument("--color-by", default="none",
                     choices=("angle", "strip-angle", "strain", "none"),
                     help="hinge colours: mountain/valley (none, default), each crease's fold "
                          "angle (angle) or each sub-strip's bend angle (strip-angle), degrees, "
                          "or each sub-strip's largest surface tension (strain); a thin "
                          "sheet: its creases by angle, its facets by side strain (strain)")
    _add_rebuild_options(ren)


def _add_export(sub) -> None:
    exp = sub.add_parser("export", help="fabrication files of a result FOLD (simulate -o)")
    exp.add_argument("result", help="FOLD file written by foldcore simulate -o")
    exp.add_argument("--svg", help="flat sheet outlines as SVG (mm)")
    exp.add_argument("--dxf", help="flat sheet outlines as DXF (mm; needs the 'export' extra)")
    exp.add_argument("--stl", help="folded solid as binary STL (mm)")
    exp.add_argument("--stroke-width", type=_positive, metavar="MM",
                     help=f"SVG stroke width in mm, {STROKE_RATIO[0]:g} … {STROKE_RATIO[1]:g} × "
                          "the sheet's extent (default: 1/1000 of the sheet, at most 0.1 mm)")
    exp.add_argument("--margin", type=_non_negative, metavar="MM",
                     help=f"SVG margin around the sheet in mm, {MARGIN_RATIO[0]:g} … "
                          f"{MARGIN_RATIO[1]:g} × its extent (default: 2%% of the sheet)")
    _add_rebuild_options(exp)


def _add_scene(sub) -> None:
    from .scenes import NAMES

    scn = sub.add_parser("scene", help="fold one of the paper's scenes and write its outputs")
    scn.add_argument("name", choices=list(NAMES), metavar="NAME",
                     help="; ".join(f"{k}: {v}" for k, v in NAMES.items()))
    scn.add_argument("--out", default=".", help="output folder (default: current folder)")
    scn.add_argument("--render", action="store_true",
                     help="also write NAME.png (needs the 'render' extra: pyvista)")
    scn.add_argument("--solver", choices=SOLVERS,
                     help="iteration strategy (default: the scene's own, see its docstring)")
    scn.add_argument("--quick", action="store_true",
                     help="lower iteration budgets (tests); same geometry")
    scn.add_argument("--contact", choices=CONTACT_CHOICES,
                     help="panels never pass through each other: auto (wherever the scene's "
                          "runs can: thick rigid panels), on, off; default: the scene's "
                          "own (on for gripper, else auto)")


def run_scene(args) -> int:
    """Run ``foldcore scene``: NAME.fold and NAME.json (+ NAME.png) in --out."""
    from pathlib import Path

    from . import scenes

    if not args.out or not Path(args.out).is_dir():  # ("" would be the current folder)
        raise FoldcoreError(f"{args.out or '--out ' + repr('')}: output folder does not exist")
    check_destinations({"--out": Path(args.out) / f"{args.name}.fold"})  # writable, before
    run = scenes.run(args.name, quick=args.quick, solver=args.solver,
                     contact=args.contact)
    for path in scenes.write(run, args.out, png=args.render):
        print(path)
    if not run.result.converged:
        how = ("stopped at its iteration budget" if run.result.reason == "budget"
               else f"ended {run.result.reason}")
        print(f"foldcore: warning: {args.name}: the last run {how} without converging",
              file=sys.stderr)
    return 0


def simulate(args) -> int:
    """Run ``foldcore simulate`` (:func:`foldcore.job.fold`); raises FoldcoreError on
    bad input."""
    from .job import Interrupted, fold

    progress = _progress(args)
    try:
        done = fold(args.pattern, callback=progress, on_start=getattr(args, "say_warnings", None),
                    **option_groups(args))
    except Interrupted as stop:
        written = ", ".join(f"{in_flags(k)} {v}" for k, v in stop.written.items())
        if stop.partial:
            print(f"foldcore: interrupted (SIGINT) after {stop.result.iterations} iterations; "
                  + (f"the last iterate was written as a partial result ({written}; marked "
                     "foldcore:partial)" if written else "no output was asked for"),
                  file=sys.stderr)
        else:
            print("foldcore: interrupted (SIGINT) while the finished result was written; "
                  f"its outputs were completed first ({written or 'none asked for'})",
                  file=sys.stderr)
        return interrupts.EXIT_SIGINT
    finally:
        if progress is not None:
            progress.close()
    result = done.result
    if not result.converged:
        print(f"foldcore: warning: {args.pattern}: not converged after {result.iterations} "
              f"iterations ({_why(result)}; tolerance {args.tolerance:g}); the result is "
              "the last iterate", file=sys.stderr)
    if not args.quiet:
        print(done.summary, file=sys.stderr)
    return 0


def option_groups(args) -> dict:
    """The library's option groups (:mod:`foldcore.options`) from the flags."""
    from .io import Reading
    from .options import Outputs, Solving, Thickening

    return {"hinges": args.hinges,
            "reading": Reading(mv_without_angle="passive" if args.mv_passive else "fold",
                               trust_assignment=args.trust_assignment, scale=args.scale,
                               size=args.sheet_size, drive=args.drive),
            "thickening": Thickening(args.thickness, args.hinge_width, args.subdivisions,
                                     args.hinge, args.elastic_cells),
            "solving": Solving(args.fold_percent, args.solver, args.tolerance,
                               args.max_iterations, args.actuation, args.branch_floor,
                               contact=args.contact, obstacles=tuple(args.obstacle),
                               ground=args.ground),
            "outputs": Outputs(args.output, args.report, args.render, args.animate,
                               args.series, args.frames, args.fps)}


def in_flags(text: str) -> str:
    """A library message in the command line's words: each option name
    (``group.field``) replaced by its flag (:data:`foldcore.options.FLAGS`)."""
    from .options import FLAGS

    for name in sorted(FLAGS, key=len, reverse=True):
        text = text.replace(name, FLAGS[name])
    return text


class _Progress:
    """A tqdm bar on stderr for a run: iterations against --max-iterations, the last
    step relative to the tolerance's limit, and the ETA; shown only once the run
    has taken PROGRESS_DELAY seconds."""

    def __init__(self, total: int, limit_ratio: float):
        from tqdm import tqdm

        self._bar = tqdm(total=total, unit="it", delay=PROGRESS_DELAY, file=sys.stderr,
                         leave=False, dynamic_ncols=True)
        self._size_limit = limit_ratio

    def __call__(self, sim, moved: float) -> bool:
        self._bar.update(1)
        if self._bar.n % 10 == 0:
            self._bar.set_postfix_str(
                f"step/limit {moved / (self._size_limit * sim.length_scale):.2g}", refresh=False)
        return True

    def close(self) -> None:
        self._bar.close()


#: Seconds a run takes before its progress bar appears.
PROGRESS_DELAY = 2.0


def _progress(args):
    """A progress callback for an interactive run (stderr a terminal, no --quiet, no
    --animate or --series: their frames have their own runs), else None."""
    if args.quiet or args.animate or args.series or not sys.stderr.isatty():
        return None
    try:
        return _Progress(args.max_iterations, args.tolerance)
    except ImportError:  # tqdm is a dependency; a stripped install runs without a bar
        return None


def _why(result) -> str:
    """Why a run ended unconverged, in words (Result.reason and residual)."""
    far = ("" if math.isnan(result.residual) else  # NaN: never estimated
           f", the equilibrium estimated {result.residual:.1e} × the pattern size away")
    return {"stalled": "stalled: no step of the strategy reaches the equilibrium" + far,
            "budget": f"its budget of {result.iterations:,} iterations ran out "
                      "(--max-iterations sets it)" + far,
            "callback": "stopped"}.get(result.reason, result.reason)


COMMANDS = {"simulate": simulate, "scene": run_scene, **result_commands.COMMANDS,
            **study_commands.COMMANDS}


def _say_warnings(caught: list) -> None:
    """Print the warnings caught so far (:func:`_warning_lines`) and forget them."""
    for line in _warning_lines(caught):
        print(line, file=sys.stderr)
    caught.clear()


def _warning_lines(caught) -> list[str]:
    """One line per kind of warning, in order of first appearance: the first message
    and how many more like it (the same text up to its numbers) followed."""
    first, counts = {}, {}
    for w in caught:
        text = " ".join(str(w.message).split())
        key = (w.category.__name__, re.sub(r"\d+(\.\d+)?", "#", text))
        first.setdefault(key, text)
        counts[key] = counts.get(key, 0) + 1
    return [f"foldcore: warning: {in_flags(first[k])}" + (f" (and {counts[k] - 1} more like it)"
                                                           if counts[k] > 1 else "")
            for k in first]


def main(argv=None) -> int:
    """Entry point of the ``foldcore`` command; returns the exit code.

    Warnings are printed one line per kind, with a count, after the command
    succeeds; a refusal prints only its own line. SIGINT and SIGTERM end the
    command with one line and exit codes 130 and 143, from the first statement
    on (parsing the arguments imports most of the package; :mod:`foldcore.interrupts`);
    files not yet complete are not written (their temporary files are removed,
    :mod:`foldcore.destinations`).
    """
    with interrupts.handled():
        return _main(argv)


def _main(argv) -> int:
    """:func:`main` under its signal handlers."""
    args = handler = None
    try:
        args = build_parser().parse_args(argv)
        handler = _log_to_stderr(args.verbose)
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            warnings.simplefilter("ignore", ResourceWarning)  # (a file an interrupt left open)
            args.say_warnings = lambda: _say_warnings(caught)  # before a long run, too
            code = COMMANDS[args.command](args)
        _say_warnings(caught)
        return code
    except SystemExit as exc:  # usage error (already reported) or --help
        return exc.code
    except FoldcoreError as exc:
        print(f"foldcore: error: {in_flags(str(exc))}", file=sys.stderr)
    except OSError as exc:
        name = exc.filename or getattr(args, "pattern", None) or getattr(args, "result", "")
        print(f"foldcore: error: {name}: {exc.strerror or exc}", file=sys.stderr)
    except MemoryError:
        name = getattr(args, "pattern", None) or getattr(args, "result", None) \
            or getattr(args, "command", "foldcore")
        print(f"foldcore: error: {name}: out of memory (a smaller file, fewer cells or "
              "sub-strips, or more memory)", file=sys.stderr)
    except BaseException as exc:  # a signal, or what code it passed through made of it
        signalled = interrupts.caught(exc)
        if signalled is None:
            raise
        print(f"foldcore: {signalled[1]}; files not yet complete were not written", file=sys.stderr)
        return signalled[0]
    finally:
        if handler is not None:
            logging.getLogger("foldcore").removeHandler(handler)
    return EXIT_BAD_INPUT


def _log_to_stderr(verbosity: int):
    """The ``foldcore`` logger on stderr at INFO (``-v``) or DEBUG (``-vv``); the
    handler, to remove after the command (None: quiet, the library's default)."""
    if not verbosity:
        return None
    handler = logging.StreamHandler(sys.stderr)
    handler.setFormatter(logging.Formatter("foldcore: %(message)s"))
    logger = logging.getLogger("foldcore")
    logger.addHandler(handler)
    logger.setLevel(logging.INFO if verbosity == 1 else logging.DEBUG)
    return handler


if __name__ == "__main__":  # pragma: no cover  (python -m foldcore.cli: as python -m foldcore)
    sys.exit(interrupts.run_command(main))
