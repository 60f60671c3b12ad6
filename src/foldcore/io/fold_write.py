"""Write crease patterns and results as FOLD files (JSON, FOLD spec 1.2, lengths in mm).

The keys read back by :mod:`.fold` (foldcore's own keys: :mod:`.fold_json`);
every file is written atomically (:mod:`foldcore.files`).
"""
from __future__ import annotations

import json
from functools import partial

import numpy as np

from .. import files
from ..pattern import CreasePattern
from .fold_json import MAX_ANGLE_KEY, TARGET_KEY, THICKNESS_KEY, WIDTH_KEY


def fold_dict(pattern: CreasePattern, achieved_angles=None, frames=None,
              thickness: float | None = None, extra: dict | None = None) -> dict:
    """The FOLD object (a dict ready for JSON) of a crease pattern or result.

    Parameters
    ----------
    pattern : CreasePattern
    achieved_angles : (E,) array_like of float, optional
        Fold angles reached, degrees, valley positive; NaN → null. When given
        they fill ``edges_foldAngle`` and the targets go to
        ``foldcore:edges_targetAngle``.
    frames : sequence of dict, optional
        Extra frames (e.g. the folded thick solid), written as ``file_frames``
        unchanged (NumPy arrays are converted when written).
    thickness : float, optional
        Sheet thickness, mm (``foldcore:thickness``).
    extra : dict, optional
        More top-level keys (use a ``foldcore:`` prefix); they win on clashes.
    """
    d = {"file_spec": 1.2, "file_creator": "foldcore", "file_classes": ["singleModel"],
         "frame_classes": ["creasePattern"], "frame_attributes": ["2D"], "frame_unit": "mm",
         "vertices_coords": pattern.vertices.tolist(),
         "edges_vertices": pattern.edges.tolist(),
         "edges_assignment": pattern.assignments.tolist(),
         "faces_vertices": [f.tolist() for f in pattern.faces],
         "edges_foldAngle": _nullable(pattern.fold_angles),
         WIDTH_KEY: _nullable(pattern.widths), MAX_ANGLE_KEY: pattern.max_angles.tolist()}
    if achieved_angles is not None:
        achieved = np.asarray(achieved_angles, dtype=np.float64)
        if achieved.shape != (pattern.n_edges,):
            raise ValueError(f"achieved_angles has shape {achieved.shape}, "
                             f"expected ({pattern.n_edges},)")
        d[TARGET_KEY], d["edges_foldAngle"] = d["edges_foldAngle"], _nullable(achieved)
    if thickness is not None:
        d[THICKNESS_KEY] = float(thickness)
    if frames is not None:
        d["file_frames"] = list(frames)
    d.update(extra or {})
    return d


def write_fold(path, pattern: CreasePattern, achieved_angles=None, frames=None,
               thickness: float | None = None, extra: dict | None = None) -> None:
    """Write :func:`fold_dict` to ``path`` atomically (no partial file on error).

    Floats keep full precision (shortest round-trip repr), so reading the file
    back gives the same pattern bit for bit. One top-level key per line.
    """
    d = fold_dict(pattern, achieved_angles, frames, thickness, extra)
    dumps = partial(json.dumps, allow_nan=False, default=_jsonable)
    with files.atomic_write(path) as fh:
        fh.write("{\n")
        for i, (key, value) in enumerate(d.items()):
            fh.write(f"  {json.dumps(key)}: {dumps(value)}{',' if i < len(d) - 1 else ''}\n")
        fh.write("}\n")


def _nullable(values: np.ndarray) -> list:
    return [float(x) if np.isfinite(x) else None for x in values]


def _jsonable(obj):
    if isinstance(obj, np.ndarray):
        return obj.tolist()
    if isinstance(obj, np.generic):
        return obj.item()
    raise TypeError(f"{type(obj).__name__} is not JSON serialisable")
