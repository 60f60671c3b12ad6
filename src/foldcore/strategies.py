"""Names of the iteration strategies (kept free of heavy imports for the CLI).

* ``paper`` — the paper's local/global map (:class:`foldcore.simulation.Simulation`).
* ``rigid`` — rigid panels as rigid bodies, Levenberg–Marquardt with geodesic
  acceleration (:mod:`foldcore.rigid_body`).
"""
SOLVERS = ("paper", "rigid")
