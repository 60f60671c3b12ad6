"""Crease-pattern files: FOLD (the ecosystem's format), SVG in Origami Simulator's
colours, and the paper's OBJ/STL + hinge file. Lengths are mm, angles degrees (valley positive) once read.

>>> pattern = read("bird.fold")                      # doctest: +SKIP
>>> pattern = read("sheet.obj", hinges="sheet.hinges")  # doctest: +SKIP
"""
from __future__ import annotations

import os
from pathlib import Path

from ..errors import PatternError
from ..pattern import CreasePattern
from .conventions import Reading
from .fold import (MAX_FILE_BYTES, FoldFile, fold_dict, pattern_from_fold_dict, read_fold,
                   read_fold_file, write_fold)
from .obj import mesh_edges, read_mesh, write_hinges, write_obj

__all__ = ["MAX_FILE_BYTES", "FoldFile", "Reading", "fold_dict", "mesh_edges", "pattern_from_fold_dict",
           "read", "read_fold", "read_fold_file", "read_mesh", "write_fold", "write_hinges",
           "write_obj"]

MESH_SUFFIXES = (".obj", ".stl")


def read(path, *, hinges=None, reading: Reading | None = None) -> CreasePattern:
    """Read a crease pattern, choosing the reader by the file suffix.

    Parameters
    ----------
    path : str or os.PathLike
        ``.fold`` (FOLD JSON), ``.svg`` (Origami Simulator's colours,
        :mod:`.svg`), or ``.obj`` / ``.stl`` (2D polygon mesh, mm).
    hinges : str or os.PathLike, optional
        Hinge file of a mesh; default: the mesh path with suffix ``.hinges``.
        Not allowed with ``.fold``.
    reading : Reading, optional
        How a FOLD file is read (conventions, scaling; :mod:`.conventions`).

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
        return read_fold(source, reading)
    if suffix == ".svg":
        from .svg import read_svg  # svgelements only when an SVG is read
        if hinges is not None:
            raise PatternError(f"{source}: a hinge file only goes with an OBJ/STL mesh, "
                               "not an SVG")
        return read_svg(source, reading)
    if suffix in MESH_SUFFIXES:
        return read_mesh(source, hinges)
    raise PatternError(f"{source}: unknown crease-pattern file type {suffix or '(no suffix)'!r}"
                       " (expected .fold, .svg, .obj or .stl)")
