"""A five-crease multiple-vertex box folded at H = 1 mm and H = 4 mm (paper §6.2).

Geometry (reconstructed, Chen et al.'s pattern is not available): a hexagonal
tray, bottom side 50 mm, walls 25 mm, gussets of two 30° triangles split by a
mountain diagonal; six degree-5 vertices. Hinge widths from Eq. 7 for 180°
(1.57 mm and 6.28 mm). Details and provenance: ``foldcore.scenes.box``.

    python examples/box.py [OUT_DIR]       # writes box.fold/.json/.png (the 4 mm box)
"""
import sys

from foldcore import scenes

run = scenes.run("box")
print(f"thin box (zero thickness, walls vertical): {run.quantities['thin_box_mm3']} mm³")
for q in run.quantities["runs"]:
    angles = ", ".join(f"{family} {a['achieved_mean_deg']}° (target {a['target_deg']}°)"
                       for family, a in q["fold_angles_deg"].items())
    v = q["volume_mm3"]
    print(f"H = {q['thickness_mm']} mm, W = {q['hinge_width_mm']} mm: {q['iterations']} "
          f"iterations, converged {q['converged']}, {q['seconds']} s")
    print(f"  fold angles: {angles}; walls tilted {q['wall_tilt_deg']}° outward")
    print(f"  2D sheet (mm²): {q['sheet_mm2']}")
    print(f"  capacity {v['capacity']} mm³ (material {v['material']} mm³); thin tray at the "
          f"same tilt {v['thin_same_tilt']} mm³, ratio {v['capacity_vs_thin_same_tilt']}")
print("wrote", *scenes.write(run, sys.argv[1] if len(sys.argv) > 1 else "out"))
