"""Names of the iteration strategies (kept free of heavy imports for the CLI).

* ``paper`` — the paper's local/global map (:class:`foldcore.simulation.Simulation`).
* ``anderson`` — the same map with safeguarded Anderson acceleration
  (:mod:`foldcore.accelerated`).
* ``lbfgs`` — L-BFGS on the local/global energy, K as initial Hessian
  (:mod:`foldcore.accelerated`).
* ``rigid`` — rigid panels as rigid bodies, Levenberg–Marquardt with geodesic
  acceleration (:mod:`foldcore.rigid_body`).
* ``hybrid`` — each run starts with ``rigid`` steps (at most 200) and
  continues with ``lbfgs`` from where they stop, on the paper's energy; a mesh
  ``rigid`` cannot take (elastic cells, other element types) runs ``lbfgs``.
"""
SOLVERS = ("paper", "anderson", "lbfgs", "rigid", "hybrid")

#: The default strategy (bench/convergence, README table): ``hybrid``. Its
#: rigid phase brings long panels and closed loops to the rigid-body model's
#: state in a few iterations whatever the panel length (single hinge to 0.01°
#: in 3–8 iterations at Lp/H = 5–320 and the thin waterbomb in 34, where
#: ``lbfgs`` alone needs 31–1 980 and never in 20 000, ``paper`` 10 280 and
#: never), and its L-BFGS phase then settles
#: on the paper's own energy, so it ends at the paper model's equilibria
#: (passive creases: Eq. 9 per sub-strip), with every element type (meshes
#: the rigid phase cannot take run L-BFGS alone). On every benchmark scene
#: but one it is at least as close to the closed form as ``lbfgs`` and
#: ``paper``; on Pehrson's vertex driven flat both stop ~97° short, at
#: different equilibria of the thick model (hybrid 97.2°, lbfgs 96.8°). Cost:
#: a rigid step is a sparse Gauss–Newton solve, ~11–13 µs per thick vertex
#: (Miura 20×20, 7.8 k vertices: 85 ms in bench/convergence; 50×50, 49.6 k:
#: 0.62 s, profiled over 3 steps), so on
#: large meshes whose rigid phase needs many steps ``lbfgs`` can be quicker.
DEFAULT_SOLVER = "hybrid"
