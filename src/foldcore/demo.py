"""The main job: fold the paper's scenes and write FOLD + PNG + JSON for each.

Run ``python -m foldcore.demo --out out`` (``make demo``). Each scene of
:mod:`foldcore.scenes` writes ``NAME.fold`` (achieved angles + folded thick
solid), ``NAME.png`` (offscreen render) and ``NAME.json`` (the run report with
the scene's own ``quantities``) to the output folder, and one line to
stdout: the final run's iterations and convergence, the scene's headline
quantity and the wall time (s). What each scene measures and where its
geometry comes from is in its module docstring (``foldcore.scenes.d4v`` …).
"""
from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

DEMO_SCENES = ("d4v", "waterbomb", "miura", "hinge-study", "groove-bar", "chain", "box",
               "gripper")


def main(argv=None) -> int:
    from . import scenes

    parser = argparse.ArgumentParser(prog="python -m foldcore.demo", description=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--out", default="out", help="output folder (default: out)")
    parser.add_argument("--scene", action="append", choices=list(scenes.NAMES),
                        help="run only this scene (repeatable; default: "
                             f"{', '.join(DEMO_SCENES)})")
    args = parser.parse_args(argv)
    out = Path(args.out)
    chosen = args.scene or DEMO_SCENES
    print(f"{'scene':<13}{'iterations':>11}{'converged':>11}{'wall s':>8}  headline")
    for name in chosen:
        start = time.perf_counter()
        run = scenes.run(name)
        scenes.write(run, out)
        wall = time.perf_counter() - start
        print(f"{name:<13}{run.result.iterations:>11}{str(run.result.converged):>11}"
              f"{wall:>8.2f}  {scenes.headline(name, run.quantities)}", flush=True)
    print(f"wrote {len(chosen)} × (FOLD, PNG, JSON) to {out}/")
    return 0


if __name__ == "__main__":
    sys.exit(main())
