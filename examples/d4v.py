"""Pehrson's flat-foldable degree-4 vertex, folded to 90° and then flat.

Geometry (the paper's parameters): Ø152.4 mm, sectors 135/90/45/90°, acrylic
H = 3.175 mm, hinge widths 16/4/8/4 mm from the wrapping crease on, mode A
(V, V, V, M), slack hinges; crease 1 actuated to 90° (the others passive),
then every crease to flat. Details and provenance: ``foldcore.scenes.d4v``.

    python examples/d4v.py [OUT_DIR]     # writes d4v.fold, d4v.json, d4v.png
"""
import sys

from foldcore import scenes

run = scenes.run("d4v")
for state in ("intermediate", "flat"):
    q = run.quantities[state]
    print(f"{state:>12}: achieved {q['fold_angles_deg']} °, closed form at target "
          f"{q['closed_form_at_target_deg']} °")
flat = run.quantities["flat"]
print(f"flat: {flat['layers']} layers, stack height {flat['stack_height_mm']} mm "
      f"({flat['stack_height_in_H']} H), layers at least {flat['smallest_layer_gap_mm']} mm apart")
print("wrote", *scenes.write(run, sys.argv[1] if len(sys.argv) > 1 else "out"))
