"""A linear chain of spherical mechanisms (a 2 × 8 Miura strip) deployed, then pushed
across one end: the transverse push shortens the chain along its length until its
hinges reach their 180° limits.

Geometry: cardboard H = 3 mm, W = 4.71 mm, facets a = 29 mm, b = 22 mm, γ = 60°
(a reconstruction of the paper's Frog's-Tongue chain). Details: ``foldcore.scenes.chain``.

    python examples/chain.py [OUT_DIR]       # writes chain.fold/.json/.png
"""
import sys

from foldcore import scenes

run = scenes.run("chain")
print(f"{'push':>6} {'transverse':>11} {'longitudinal':>13} {'max zig-zag':>12}  (mm, deg)")
for row in run.quantities["pushes"]:
    print(f"{row['push_mm']:6.1f} {row['transverse_mm']:11.2f} {row['longitudinal_mm']:13.2f} "
          f"{row['max_zigzag_deg']:12.1f}")
print("wrote", *scenes.write(run, sys.argv[1] if len(sys.argv) > 1 else "out"))
