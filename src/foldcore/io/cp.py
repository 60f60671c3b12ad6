"""Read ``.cp`` crease patterns: the line format of ORIPA, Oriedita and flat-folder.

One line per segment, ``TYPE X1 Y1 X2 Y2`` (whitespace separated, numbers in
the file's units: ORIPA draws a 400-unit sheet):

====  ==========  ==========================================================
TYPE  line        foldcore
====  ==========  ==========================================================
1     border      ``B``
2     mountain    ``M``, folds to −180° × the fold percent
3     valley      ``V``, folds to +180° × the fold percent
0, 4  auxiliary   not a crease (a drawing aid): left out, said once with a count
====  ==========  ==========================================================

The format holds no angles: its mountains and valleys fold as an SVG's fully
opaque ones, or a FOLD file's without ``edges_foldAngle`` (Origami Simulator's
convention). Lengths: one file unit is 1 mm unless ``Reading.scale`` or
``Reading.size`` says otherwise; coordinates as written (x right, y up).
Segments are noded as an SVG's are (:mod:`.lines`), merging points within
1e-6 of the sheet's extent (the format's coordinates are computed, not drawn).
A line that is not five numbers, a type outside 0–4, a coordinate that is not
finite or beyond ±1e9, or a zero-length segment is refused naming its line;
files over :data:`foldcore.io.MAX_FILE_BYTES` or :data:`MAX_LINES` lines are
refused.
"""
from __future__ import annotations

import math
import os

import numpy as np

from ..errors import PatternError
from ..pattern import CreasePattern
from .conventions import Reading, drive_only, note
from .lines import check_meetings, pattern_from_lines

#: TYPE → (assignment, target angle in degrees); None: an auxiliary line.
TYPES = {1: ("B", math.nan), 2: ("M", -180.0), 3: ("V", 180.0), 0: None, 4: None}
#: Merge distance, a share of the sheet's larger extent.
MERGE = 1e-6
#: Largest |coordinate| accepted.
MAX_COORD = 1e9
#: Most lines in one file (as many as an SVG's segments).
MAX_LINES = 200_000


def read_cp(path, reading: Reading | None = None) -> CreasePattern:
    """Read a ``.cp`` crease pattern (module docstring); lengths mm, angles degrees.

    Raises
    ------
    PatternError
        A malformed line (named), no crease, conflicting types on one segment, or
        a malformed pattern (named as :class:`CreasePattern` names it).
    """
    source = os.fspath(path)
    return pattern_of_typed_lines(_lines(source), source, reading)


def pattern_of_typed_lines(lines, source: str, reading: Reading | None) -> CreasePattern:
    """The pattern of ORIPA's typed lines (``lines``: (S, 2, 2) segments, assignments,
    targets, names), noded with :data:`MERGE` and scaled by ``reading``."""
    segments, kinds, angles, owners = lines
    reading = Reading() if reading is None else reading
    if not len(segments):
        raise PatternError(f"{source}: no border, mountain or valley line (types 1, 2, 3)")
    check_meetings(segments, source)
    extent = float(np.ptp(segments.reshape(-1, 2), axis=0).max())
    return drive_only(pattern_from_lines(segments, kinds, angles, owners, source,
                                         tol=MERGE * extent, factor=reading.factor(extent)),
                      reading.drive, source)


def _lines(source: str):
    """(S, 2, 2) segments, their assignments, targets and ``line N`` names."""
    from .fold import read_bytes

    try:  # (the size limit of every reader, checked before the file is read)
        text = read_bytes(source).decode("utf-8-sig")
    except UnicodeDecodeError:
        raise PatternError(f"{source}: not a text file (a .cp file is lines of "
                           "TYPE X1 Y1 X2 Y2)") from None
    numbered = ((number, line) for number, line in enumerate(text.splitlines(), start=1)
                if line.strip())
    return typed_lines((_parse(line, number, source) + (f"line {number}",)
                        for number, line in numbered), source)


def typed_lines(parsed, source: str):
    """(segments, assignments, targets, names) of ``parsed`` (TYPES entry, (2, 2)
    segment, name) triples, the auxiliary lines left out (said once with a count);
    more than :data:`MAX_LINES` refused."""
    segments, kinds, angles, owners, auxiliary = [], [], [], [], 0
    for kind, segment, name in parsed:
        if len(segments) + auxiliary >= MAX_LINES:
            raise PatternError(f"{source}: more than {MAX_LINES} lines")
        if kind is None:
            auxiliary += 1
            continue
        segments.append(segment)
        kinds.append(kind[0])
        angles.append(kind[1])
        owners.append(name)
    if auxiliary:
        note(source, f"{auxiliary} auxiliary lines (types 0 and 4) are not creases: "
                     "left out")
    return (np.array(segments, dtype=np.float64).reshape(-1, 2, 2), kinds, angles, owners)


def _parse(text: str, number: int, source: str):
    """(TYPES entry, (2, 2) segment) of one line; PatternError naming it otherwise."""
    fields = text.split()
    where = f"{source}: line {number}"
    if len(fields) != 5:
        raise PatternError(f"{where}: expected TYPE X1 Y1 X2 Y2, got {len(fields)} fields")
    try:
        kind = int(fields[0])
        values = [float(v) for v in fields[1:]]
    except ValueError:
        raise PatternError(f"{where}: expected an integer type and four numbers, got "
                           f"{' '.join(fields)[:80]!r}") from None
    return checked_line(kind, values, where)


def checked_line(kind: int, values, where: str):
    """(TYPES entry, (2, 2) segment) of a line of ``kind`` from (x1, y1, x2, y2)
    ``values``; PatternError starting with ``where`` if either is out of range."""
    if kind not in TYPES:
        raise PatternError(f"{where}: type {kind} is not 1 (border), 2 (mountain), "
                           "3 (valley) or 0/4 (auxiliary)")
    if not all(math.isfinite(v) and abs(v) <= MAX_COORD for v in values):
        raise PatternError(f"{where}: coordinates must be finite numbers within "
                           f"±{MAX_COORD:g}")
    segment = np.array(values).reshape(2, 2)
    if TYPES[kind] is not None and np.array_equal(segment[0], segment[1]):
        raise PatternError(f"{where}: a segment of zero length")
    return TYPES[kind], segment
