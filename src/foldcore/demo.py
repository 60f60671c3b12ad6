"""The main job: fold the built-in demo scenes and write FOLD + PNG + JSON.

Run ``python -m foldcore.demo --out out`` (``make demo``). Each scene writes
``NAME.fold`` (achieved angles + folded thick solid), ``NAME.png`` (offscreen
render) and ``NAME.json`` (the run report) to the output folder, and one line
to stdout: iterations, convergence, the largest fold-angle error against the
targets (degrees) and the wall time.

The Miura cell is actuated on every crease with the zero-thickness rigid-fold
angles; with hinges of finite width those targets are not exactly compatible,
so its achieved angles differ from them (reported, not hidden).

The scenes are kept to short panels (panel length ≤ 5 H): the paper's plain
iteration slows down sharply as panels grow relative to the thickness
(DESIGN.md, "Convergence").
"""
from __future__ import annotations

import argparse
import sys
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Callable

import numpy as np


@dataclass(frozen=True)
class Scene:
    """A pattern, its thickness and how to run it."""

    name: str
    build: Callable          # () -> CreasePattern with actuated targets
    thickness: float         # mm
    subdivisions: int | str = "auto"
    hinge_width: float | None = None   # mm; None: the pattern's or Eq. 7
    tolerance: float = 1e-8
    max_iterations: int = 40_000


def _scenes() -> list[Scene]:
    from . import patterns

    return [
        Scene("hinge_90", lambda: patterns.single_hinge(panel_length=5.0, depth=4.0,
                                                        angle=90.0, width=2.0),
              thickness=1.0, subdivisions=4),
        Scene("hinge_mountain_150", lambda: patterns.single_hinge(
            panel_length=5.0, depth=4.0, angle=-150.0, assignment="M", width=2.0),
              thickness=1.0, subdivisions=4),
        Scene("miura_2x2", _miura_folded, thickness=1.0, subdivisions=4,
              hinge_width=2.0),
    ]


def _miura_folded(n: int = 2, m: int = 2, size: float = 5.0, gamma: float = 60.0,
                  tilt: float = 30.0):
    """n×m Miura-ori, every crease actuated to its rigid-fold angle at facet tilt (deg)."""
    from . import kinematics, patterns

    pattern = patterns.miura(n, m, a=size, b=size, gamma=gamma)
    zigzag, straight = kinematics.miura_angles_deg(gamma, tilt)
    kinds = patterns.miura_edge_kinds(n, m)
    magnitude = np.select([kinds == "zigzag", kinds == "straight"], [zigzag, straight], np.nan)
    sign = np.where(pattern.assignments == "M", -1.0, 1.0)
    return pattern.replace(fold_angles=np.where(kinds == "boundary", np.nan, sign * magnitude))


def run_scene(scene: Scene, out: Path) -> dict:
    """Fold one scene and write its outputs; returns its summary (see module doc)."""
    from .outputs import write_result
    from .simulation import Simulation
    from .thicken import thicken

    start = time.perf_counter()
    pattern = scene.build()
    mesh = thicken(pattern, scene.thickness, scene.hinge_width, scene.subdivisions)
    sim = Simulation(mesh, pattern)
    result = sim.run(tolerance=scene.tolerance, max_iterations=scene.max_iterations)
    wall = time.perf_counter() - start
    base = out / scene.name
    settings = {"scene": scene.name, "thickness_mm": scene.thickness,
                "tolerance": scene.tolerance, "max_iterations": scene.max_iterations,
                "solver": sim.solver, "backend": sim.system.factor.backend}
    write_result(result, pattern, mesh, scene.thickness, settings,
                 fold=base.with_suffix(".fold"), report=base.with_suffix(".json"),
                 png=base.with_suffix(".png"))
    error = np.abs(result.fold_angles_deg - pattern.fold_angles)
    return {"scene": scene.name, "iterations": result.iterations,
            "converged": result.converged, "max_error_deg": float(np.nanmax(error)),
            "wall_s": wall}


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(prog="python -m foldcore.demo", description=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--out", default="out", help="output folder (default: out)")
    parser.add_argument("--scene", action="append",
                        help="run only this scene (repeatable; default: all)")
    args = parser.parse_args(argv)
    scenes = [s for s in _scenes() if not args.scene or s.name in args.scene]
    if not scenes:
        parser.exit(2, f"foldcore.demo: error: no scene named {args.scene}\n")
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    print(f"{'scene':<22}{'iterations':>11}{'converged':>11}{'max|Δθ| °':>11}{'wall s':>9}")
    for scene in scenes:
        s = run_scene(scene, out)
        print(f"{s['scene']:<22}{s['iterations']:>11}{str(s['converged']):>11}"
              f"{s['max_error_deg']:>11.4f}{s['wall_s']:>9.2f}", flush=True)
    print(f"wrote {len(scenes)} × (FOLD, PNG, JSON) to {out}/")
    return 0


if __name__ == "__main__":
    sys.exit(main())
