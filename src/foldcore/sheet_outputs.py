"""What a thin-sheet fold writes: the result FOLD, the JSON report, the PNG, a series.

The result FOLD is the crease pattern (its ``edges_foldAngle`` the achieved
angles) with one ``foldedForm`` frame: the pattern's vertices where the sheet
put them (mm) and the sheet's triangles, each naming the pattern face it cuts
(``foldcore:faces_face``). The file says ``"foldcore:model": "sheet"`` and has
no ``foldcore:thickness``. A series is the same with one frame per fold
percent of the sweep, each with the keys of a thick sheet's series frame
(:func:`foldcore.outputs.series_entries`). The data files are written all or
nothing, the picture after them (:func:`foldcore.outputs.write_picture`).
"""
from __future__ import annotations

from dataclasses import asdict

import numpy as np

from .io.fold_json import MODEL_KEY
from .outputs import (FACE_PART_KEY, PARTIAL_KEY, actuation_entries, in_fold_range,
                      machine_entries, nullable, series_entries, write_picture, write_report)

MODEL = "sheet"


def sheet_frame(sheet, positions: np.ndarray) -> dict:
    """FOLD frame of the folded sheet: 3D coordinates (mm), triangles, the face of each."""
    return {"frame_classes": ["foldedForm"], "frame_attributes": ["3D"],
            "frame_unit": "mm", "frame_parent": 0, "frame_inherit": False,
            "vertices_coords": np.asarray(positions).tolist(),
            "faces_vertices": sheet.pattern_triangles.tolist(),
            FACE_PART_KEY: sheet.triangle_face.tolist()}


def sheet_report(fold, pattern, sheet, settings: dict) -> dict:
    """The JSON report of a thin-sheet fold: verdict, angles and misses (degrees,
    valley > 0), the sheet's make-up, its stiffnesses (Origami Simulator's
    conventions, normalised frame), timings (s) and the settings used."""
    facets = int(np.count_nonzero(sheet.hinge_edge < 0))
    sprung = sheet.hinge_elements >= 0
    return {
        "model": MODEL,
        "iterations": int(fold.iterations),
        "converged": bool(fold.converged),
        "reason": fold.reason,
        "residual": float(fold.residual),
        "residual_unit": "largest force imbalance at a node / the forces meeting there",
        "energy": float(fold.energy),
        "fold_angles_deg": nullable(fold.fold_angles_deg),
        "target_angles_deg": nullable(fold.target_angles_deg),
        "actuation": actuation_entries(fold, pattern),
        "sheet": {"vertices": int(len(sheet.flat)), "merged_vertices": int(len(sheet.merged)),
                  "triangles": int(len(sheet.triangles)),
                  "creases": int(np.count_nonzero(sprung & (sheet.hinge_edge >= 0))),
                  "facet_hinges": facets,
                  "free_hinges": int(np.count_nonzero(~sprung)),
                  "sliver_corners": int(fold.sliver_corners),
                  "radius_mm": float(sheet.radius),
                  "stiffness": asdict(sheet.constants)},
        "contact": fold.contact,
        "timings_s": {k: float(v) for k, v in fold.timings_s.items()},
        "settings": settings,
        "machine": machine_entries(),
    }


def write_sheet_result(fold, pattern, sheet, settings: dict, *, fold_path=None, report=None,
                       png=None, partial: bool = False, series=None, sweep=None) -> None:
    """Write the outputs asked for (module docstring); None skips one.

    ``partial``: the run was interrupted, said in both files as the thick
    sheet's outputs say it (:func:`foldcore.outputs.write_result`). ``series``:
    with ``sweep`` (a list of (fold percent, SheetFold), in order), the series FOLD.
    """
    from .files import all_or_nothing
    from .io import write_fold

    with all_or_nothing({"fold": fold_path, "report": report, "series": series}) as tmp:
        if series:
            write_fold(tmp["series"], pattern,
                       achieved_angles=in_fold_range(fold.fold_angles_deg),
                       frames=[{**sheet_frame(sheet, r.positions), **series_entries(r, p)}
                               for p, r in sweep], extra={MODEL_KEY: MODEL})
        if fold_path:
            extra = {MODEL_KEY: MODEL, **({PARTIAL_KEY: True} if partial else {})}
            write_fold(tmp["fold"], pattern, achieved_angles=in_fold_range(fold.fold_angles_deg),
                       frames=[sheet_frame(sheet, fold.positions)], extra=extra)
        if report:
            write_report(tmp["report"], {**sheet_report(fold, pattern, sheet, settings),
                                         **({"partial": True} if partial else {})})
    if png:
        from .sheet_render import render_sheet_png

        write_picture(png, lambda path: render_sheet_png(pattern, sheet.pattern_triangles,
                                                         fold.positions, path),
                      written=[p for p in (fold_path, report, series) if p])

