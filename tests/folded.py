"""Small folded test scenes shared by the render and fabrication tests."""
from __future__ import annotations

from functools import lru_cache

from foldcore import patterns


@lru_cache(maxsize=None)
def scene(name: str):
    """(pattern, mesh, result) of a test scene, folded with the rigid strategy.

    ``"hinge"``: one hinge at 90°, panels 5 × 4 mm, k = 4; ``"d4"``: a degree-4
    vertex (R = 20 mm, widths 4/1/2/1 mm) with crease 1 at 90°. H = 1 mm.
    """
    from foldcore.simulation import Simulation
    from foldcore.thickening import thicken

    if name == "hinge":
        pattern = patterns.single_hinge(panel_length=5.0, depth=4.0, angle=90.0, width=2.0)
        mesh = thicken(pattern, 1.0, subdivisions=4)
    elif name == "d4":
        pattern = patterns.degree4_vertex(radius=20.0, widths=(4.0, 1.0, 2.0, 1.0), rho1=90.0)
        mesh = thicken(pattern, 1.0)
    else:
        raise KeyError(name)
    result = Simulation(mesh, pattern, solver="rigid").run(tolerance=1e-10,
                                                           max_iterations=200)
    assert result.converged
    return pattern, mesh, result


def result_fold(folder):
    """The folded d4 scene written to ``folder/d4.fold`` as ``simulate -o`` writes it."""
    from foldcore.outputs import write_result

    pattern, mesh, result = scene("d4")
    path = folder / "d4.fold"
    write_result(result, pattern, mesh, 1.0, {}, fold=path)
    return path
