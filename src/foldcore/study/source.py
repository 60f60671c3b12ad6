"""What a study folds: a pattern file (shipped to each worker once) or a generator.

A :class:`PatternFile` carries the file's bytes (and its hinge file's, for
OBJ/STL), so a worker on another machine needs no shared disk: it writes them
once into a folder of its own and folds that copy under the same name. A
:class:`Generator` builds the pattern from a point's parameters on the worker
(:data:`GENERATORS`: the built-in ones by name, or any function returning a
:class:`foldcore.CreasePattern`).
"""
from __future__ import annotations

import hashlib
import inspect
import os
import tempfile
from dataclasses import dataclass, field
from pathlib import Path

from .points import StudyError

#: Built-in generators a study can sweep by name (:mod:`foldcore.patterns`).
GENERATORS = ("miura", "miura_one_crease", "waterbomb", "degree4_vertex", "single_vertex",
              "grid", "single_hinge", "panel_row", "gripper")


@dataclass(frozen=True)
class PatternFile:
    """A pattern file's name and bytes (and its hinge file's, if any)."""

    name: str
    data: bytes = field(repr=False)
    hinges: bytes | None = field(default=None, repr=False)

    @classmethod
    def read(cls, path, hinges=None) -> "PatternFile":
        """Read ``path`` (and its hinge file: ``hinges``, else PATH.hinges for OBJ/STL)
        as every reader reads a file (:func:`foldcore.io.fold.read_bytes`: a regular
        file within the size limit)."""
        from ..io import MESH_SUFFIXES
        from ..io.fold import read_bytes
        from ..io.obj import HINGE_SUFFIX

        name = os.fspath(path)
        if hinges is None and Path(name).suffix.lower() in MESH_SUFFIXES:
            guess = Path(name).with_suffix(HINGE_SUFFIX)
            hinges = guess if guess.is_file() else None
        return cls(name, read_bytes(name),
                   None if hinges is None else read_bytes(os.fspath(hinges)))

    @property
    def label(self) -> str:
        return self.name

    @property
    def parameters(self) -> tuple:
        return ()

    def key(self) -> str:
        """A hash of the bytes: the cache's key for the pattern."""
        return hashlib.sha256(self.data + b"\0" + (self.hinges or b"")).hexdigest()

    def materialise(self, params: dict) -> tuple[str, str | None]:
        """(path, hinge path) of this worker's copy, written on first use."""
        folder = _worker_folder() / self.key()[:16]
        path = folder / Path(self.name).name
        from ..io.obj import HINGE_SUFFIX

        hinge_path = path.with_suffix(HINGE_SUFFIX) if self.hinges is not None else None
        if not path.exists():
            folder.mkdir(parents=True, exist_ok=True)
            if hinge_path is not None:
                hinge_path.write_bytes(self.hinges)
            path.write_bytes(self.data)
        return str(path), None if hinge_path is None else str(hinge_path)


@dataclass(frozen=True)
class Generator:
    """A pattern built from a point's parameters by ``function(**parameters)``."""

    function: object
    name: str

    @classmethod
    def named(cls, name: str) -> "Generator":
        """A built-in generator of :mod:`foldcore.patterns` (``-`` read as ``_``)."""
        from .. import patterns

        key = name.replace("-", "_")
        if key not in GENERATORS:
            raise StudyError(f"{name}: not a pattern file or a generator (generators: "
                             f"{', '.join(GENERATORS)})")
        return cls(getattr(patterns, key), key)

    @property
    def label(self) -> str:
        return self.name

    @property
    def parameters(self) -> tuple:
        """The generator's keyword parameters as the study names them."""
        return tuple(p.replace("_", "-") for p in inspect.signature(self.function).parameters)

    def key(self) -> str:
        """A hash of the generator's name and code (constants and defaults included)."""
        from .cache import code_identity

        return hashlib.sha256(f"{self.name}\0{code_identity(self.function)}".encode()) \
            .hexdigest()

    def materialise(self, params: dict) -> tuple[str, str | None]:
        """(path, None) of a FOLD file of the pattern the parameters make. A pattern
        without a target angle is written without ``edges_foldAngle``, so its M/V
        creases fold to ±180° × the fold percent, as such a file's do."""
        import json

        import numpy as np

        from ..files import write_text
        from ..io.fold_write import fold_dict

        kwargs = {k.replace("-", "_"): v for k, v in params.items()}
        try:
            pattern = self.function(**kwargs)
        except (TypeError, ValueError) as exc:
            raise StudyError(f"{self.name}({_args(params)}): {exc}") from None
        digest = hashlib.sha256(json.dumps(params, sort_keys=True, default=str)
                                .encode()).hexdigest()[:12]
        path = _worker_folder() / f"{self.name}-{digest}.fold"
        if not path.exists():
            d = fold_dict(pattern)
            if not np.isfinite(pattern.fold_angles).any():
                del d["edges_foldAngle"]
            write_text(path, json.dumps(d, allow_nan=False))
        return str(path), None


def _args(params: dict) -> str:
    return ", ".join(f"{k}={v!r}" for k, v in params.items())


def source_of(pattern, hinges=None):
    """A :class:`PatternFile` for a path to a file, a :class:`Generator` for a built-in
    generator's name or a function."""
    if callable(pattern):
        return Generator(pattern, getattr(pattern, "__name__", "generator"))
    text = os.fspath(pattern)
    if not os.path.exists(text) and text.replace("-", "_") in GENERATORS:
        return Generator.named(text)
    if not os.path.exists(text):
        raise StudyError(f"{text}: no such file, and not a generator (generators: "
                         f"{', '.join(GENERATORS)})")
    return PatternFile.read(text, hinges)


_FOLDER: list = []


def _worker_folder() -> Path:
    """This process's folder for the patterns it folds (removed when it exits)."""
    if not _FOLDER:
        import atexit
        import shutil

        _FOLDER.append(Path(tempfile.mkdtemp(prefix="foldcore-study-")))
        atexit.register(shutil.rmtree, _FOLDER[0], ignore_errors=True)
    return _FOLDER[0]
