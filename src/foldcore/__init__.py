"""foldcore: geometry-based simulation of thick origami.

Data flow: pattern → thick mesh → system → simulation → result → outputs::

    import foldcore
    pattern = foldcore.patterns.single_hinge(panel_length=5, angle=90)
    mesh = foldcore.thicken(pattern, thickness=1.0, hinge_width=2.0, subdivisions=4)
    sim = foldcore.Simulation(mesh, pattern)
    result = sim.run(tolerance=1e-9)
    result.fold_angles_deg[0]          # ≈ 90 (degrees, valley > 0)

    # or from a file, as the command line does (foldcore.job):
    result = foldcore.simulate("crane.fold", reading={"size": 200},
                               thickening={"thickness": 0.5},
                               solving={"fold_percent": 30},
                               outputs={"fold": "crane-30.fold"})

Units: mm and degrees at every public API. Submodules are imported lazily so
that ``import foldcore`` is fast and never imports numba kernels or pyvista.
"""
import logging
import os
from importlib import import_module

# Before anything loads GNU OpenMP (numba's "omp" threading layer, CHOLMOD
# through scikit-sparse): idle OpenMP threads sleep instead of spinning, so a
# parallel step on a shared machine does not wait a time slice for a thread a
# spinning sibling displaced (bench/load.py measures it; see foldcore.threads).
# A value the user set is kept; libgomp reads it once, when it loads.
os.environ.setdefault("OMP_WAIT_POLICY", "PASSIVE")

from .errors import (FoldcoreError, KernelCacheWarning, MeshError, PatternError, PatternWarning,
                     RunWarning, SimulationError)

__version__ = "0.1.0"

# The library logs through the "foldcore" logger and says nothing unless asked
# (``foldcore -v``, or a handler of the application's own).
logging.getLogger(__name__).addHandler(logging.NullHandler())

_LAZY = {
    "CreasePattern": ("foldcore.pattern", "CreasePattern"),
    "thicken": ("foldcore.thickening", "thicken"),
    "ThickMesh": ("foldcore.mesh", "ThickMesh"),
    "Simulation": ("foldcore.simulation", "Simulation"),
    "Result": ("foldcore.result", "Result"),
    "Model": ("foldcore.model", "Model"),
    "read": ("foldcore.io", "read"),
    "simulate": ("foldcore.job", "simulate"),
    "Reading": ("foldcore.io", "Reading"),
    "write_fold": ("foldcore.io", "write_fold"),
    "patterns": ("foldcore.patterns", None),
    "kinematics": ("foldcore.kinematics", None),
}

__all__ = ["FoldcoreError", "KernelCacheWarning", "MeshError", "PatternError", "PatternWarning",
           "RunWarning", "SimulationError", *_LAZY]


def __getattr__(name):
    if name not in _LAZY:
        raise AttributeError(f"module 'foldcore' has no attribute {name!r}")
    module, attr = _LAZY[name]
    value = import_module(module)
    value = value if attr is None else getattr(value, attr)
    globals()[name] = value
    return value
