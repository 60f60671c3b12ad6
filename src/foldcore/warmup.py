"""Compile the default path's kernels once, at set-up (``python -m foldcore.warmup``).

numba compiles a ``cache=True`` kernel on its first call and writes it next
to its source; every later process loads it. Without this step a user's
first ``foldcore simulate`` pays the compilation (tens of seconds:
docs/architecture.md#warm-up-at-set-up). The README's set-up (``make``) runs this
module once, so the first simulation starts warm.

What it folds — tiny scenes, each through the command line's defaults where
possible, so exactly the kernels the default path uses are compiled:

* a degree-4 vertex from flat with one crease driven (``hybrid``: the branch
  stage, the rigid-body phase, the prepared hinge kernels, the misfit
  report);
* the same vertex, a few ``lbfgs`` and ``paper`` steps (the local/global
  kernels the hybrid strategy falls back to, the paper map's solution take);
* a hinge with a bar of elastic cells (L-BFGS alone, the stops' check);
* where contact is installed (``ipctk``), the panel broad phase's kernels
  (:func:`foldcore.contact.kernels.compile_all`: a first run with contact
  would otherwise wait some 7 s for them).

Kernels the default path never calls (stretch hinges, the hinges'
unprepared ``batch``) are left to compile when a scene first needs them.
"""
from __future__ import annotations

import importlib.util
import sys
import time


def warm() -> dict:
    """Fold the warm-up scenes; returns {"seconds": …, "compiled": …, "loaded": …}."""
    import numba.core.registry  # noqa: F401  (numba itself, before timing)

    from . import patterns
    from .simulation import Simulation
    from .thickening import thicken

    start = time.perf_counter()
    vertex = patterns.degree4_vertex(radius=10.0, widths=[0.03] * 4, rho1=40.0)
    mesh = thicken(vertex, 0.01)
    Simulation(mesh, vertex).run(max_iterations=200)
    for solver in ("lbfgs", "paper"):
        Simulation(mesh, vertex, solver=solver).run(tolerance=0, max_iterations=3)
    bar = patterns.single_hinge(panel_length=10.0, depth=5.0, angle=60.0, width=2.0)
    cells = thicken(bar, 1.0, elastic={1: 2})
    Simulation(cells, bar).run(tolerance=0, max_iterations=3)
    if importlib.util.find_spec("ipctk") is not None:
        from .contact.kernels import compile_all

        compile_all()
    return {"seconds": time.perf_counter() - start, **_cache_counts()}


def _cache_counts() -> dict:
    """Kernels compiled (cache misses) and loaded (hits) in this process."""
    from numba.core.registry import CPUDispatcher

    compiled = loaded = 0
    for module in [m for name, m in sys.modules.items()
                   if name.startswith(("foldcore", "elements"))]:
        for value in vars(module).values():
            if isinstance(value, CPUDispatcher):
                compiled += sum(value.stats.cache_misses.values())
                loaded += sum(value.stats.cache_hits.values())
    return {"compiled": compiled, "loaded": loaded}


def main() -> int:
    counts = warm()
    how = (f"{counts['compiled']} kernel compilations" if counts["compiled"]
           else "all loaded from the cache")
    print(f"foldcore: kernels ready ({how}, {counts['seconds']:.1f} s)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
