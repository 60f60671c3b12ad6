"""Command line: ``foldcore simulate PATTERN [options]``.

Exit codes: 0 success (stopping at --max-iterations without convergence is a
result: exit 0, ``converged: false`` and a warning line on stderr); 2 bad input,
with one line on stderr naming the problem and no output file written.
"""
from __future__ import annotations

import argparse
import sys
import warnings

from .strategies import SOLVERS

EXIT_BAD_INPUT = 2


class _Parser(argparse.ArgumentParser):
    """argparse that reports a usage error as one line and exit code 2."""

    def error(self, message):
        self.exit(EXIT_BAD_INPUT, f"foldcore: error: {message} (see --help)\n")


def _subdivisions(text: str):
    if text == "auto":
        return "auto"
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a positive integer or 'auto', got {text!r}")
    if value < 1:
        raise argparse.ArgumentTypeError(f"expected a positive integer or 'auto', got {value}")
    return value


def _positive(text: str) -> float:
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a number, got {text!r}")
    if not value > 0 or value == float("inf"):
        raise argparse.ArgumentTypeError(f"expected a positive finite number, got {text}")
    return value


def build_parser() -> argparse.ArgumentParser:
    parser = _Parser(prog="foldcore", description="Thick-origami simulation.")
    sub = parser.add_subparsers(dest="command", required=True, parser_class=_Parser)
    sim = sub.add_parser("simulate", help="fold a crease pattern (FOLD, or OBJ/STL + hinges)")
    sim.add_argument("pattern", help="crease pattern: .fold, or .obj/.stl with a .hinges file")
    sim.add_argument("--hinges", help="hinge file of an OBJ/STL pattern (default: PATTERN.hinges)")
    sim.add_argument("--thickness", type=_positive,
                     help="sheet thickness H in mm (default: the file's foldcore:thickness)")
    sim.add_argument("--hinge-width", type=_positive,
                     help="hinge width W in mm for every crease (default: the file's widths, "
                          "else Eq. 7 with r = 0)")
    sim.add_argument("--subdivisions", type=_subdivisions, default="auto",
                     help="sub-strips per hinge, or 'auto' (default)")
    sim.add_argument("--fold-percent", type=float, default=100.0,
                     help="scale all target angles, -100…100 (default 100)")
    sim.add_argument("--solver", default="paper", choices=SOLVERS,
                     help="iteration strategy: paper (the paper's local/global map), "
                          "anderson (the same map, safeguarded Anderson acceleration), lbfgs "
                          "(L-BFGS on the same energy, K as initial Hessian) or rigid "
                          "(panels as rigid bodies, Levenberg-Marquardt; far fewer iterations "
                          "on long panels, rigid panels only); default: paper")
    sim.add_argument("--tolerance", type=_positive, default=1e-8,
                     help="stop when the largest step is below this × pattern size")
    sim.add_argument("--max-iterations", type=int, default=10_000)
    sim.add_argument("--eq8", action="store_true",
                     help="use Eq. 8 trapezoid hinge targets instead of the exact arc")
    sim.add_argument("-o", "--output", help="write the result as FOLD (achieved angles + "
                                            "folded solid in file_frames)")
    sim.add_argument("--report", help="write the JSON report here")
    sim.add_argument("--render", help="write an offscreen PNG render of the folded solid "
                                      "(needs the 'render' extra: pyvista)")
    return parser


def _load(args):
    from .io import read, read_fold_file
    from .errors import PatternError

    if args.pattern.lower().endswith(".fold"):
        if args.hinges:
            raise PatternError(f"{args.pattern}: --hinges only goes with an OBJ/STL pattern")
        fold = read_fold_file(args.pattern)
        return fold.pattern, fold.thickness
    return read(args.pattern, hinges=args.hinges), None


def simulate(args) -> int:
    """Run ``foldcore simulate``; raises FoldcoreError on bad input."""
    from .errors import SimulationError
    from .outputs import write_result
    from .simulation import Simulation
    from .thicken import thicken

    if args.max_iterations < 1:
        raise SimulationError(f"--max-iterations must be ≥ 1, got {args.max_iterations}")
    pattern, file_thickness = _load(args)
    thickness = args.thickness or file_thickness
    if thickness is None:
        raise SimulationError(f"{args.pattern}: no thickness: pass --thickness H (mm) "
                              "or set foldcore:thickness in the file")
    mesh = thicken(pattern, thickness, args.hinge_width, args.subdivisions,
                   exact_arc=not args.eq8)
    sim = Simulation(mesh, pattern, solver=args.solver)
    sim.set_fold_percent(args.fold_percent)
    result = sim.run(tolerance=args.tolerance, max_iterations=args.max_iterations)
    if not result.converged:
        print(f"foldcore: warning: not converged after {result.iterations} iterations "
              f"(tolerance {args.tolerance:g}); the result is the last iterate",
              file=sys.stderr)
    settings = {k: getattr(args, k) for k in ("pattern", "fold_percent", "solver",
                                              "tolerance", "max_iterations", "subdivisions")}
    settings.update(thickness_mm=thickness, exact_arc=not args.eq8,
                    backend=sim.system.factor.backend)
    write_result(result, pattern, mesh, thickness, settings, fold=args.output,
                 report=args.report, png=args.render)
    return 0


def main(argv=None) -> int:
    """Entry point of the ``foldcore`` command; returns the exit code."""
    from .errors import FoldcoreError

    try:
        args = build_parser().parse_args(argv)
    except SystemExit as exc:  # usage error (already reported) or --help
        return exc.code
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("default")
            return simulate(args)
    except FoldcoreError as exc:
        print(f"foldcore: error: {exc}", file=sys.stderr)
    except OSError as exc:
        name = exc.filename or args.pattern
        print(f"foldcore: error: {name}: {exc.strerror or exc}", file=sys.stderr)
    return EXIT_BAD_INPUT


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
