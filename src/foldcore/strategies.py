"""Names of the iteration strategies (kept free of heavy imports for the CLI).

* ``paper`` — the paper's local/global map (:class:`foldcore.simulation.Simulation`).
* ``anderson`` — the same map with safeguarded Anderson acceleration
  (:mod:`foldcore.accelerated`).
* ``lbfgs`` — L-BFGS on the local/global energy, K as initial Hessian
  (:mod:`foldcore.accelerated`).
* ``rigid`` — rigid panels as rigid bodies, Levenberg–Marquardt with geodesic
  acceleration (:mod:`foldcore.rigid_body`).
"""
SOLVERS = ("paper", "anderson", "lbfgs", "rigid")
