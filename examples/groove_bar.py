"""An elastic bar with a 90° V-groove joint pulled past its limit: the hinge stops, the panels bend.

Geometry (a reconstruction of the paper's groove bar): two panels 40 × 10 mm,
H = 2 mm, hinge W = 3 mm with θmax = 90°, each panel 8 elastic cells. Details:
``foldcore.scenes.groove_bar``.

    python examples/groove_bar.py [OUT_DIR]   # writes groove-bar.fold/.json/.png
"""
import sys

from foldcore import scenes

run = scenes.run("groove-bar")
print(f"{'pull °':>7} {'hinge °':>8} {'panel bend °':>12} {'panel deviation':>15}")
for s in run.quantities["steps"]:
    print(f"{s['pull_deg']:>7} {s['hinge_angle_deg']:>8.3f} {s['panel_bend_deg']:>12.3f} "
          f"{s['panel_deviation']:>15.2e}")
print("wrote", *scenes.write(run, sys.argv[1] if len(sys.argv) > 1 else "out"))
