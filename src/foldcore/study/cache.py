"""Finished points on disk, so an interrupted or repeated study computes only what is missing.

One JSON file per finished row (and its result FOLD, when kept) in the cache
folder, named by a key that hashes everything the row depends on: the
foldcore version, the pattern's bytes (or the generator's code), the point,
the fold percents its continuation path ran before it, and the metric's code.
The client writes each row as it arrives, so a study on a remote cluster
caches on the machine that runs it. Default folder:
``$XDG_CACHE_HOME/foldcore/study`` (``~/.cache/foldcore/study``).
"""
from __future__ import annotations

import hashlib
import json
import math
import os
from pathlib import Path


def default_folder() -> Path:
    base = os.environ.get("XDG_CACHE_HOME") or Path.home() / ".cache"
    return Path(base) / "foldcore" / "study"


def point_key(source_key: str, point: dict, before: list, metric=None) -> str:
    """The cache key of a point whose path folded ``before`` (fold percents) first."""
    from .. import __version__

    identity = {"version": __version__, "source": source_key, "point": point,
                "before": before, "metric": None if metric is None else code_identity(metric)}
    text = json.dumps(identity, sort_keys=True, default=str)
    return hashlib.sha256(text.encode()).hexdigest()[:32]


def code_identity(function) -> str:
    """A hash of what a function (or callable object) computes with: its code with its
    constants and nested functions (``marshal``), its defaults, and an object's
    state and its class's methods. Another constant or default is another key;
    a name alone is not."""
    import marshal

    parts = []
    callables = [function]
    if not hasattr(function, "__code__"):  # an object: its class's methods and its state
        callables = [v for v in vars(type(function)).values() if hasattr(v, "__code__")]
        parts.append(repr(sorted(getattr(function, "__dict__", {}).items(), key=str)))
    for f in callables:
        parts += [marshal.dumps(f.__code__).hex(), repr(getattr(f, "__defaults__", None)),
                  repr(getattr(f, "__kwdefaults__", None))]
    parts.append(getattr(function, "__qualname__", type(function).__qualname__))
    return hashlib.sha256("\0".join(parts).encode()).hexdigest()


class Cache:
    """Rows by key in ``folder`` (None: no cache; nothing read or written)."""

    def __init__(self, folder=None):
        self.folder = None if folder is None else Path(folder)

    @classmethod
    def at(cls, cache) -> "Cache":
        """The cache a study's ``cache`` argument names: ``"default"``
        (:func:`default_folder`), a folder, or None (no cache)."""
        return cls(default_folder() if cache == "default" else cache)

    def get(self, key: str):
        """(row, result FOLD bytes or None), or None if the key is not cached."""
        if self.folder is None:
            return None
        path = self.folder / f"{key}.json"
        try:
            row = json.loads(path.read_text())
        except (OSError, ValueError):
            return None
        fold = self.folder / f"{key}.fold"
        return row, fold.read_bytes() if fold.is_file() else None

    def put(self, key: str, row: dict, fold: bytes | None = None) -> None:
        """Store a finished row (atomically: a study killed while writing leaves no
        half file)."""
        from ..files import atomic_write

        if self.folder is None:
            return
        self.folder.mkdir(parents=True, exist_ok=True)
        if fold is not None:
            with atomic_write(self.folder / f"{key}.fold", binary=True) as fh:
                fh.write(fold)
        with atomic_write(self.folder / f"{key}.json") as fh:
            json.dump({k: _jsonable(v) for k, v in row.items()}, fh)


def _jsonable(value):
    if isinstance(value, float) and not math.isfinite(value):
        return None if math.isnan(value) else str(value)
    if hasattr(value, "item"):  # numpy scalars
        return value.item()
    return value
