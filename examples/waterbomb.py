"""The 6-crease waterbomb base in its two stable positions, beside the paper's Table 1.

Geometry: 6 equal creases (R = 50 mm), alternating M/V, H = 1 mm, W = 2 mm — a
reconstruction (the paper does not give the dimensions); each position is
folded from flat by hinge actuation. Details and provenance:
``foldcore.scenes.waterbomb``.

    python examples/waterbomb.py [OUT_DIR]   # writes waterbomb.fold/.json/.png
"""
import sys

from foldcore import scenes

run = scenes.run("waterbomb")
for position in ("position_1", "position_2"):
    q = run.quantities[position]
    print(f"{position}: θm = {q['theta_m_deg']}°, θv = {q['theta_v_deg']}° "
          f"(Table 1: {q['table_1']}; closed-form minor {q['closed_form_minor_deg']}°)")
print("wrote", *scenes.write(run, sys.argv[1] if len(sys.argv) > 1 else "out"))
