"""Iteration strategies: one module (or package) each, behind one small protocol.

A :class:`foldcore.Simulation` holds the model (:class:`foldcore.model.Model`:
geometry, element groups, actuation, pins and the positions ``model.x``) and
hands it to one strategy, which only moves the state and reports each step
to the run's convergence test (:mod:`foldcore.convergence`). Built in:

* ``paper`` — the paper's local/global map (:mod:`.paper`).
* ``anderson`` — the same map with safeguarded Anderson acceleration.
* ``lbfgs`` — L-BFGS on the local/global energy, K as initial Hessian.
* ``rigid`` — rigid panels as rigid bodies, Levenberg–Marquardt with geodesic
  acceleration (:mod:`.rigid`, a package holding its engine).
* ``newton`` — Gauss–Newton / Levenberg–Marquardt on every vertex, each step
  corrected by the paper's map: for elastic cells.
* ``hybrid`` — the default, a composite: ``rigid`` steps first, ending there
  when they settle, else ``newton`` (``lbfgs`` on meshes it refuses) from
  where they stop (:mod:`.hybrid`).

A user strategy is a subclass in any module (registered by class definition,
like element types): `docs/adding-a-strategy.md`. The names below are
importable without numba or SciPy, for the command line.
"""
from __future__ import annotations

from .base import SOLVERS, NoOptions, Strategy, available, get, unregister

#: The default strategy: ``hybrid``. Why: `docs/architecture.md#the-default-strategy`.
DEFAULT_SOLVER = "hybrid"

__all__ = ["DEFAULT_SOLVER", "NoOptions", "SOLVERS", "Strategy", "available", "get",
           "unregister"]
