"""A scene with a user-defined element: a bar props a hinge open short of its target.

One hinge (panels 20 mm, H = 1 mm, W = 2 mm, k = 4) is actuated to 90°; a bar
joins the far top edges of its two panels with the length they have when
the hinge is folded to 60° (geometry below). The bar is stiff (weight 100×
the hinge's), so the hinge stops near 60°, not 90°: the angle printed is
where the bar's and the hinge's springs balance — 58.79° with the default
axis hinge, whose strips, held short of 90°, still shorten toward their 90°
length and draw the panels together (60.11° with ``hinge="arc"``, whose
strips keep their length; measured). ``bar.py`` defines the
element type; nothing in foldcore is edited.

    python examples/plugin_bar/prop.py [OUT_DIR]   # writes prop.fold / prop.json
"""
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).parent))
from bar import bar_group  # noqa: E402  (defining Bar registers the type)

import elements  # noqa: E402
from foldcore import patterns  # noqa: E402
from foldcore.hinges import DEFAULT_HINGE, neutral_length  # noqa: E402
from foldcore.outputs import write_result  # noqa: E402
from foldcore.simulation import Simulation  # noqa: E402
from foldcore.thickening import thicken  # noqa: E402

PANEL, DEPTH, H, W, K = 20.0, 10.0, 1.0, 2.0, 4  # mm, mm, mm, mm, count
TARGET, PROP = 90.0, 60.0  # degrees: hinge target, angle at which the bar is at rest


def far_edge_distance(angle_deg: float) -> float:
    """Distance (mm) between the panels' far top edges at fold angle ``angle_deg`` (valley).

    The hinge's neutral surface is an arc of angle φ and the length L its model
    gives it (:func:`foldcore.hinges.neutral_length`: W·(φ/2)/tan(φ/2) for the
    default axis hinge, W for the arc): its chord is c = 2(L/φ)·sin(φ/2), and
    each panel leaves a chord end at φ/2 to it. A far top edge lies ℓ = PANEL − W/2 along its panel and
    H/2 toward the fold's inside, so the distance is c + 2ℓ·cos(φ/2) − H·sin(φ/2).
    """
    phi = np.radians(angle_deg)
    chord = 2 * (float(neutral_length(DEFAULT_HINGE, W, H, phi)) / phi) * np.sin(phi / 2)
    return chord + 2 * (PANEL - W / 2) * np.cos(phi / 2) - H * np.sin(phi / 2)


def main(out="out") -> float:
    pattern = patterns.single_hinge(panel_length=PANEL, depth=DEPTH, angle=TARGET, width=W)
    mesh = thicken(pattern, H, subdivisions=K)
    rest = mesh.rest_positions
    far = [int(np.argmin(np.linalg.norm(rest - [x, 0.0, H / 2], axis=1))) for x in (-PANEL, PANEL)]
    hinge_weight = mesh.groups["bending_hinge"].weights.sum()
    mesh.groups["bar"] = bar_group([far], [far_edge_distance(PROP)], [100 * hinge_weight])
    sim = Simulation(mesh, pattern, solver="lbfgs")
    result = sim.run(tolerance=1e-10, max_iterations=20_000)
    angle = float(result.fold_angles_deg[0])
    print(f"element types: {elements.registered()}")
    print(f"hinge target {TARGET}°, bar at rest at {PROP}°: folded to {angle:.2f}° "
          f"in {result.iterations} iterations (converged: {result.converged})")
    folder = Path(out)
    folder.mkdir(parents=True, exist_ok=True)
    write_result(result, pattern, mesh, H, {"scene": "prop", "solver": "lbfgs"},
                 fold=folder / "prop.fold", report=folder / "prop.json")
    return angle


if __name__ == "__main__":
    main(*sys.argv[1:])
