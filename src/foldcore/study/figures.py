"""A study row's figures of one fold: what ``foldcore simulate`` reports, flattened.

Every figure is a number, a bool or a short string, so a row is one line of a
CSV file. Units: mm, degrees, seconds; strains dimensionless.
"""
from __future__ import annotations

import math

import numpy as np

#: The figures' columns, in the table's order, after the point's own names.
FIGURES = ("converged", "reason", "iterations", "wall_s", "run_s", "setup_s",
           "miss_max_deg", "miss_median_deg", "driven", "binding", "residual",
           "largest_strain", "fractured", "contact_pairs",
           "smallest_gap_mm", "touching_panels", "bbox_x_mm", "bbox_y_mm", "bbox_z_mm",
           "stack_height_mm")
#: The table's columns after the metric's.
TRAILING = ("start", "worker", "cached", "result_fold", "warnings", "error")
#: Columns a study adds beside those (a metric may not use their names either).
RESERVED = ("metric", "metric_error", "trial", "objective", "feasible")


def figures(result, pattern, mesh) -> dict:
    """The figures of ``result`` (:class:`foldcore.Result`) folded from ``pattern`` on
    ``mesh``.

    Returns
    -------
    dict
        ``converged``, ``reason``, ``iterations``, ``residual``; ``setup_s`` (the
        model's set-up: K assembled and factorised); ``miss_max_deg``,
        ``miss_median_deg`` (driven creases' |achieved − target|, as the
        report's actuation), ``driven``, ``binding``; ``largest_strain``
        (sub-strips' largest |surface strain|, NaN without hinges),
        ``fractured`` (hinges past their strain limits); ``contact_pairs``,
        ``smallest_gap_mm``, ``touching_panels`` (NaN with contact off); and the
        folded solid's ``bbox_x_mm``, ``bbox_y_mm``, ``bbox_z_mm`` and
        ``stack_height_mm`` (its least extent along its principal axes: the
        stack's height when folded flat).
    """
    from ..outputs import actuation_entries

    act = actuation_entries(result, pattern)
    timings = result.timings_s
    strains = result.strip_strains
    row = {"converged": bool(result.converged), "reason": result.reason,
           "iterations": int(result.iterations), "residual": _number(result.residual),
           "setup_s": timings.get("setup", math.nan),
           "miss_max_deg": act["largest_miss_deg"], "miss_median_deg": act["median_miss_deg"],
           "driven": len(act["creases"]), "binding": act["binding"],
           "largest_strain": float(np.abs(strains).max()) if strains is not None
           and len(strains) else math.nan,
           "fractured": len(result.failures)}
    row.update(_contact(result.contact))
    row.update(extents(result.positions))
    return row


def _number(value) -> float:
    value = float(value)
    return value if math.isfinite(value) else math.nan


def _contact(contact: dict | None) -> dict:
    if contact is None:
        return {"contact_pairs": math.nan, "smallest_gap_mm": math.nan,
                "touching_panels": math.nan}
    gap = contact.get("smallest_gap_mm")
    return {"contact_pairs": len(contact.get("active_pairs", [])),
            "smallest_gap_mm": math.nan if gap is None else float(gap),
            "touching_panels": len(contact.get("touching_faces", []))}


def extents(positions: np.ndarray) -> dict:
    """Bounding box of the solid in the pattern's frame and its least principal extent
    (mm), of (N, 3) vertex positions."""
    span = positions.max(axis=0) - positions.min(axis=0)
    centred = positions - positions.mean(axis=0)
    _, _, axes = np.linalg.svd(centred, full_matrices=False)
    along = centred @ axes.T
    principal = along.max(axis=0) - along.min(axis=0)
    return {"bbox_x_mm": float(span[0]), "bbox_y_mm": float(span[1]),
            "bbox_z_mm": float(span[2]), "stack_height_mm": float(principal.min())}
