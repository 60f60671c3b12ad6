"""Pehrson's flat-foldable degree-4 vertex, folded to 90° and toward flat.

Geometry (the paper's parameters): Ø152.4 mm, sectors 135/90/45/90°, acrylic
H = 3.175 mm, hinge widths 16/4/8/4 mm, mode A (V, V, V, M); crease 1 actuated,
the others passive. Details and provenance: ``foldcore.scenes.d4v``.

    python examples/d4v.py [OUT_DIR]     # writes d4v.fold, d4v.json, d4v.png
"""
import sys

from foldcore import scenes

run = scenes.run("d4v")
for state in ("intermediate", "flat"):
    q = run.quantities[state]
    print(f"{state:>12}: achieved {q['fold_angles_deg']} °, closed form at target "
          f"{q['closed_form_at_target_deg']} °")
print(f"stack height at the flat target: {run.quantities['flat']['stack_height_mm']} mm")
print("wrote", *scenes.write(run, sys.argv[1] if len(sys.argv) > 1 else "out"))
