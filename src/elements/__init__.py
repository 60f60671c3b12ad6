"""Element types: one module each, registered by class definition.

An element type is a small module holding

* a pure ``@njit`` kernel that maps one element's current positions to its
  rotated target shape, writing only its own rows;
* a module-level ``@njit(parallel=True, cache=True)`` batch loop with the
  signature ``batch(x, indptr, indices, rest, params, out, energy, state)``;
* a subclass of :class:`ElementType` naming the kernel and its metadata.

Defining the subclass registers it. Third-party packages can also register
types through the ``foldcore.elements`` entry-point group (loaded lazily, on the
first lookup of an unknown name). See ``docs/elements.md``.
"""
from ._registry import ElementType, available, get, registered

__all__ = ["ElementType", "available", "get", "registered"]
