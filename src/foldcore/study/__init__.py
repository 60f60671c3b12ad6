"""Design studies: one pattern folded over a grid or list of option values, on Dask.

>>> from foldcore import study
>>> table = study.sweep("miura.fold", grid={"thickness": [0.1, 0.2],
...                                         "hinge-width": [0.3, 0.5, 0.7]})  # doctest: +SKIP

Each point is a ``foldcore simulate`` run of the same options (names as the
command line's flags without dashes; :mod:`.points`), or a fold of a built-in
generator's pattern with its parameters (:mod:`.source`). Points run on Dask
distributed (:mod:`.execute`: an embedded LocalCluster by default, or an existing
cluster); finished points are cached on disk (:mod:`.cache`), so a rerun folds
only what is missing. :func:`sweep` returns the table (pandas), :func:`write_table`
writes it as CSV or Parquet. :func:`optimize` searches ranges of the same names
for the point whose fold minimises (or maximises) a column of its row, with
Optuna (:mod:`.optimize`). Needs the ``study`` extra (dask, distributed, pandas,
optuna).
"""
from __future__ import annotations

from .points import OPTIONS, StudyError, grid, parse_set, read_points
from .optimize import Optimum, optimize
from .sweep import FIGURES, sweep
from .table import write_table

__all__ = ["OPTIONS", "FIGURES", "Optimum", "StudyError", "grid", "optimize", "parse_set",
           "read_points", "sweep", "write_table"]
