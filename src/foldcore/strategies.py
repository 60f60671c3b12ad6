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

#: The default strategy (bench/convergence, README table). No strategy is fast
#: on every benchmark scene; ``lbfgs`` minimises the paper's own energy, so it
#: reaches the paper's equilibria, and on every scene it is at least as
#: accurate as ``paper`` at a fraction of the iterations (hinge Lp/H = 5: 31 vs
#: 10 280; Lp/H ≥ 20: converged where ``paper`` never gets there; the thin
#: waterbomb is slow: 0.011° after 40 000); it works with every element type. ``rigid`` is
#: faster where it applies (rigid panels and bending hinges only) but its
#: one-arc passive hinge is a different model whose equilibria differ on
#: passive loops (thick Miura 5×5: 49.7° from the closed form against 9.4°).
DEFAULT_SOLVER = "lbfgs"
