"""Two hinge stiffnesses, two folded shapes: a degree-4 vertex with conflicting targets.

Creases 1 and 2 of a flat-foldable vertex (sectors 135/90/45/90°, R = 50 mm,
H = 1 mm, W = 2 mm) are driven to 90° and 20°, which no rigid folding of the
vertex satisfies together (mode A pairs ρ1 = 90° with ρ2 = 45°). The other two
creases are passive. Which target wins depends on the hinges' stiffness
factors (``thicken(..., stiffness={"hinge": ...})``, FOLD key
``foldcore:edges_stiffness``): the stiffer hinge stays closer to its target.

    python examples/stiffness.py [OUT_DIR]   # writes stiffness_*.fold/.json/.png
"""
import sys
from pathlib import Path

import numpy as np

from foldcore import patterns
from foldcore.outputs import write_result
from foldcore.simulation import Simulation
from foldcore.thickening import thicken

TARGETS = {0: 90.0, 1: 20.0}  # crease → degrees
CASES = {"equal": (1.0, 1.0), "crease1_stiff": (10.0, 1.0), "crease2_stiff": (1.0, 10.0)}


def fold(factors):
    """Fold the vertex with hinge stiffness factors (crease 1, crease 2); returns the run."""
    pattern = patterns.degree4_vertex(radius=50.0, widths=[2.0] * 4, mode="A")
    angles = [TARGETS.get(e) for e in range(pattern.n_edges)]
    pattern = pattern.replace(fold_angles=angles)
    hinge = np.ones(pattern.n_edges)
    hinge[[0, 1]] = factors
    mesh = thicken(pattern, 1.0, subdivisions=4, stiffness={"hinge": hinge})
    result = Simulation(mesh, pattern, solver="rigid").run(tolerance=1e-10, max_iterations=300)
    return pattern, mesh, result


def main(out="out") -> dict:
    folder = Path(out)
    folder.mkdir(parents=True, exist_ok=True)
    achieved = {}
    for name, factors in CASES.items():
        pattern, mesh, result = fold(factors)
        achieved[name] = result.fold_angles_deg[:4]
        print(f"{name:>14}: stiffness {factors} → ρ = {np.round(achieved[name], 2)} ° "
              f"(targets ρ1 = 90°, ρ2 = 20°)")
        base = folder / f"stiffness_{name}"
        write_result(result, pattern, mesh, 1.0, {"scene": "stiffness", "factors": factors},
                     fold=base.with_suffix(".fold"), report=base.with_suffix(".json"),
                     png=base.with_suffix(".png"))
    return achieved


if __name__ == "__main__":
    main(*sys.argv[1:])
