"""A 4×4 Miura-ori sheet folded along its rigid-folding path to facet tilt 30°.

Geometry: a = b = 20 mm, γ = 60°, H = 1 mm, W = 2 mm; every crease actuated to
its zero-thickness angle. Details: ``foldcore.scenes.miura``.

    python examples/miura.py [OUT_DIR]       # writes miura.fold/.json/.png
"""
import sys

from foldcore import scenes

run = scenes.run("miura")
for family in ("zigzag", "straight"):
    q = run.quantities[family]
    print(f"{family:>8}: closed form {q['closed_form_deg']}°, achieved mean "
          f"{q['achieved_mean_deg']}°, largest deviation {q['max_deviation_deg']}°")
print("extents (mm):", run.quantities["extent_mm"])
print("wrote", *scenes.write(run, sys.argv[1] if len(sys.argv) > 1 else "out"))
