"""Crease-pattern files: FOLD (the ecosystem's format) and the paper's OBJ/STL +
hinge file. Lengths are mm, angles degrees (valley positive) once read.

>>> pattern = read("bird.fold")                      # doctest: +SKIP
>>> pattern = read("sheet.obj", hinges="sheet.hinges")  # doctest: +SKIP
"""
from __future__ import annotations

import os
from pathlib import Path

from ..errors import PatternError
from ..pattern import CreasePattern
from .fold import (MAX_FILE_BYTES, FoldFile, fold_dict, pattern_from_fold_dict, read_fold,
                   read_fold_file, write_fold)
from .obj import mesh_edges, read_mesh, write_hinges, write_obj

__all__ = ["MAX_FILE_BYTES", "FoldFile", "fold_dict", "mesh_edges", "pattern_from_fold_dict",
           "read", "read_fold", "read_fold_file", "read_mesh", "write_fold", "write_hinges",
           "write_obj"]

MESH_SUFFIXES = (".obj", ".stl")


def read(path, *, hinges=None) -> CreasePattern:
    """Read a crease pattern, choosing the reader by the file suffix.

    Parameters
    ----------
    path : str or os.PathLike
        ``.fold`` (FOLD JSON), or ``.obj`` / ``.stl`` (2D polygon mesh, mm).
    hinges : str or os.PathLike, optional
        Hinge file of a mesh; default: the mesh path with suffix ``.hinges``.
        Not allowed with ``.fold``.

    Returns
    -------
    CreasePattern
        Lengths in mm, angles in degrees. For a FOLD file's
        ``foldcore:thickness`` use :func:`read_fold_file`.

    Raises
    ------
    PatternError
        Unknown suffix, missing hinge file, or any malformed input.
    """
    source = os.fspath(path)
    suffix = Path(source).suffix.lower()
    if suffix == ".fold":
        if hinges is not None:
            raise PatternError(f"{source}: a hinge file only goes with an OBJ/STL mesh, "
                               "not a FOLD file")
        return read_fold(source)
    if suffix in MESH_SUFFIXES:
        return read_mesh(source, hinges)
    raise PatternError(f"{source}: unknown crease-pattern file type {suffix or '(no suffix)'!r}"
                       " (expected .fold, .obj or .stl)")
