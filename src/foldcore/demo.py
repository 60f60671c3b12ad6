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

DEMO_SCENES = ("d4v", "waterbomb", "miura", "hinge-study", "groove-bar")


def headline(name: str, quantities: dict) -> str:
    """One short line of a scene's quantities (angles in degrees, lengths mm)."""
    if name == "d4v":
        flat = quantities["flat"]
        return f"crease 1 at the flat target: {flat['fold_angles_deg'][0]}°"
    if name == "waterbomb":
        one, two = quantities["position_1"], quantities["position_2"]
        return (f"θm/θv {one['theta_m_deg']:.1f}/{one['theta_v_deg']:.1f} and "
                f"{two['theta_m_deg']:.1f}/{two['theta_v_deg']:.1f}")
    if name == "miura":
        worst = max(quantities[k]["max_deviation_deg"] for k in ("zigzag", "straight"))
        return f"largest deviation from the rigid-fold angles {worst}°"
    if name == "groove-bar":
        last = quantities["steps"][-1]
        return (f"pulled to {last['pull_deg']}°: hinge {last['hinge_angle_deg']}°, "
                f"panel bent {last['panel_bend_deg']}°")
    if name == "hinge-study":
        worst = max(r["angle_error_deg"] for r in quantities["runs"])
        return f"{len(quantities['runs'])} hinges, largest angle error {worst}°"
    return ""


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
              f"{wall:>8.2f}  {headline(name, run.quantities)}", flush=True)
    print(f"wrote {len(chosen)} × (FOLD, PNG, JSON) to {out}/")
    return 0


if __name__ == "__main__":
    sys.exit(main())
