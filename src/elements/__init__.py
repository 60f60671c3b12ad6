"""Element types: one module each, registered by class definition.

An element type is a small module holding

* a pure ``@njit`` kernel that maps one element's current positions to its
  rotated target shape, writing only its own rows;
* a module-level ``@njit(parallel=True, cache=True)`` batch loop with the
  signature ``batch(x, indptr, indices, rest, params, out, energy, state)``;
* a subclass of :class:`ElementType` naming the kernel and its metadata;
* optionally, a ``prepare`` / ``prepared_batch`` pair for targets that partly
  depend on parameters only (computed once per change, not per iteration).

Defining the subclass registers it. Third-party packages can also register
types through the ``foldcore.elements`` entry-point group (loaded lazily, on the
first lookup of an unknown name). See ``docs/adding-an-element-type.md``.

Importing the package first drops numba cache files compiled from other
sources than the current ones (:mod:`elements.cache`: numba keys a kernel on
its own file only, not on the helpers it calls), after making sure numba has a writable cache
folder (a read-only install without a writable home falls back to another
folder, or to no cache, with one :class:`foldcore.errors.KernelCacheWarning`).
"""
from pathlib import Path as _Path

import numba as _numba

from .cache import choose_cache_dir as _choose_cache_dir
from .cache import drop_stale_kernels as _drop_stale_kernels

_choose_cache_dir(_Path(__file__))  # before any cache=True decorator (read-only installs)
_drop_stale_kernels(_Path(__file__).parent, _numba.__version__)

from ._registry import ElementType, available, get, registered  # noqa: E402

__all__ = ["ElementType", "available", "get", "registered"]
