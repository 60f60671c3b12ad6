"""Registry of element types (no numba import here: it stays cheap)."""
from __future__ import annotations

import importlib
import warnings
from importlib.metadata import entry_points

_REGISTRY: dict[str, type] = {}
_BUILTIN_MODULES = {"rigid_panel": "elements.rigid_panel",
                    "bending_hinge": "elements.bending_hinge",
                    "stretch_hinge": "elements.stretch_hinge"}
ENTRY_POINT_GROUP = "foldcore.elements"


class ElementType:
    """Base class of element types; subclasses register themselves by ``name``.

    Class attributes
    ----------------
    name : str
        Registry key, also the ElementGroup ``kind``.
    params : tuple of str
        Names of the per-element parameter columns.
    state : tuple of str
        Names of the per-element state columns the batch loop writes
        (e.g. the bend angle a hinge used), possibly empty.
    batch : callable
        The numba batch loop ``batch(x, indptr, indices, rest, params, out,
        energy, state)``; see the package docstring.
    prepare, prepared_batch : callable or None
        Optional pair, for types whose targets partly depend on parameters
        only (an actuated hinge's bent shape): ``prepare(indptr, rest,
        params, shapes)`` writes those elements' target shapes (local frame,
        centred) into their rows of ``shapes`` (nnz, 3); the engine calls it
        once per change of ``params`` and then, every iteration,
        ``prepared_batch(x, indptr, indices, rest, shapes, params, out,
        energy, state)`` instead of ``batch``, which must give what ``batch``
        gives. Both or neither.
    """

    name: str = ""
    params: tuple = ()
    state: tuple = ()
    batch = None
    prepare = None
    prepared_batch = None

    def __init_subclass__(cls, **kwargs):
        super().__init_subclass__(**kwargs)
        if not cls.name:
            raise TypeError(f"{cls.__qualname__} must set a non-empty `name`")
        if (cls.prepare is None) != (cls.prepared_batch is None):
            raise TypeError(f"{cls.__qualname__} must set both `prepare` and "
                            "`prepared_batch`, or neither")
        old = _REGISTRY.get(cls.name)
        if old is not None and old is not cls:
            warnings.warn(f"element type {cls.name!r} from {cls.__module__} replaces the "
                          f"one from {old.__module__}", RuntimeWarning, stacklevel=2)
        _REGISTRY[cls.name] = cls

    @classmethod
    def origin(cls) -> str:
        """Module the type was defined in."""
        return cls.__module__


def registered() -> dict[str, str]:
    """Names of the types registered so far, mapped to their defining module."""
    return {name: cls.origin() for name, cls in _REGISTRY.items()}


def available() -> list[str]:
    """Every type that can be looked up: built-in, registered, entry points."""
    names = set(_REGISTRY) | set(_BUILTIN_MODULES)
    names |= {ep.name for ep in entry_points(group=ENTRY_POINT_GROUP)}
    return sorted(names)


def get(name: str) -> type:
    """Element type by name, importing its module on first use.

    Raises
    ------
    KeyError
        If no built-in, registered or entry-point type has that name.
    """
    if name not in _REGISTRY and name in _BUILTIN_MODULES:
        importlib.import_module(_BUILTIN_MODULES[name])
    if name not in _REGISTRY:
        for ep in entry_points(group=ENTRY_POINT_GROUP):
            if ep.name == name:
                ep.load()
    try:
        return _REGISTRY[name]
    except KeyError:
        raise KeyError(f"unknown element type {name!r}; available: "
                       f"{', '.join(available())}") from None
