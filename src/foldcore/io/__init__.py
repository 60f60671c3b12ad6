"""Crease-pattern files: FOLD (the ecosystem's format), SVG in Origami Simulator's
colours, and the paper's OBJ/STL + hinge file. Lengths are mm, angles degrees
(valley positive) once read; :func:`read_file` chooses the reader.

>>> pattern = read("bird.fold")                      # doctest: +SKIP
>>> pattern = read("sheet.obj", hinges="sheet.hinges")  # doctest: +SKIP
"""
from __future__ import annotations

import os
from pathlib import Path

from ..errors import PatternError
from ..files import check_input
from ..pattern import CreasePattern
from .conventions import Reading, drive_only
from .fold import MAX_FILE_BYTES, FoldFile, pattern_from_fold_dict, read_fold, read_fold_file
from .fold_write import fold_dict, write_fold
from .obj import mesh_edges, read_mesh, write_hinges, write_obj

__all__ = ["MAX_FILE_BYTES", "FoldFile", "Reading", "fold_dict", "mesh_edges",
           "pattern_from_fold_dict", "read", "read_file", "read_fold", "read_fold_file",
           "read_mesh", "write_fold", "write_hinges", "write_obj"]

MESH_SUFFIXES = (".obj", ".stl")


def read(path, *, hinges=None, reading: Reading | None = None) -> CreasePattern:
    """Read a crease pattern, choosing the reader by the file suffix (:func:`read_file`).

    Returns
    -------
    CreasePattern
        Lengths in mm, angles in degrees. For a FOLD file's
        ``foldcore:thickness`` and other file-level values use :func:`read_file`.
    """
    return read_file(path, hinges=hinges, reading=reading).pattern


#: What each suffix without a hinge file is, for messages.
_KINDS = {".fold": "a FOLD file", ".svg": "an SVG", ".cp": "a .cp file",
          ".opx": "an ORIPA .opx file"}
#: Suffixes of the crease-pattern files read without a hinge file.
_PATTERNS = tuple(_KINDS)


def read_file(path, *, hinges=None, reading: Reading | None = None) -> FoldFile:
    """Read a crease-pattern file of any kind: the one place that dispatches on the suffix.

    Parameters
    ----------
    path : str or os.PathLike
        ``.fold`` (FOLD JSON), ``.svg`` (Origami Simulator's colours,
        :mod:`.svg`), ``.cp`` (ORIPA's lines, :mod:`.cp`), ``.opx`` (ORIPA's
        own files, :mod:`.opx`), or ``.obj`` / ``.stl``
        (2D polygon mesh, mm).
    hinges : str or os.PathLike, optional
        Hinge file of a mesh; default: the mesh path with suffix ``.hinges``.
        Only with an OBJ/STL mesh.
    reading : Reading, optional
        How the file is read (conventions, scaling; :mod:`.conventions`); an
        OBJ/STL mesh is read in mm, so it takes no ``scale`` or ``size``.

    Returns
    -------
    FoldFile
        The pattern (lengths mm, angles degrees) and, for a FOLD file, its
        thickness, unit, stiffness factors and hinge models (None otherwise;
        ``frame_unit`` "mm" for SVG and meshes, whose lengths are mm once read).

    Raises
    ------
    PatternError
        Unknown suffix, a hinge file or a scale given where it does not apply,
        a missing file or one that is not a regular file (a named pipe, a
        device, a folder: refused before it is opened), or any malformed input.
    """
    source = os.fspath(path)
    suffix = Path(source).suffix.lower()
    reading = Reading() if reading is None else reading
    if suffix in _PATTERNS and hinges is not None:
        raise PatternError(f"{source}: a hinge file only goes with an OBJ/STL mesh, "
                           f"not {_KINDS[suffix]}")
    check_input(source, PatternError)  # before it is opened: a named pipe blocks a read
    if hinges is not None and suffix in MESH_SUFFIXES:
        check_input(hinges, PatternError)
    if suffix == ".fold":
        return read_fold_file(source, reading)
    if suffix == ".svg":
        from .svg import read_svg  # svgelements only when an SVG is read
        pattern, drawn = read_svg(source, reading, with_drawn=True)
        return FoldFile(pattern, None, "mm", drawing=drawn)
    if suffix == ".cp":
        from .cp import read_cp
        return FoldFile(read_cp(source, reading), None, "mm")
    if suffix == ".opx":
        from .opx import read_opx
        return FoldFile(read_opx(source, reading), None, "mm")
    if suffix in MESH_SUFFIXES:
        if reading.scale is not None or reading.size is not None:
            raise PatternError(f"{source}: a scale or sheet size applies to FOLD and SVG "
                               "patterns; an OBJ/STL mesh is read in mm")
        return FoldFile(drive_only(read_mesh(source, hinges), reading.drive, source), None,
                        "mm")
    raise PatternError(f"{source}: unknown crease-pattern file type {suffix or '(no suffix)'!r}"
                       " (expected .fold, .svg, .cp, .opx, .obj or .stl)")
