"""A 3 × 3 Miura sheet with rigid panels and with elastic plates (beyond paper §5.5).

Every crease is driven to its zero-thickness rigid-fold angle at facet tilt
30° (a = b = 20 mm, γ = 60°, H = 1 mm, W = 2 mm, k = 2), with rigid panels
and with ``elastic="plates"`` (cells of at most 5 mm; the strips' Eq. 1 gaps
at acute/obtuse corners become extra cells or triangles), under two hinge
models. With the default axis hinge the angles are compatible at any
thickness: both sheets meet them and the plates stay unstrained. With the
paper's arc hinge the thick vertices cannot meet them (the hinge axes sit
off the creases), and the plates flex to absorb part of the mismatch.
Printed: cells, iterations, and the largest deviation from the rigid-fold
angles (degrees).

    python examples/miura_plates.py [OUT_DIR]   # miura_{axis,arc}_{rigid,plates}.fold/.json/.png
"""
import sys
from pathlib import Path

import numpy as np

from foldcore import patterns
from foldcore.outputs import write_result
from foldcore.simulation import Simulation
from foldcore.thickening import thicken

N, A, GAMMA, TILT = 3, 20.0, 60.0, 30.0  # facets, mm, degrees, degrees
THICKNESS, WIDTH, CELL = 1.0, 2.0, 5.0  # mm


def actuated_miura():
    return patterns.miura(N, N, a=A, b=A, gamma=GAMMA, width=WIDTH).replace(
        fold_angles=patterns.miura_fold_angles(N, N, GAMMA, TILT))


def main(out="out") -> dict:
    folder = Path(out)
    folder.mkdir(parents=True, exist_ok=True)
    pattern = actuated_miura()
    deviation = {}
    for hinge, panels, elastic in (("axis", "rigid", None), ("axis", "plates", "plates"),
                                   ("arc", "rigid", None), ("arc", "plates", "plates")):
        name = f"{hinge}_{panels}"
        mesh = thicken(pattern, THICKNESS, subdivisions=2, elastic=elastic, cell_size=CELL,
                       hinge=hinge)
        result = Simulation(mesh, pattern).run(tolerance=1e-9, max_iterations=20_000)
        creases = pattern.creases
        deviation[name] = float(np.abs(result.fold_angles_deg[creases]
                                       - pattern.fold_angles[creases]).max())
        print(f"{name:>12}: {len(mesh.groups['rigid_panel'])} panel cells, {result.iterations} "
              f"iterations (converged {result.converged}), largest deviation from the "
              f"rigid-fold angles {deviation[name]:.3f}°")
        base = folder / f"miura_{name}"
        write_result(result, pattern, mesh, THICKNESS,
                     {"scene": "miura_plates", "panels": panels, "hinge": hinge},
                     fold=base.with_suffix(".fold"), report=base.with_suffix(".json"),
                     png=base.with_suffix(".png"))
    return deviation


if __name__ == "__main__":
    main(*sys.argv[1:])
