"""One hinge (H = 0.5 mm) folded 180°: bend radius and angle error vs subdivisions.

The paper's study: W = 0.8 mm (Eq. 7 with r ≈ 0) and W = 1 mm, k = 2, 4, 8, with
each hinge model: Eq. 8 trapezoids, the constant-length arc and the axis hinge. Details: ``foldcore.scenes.hinge_study``.

    python examples/hinge_study.py [OUT_DIR]  # writes hinge-study.fold/.json/.png
"""
import sys

from foldcore import scenes

run = scenes.run("hinge-study")
print(f"{'hinge':>10} {'W mm':>5} {'k':>2} {'angle err °':>11} {'r mm':>9} {'Eq.7 r mm':>9}")
for row in run.quantities["runs"]:
    radius = "—" if row["inner_radius_mm"] is None else f"{row['inner_radius_mm']:.5f}"
    print(f"{row['hinge']:>10} {row['width_mm']:>5} {row['subdivisions']:>2} "
          f"{row['angle_error_deg']:>11.5f} {radius:>9} {row['eq7_inner_radius_mm']:>9.5f}")
print("wrote", *scenes.write(run, sys.argv[1] if len(sys.argv) > 1 else "out"))
