"""Outputs of a run: the JSON report and the folded thick solid as a FOLD frame.

Reads a Result (and the mesh/pattern it came from); never drives the solver.
"""
from __future__ import annotations

import json
import platform

import numpy as np

from .io.fold_json import CELLS_KEY, HINGE_KEY, POISSON_KEY
from .mesh import surface_polygons

#: Keys of a folded frame naming each face's part: the crease-pattern face of a panel
#: (or elastic cell) face, the crease of a hinge-strip face; null for the other kind.
FACE_PART_KEY = "foldcore:faces_face"
EDGE_PART_KEY = "foldcore:faces_edge"
#: FOLD key marking a result written from an interrupted run's last iterate.
PARTIAL_KEY = "foldcore:partial"
#: Keys of a series frame: its fold percent, and per key-frame edge the achieved
#: angle and the effective target (degrees).
SERIES_PERCENT_KEY = "foldcore:fold_percent"
SERIES_ANGLE_KEY = "foldcore:pattern_foldAngle"
SERIES_TARGET_KEY = "foldcore:pattern_targetAngle"


def folded_frame(mesh, positions: np.ndarray) -> dict:
    """FOLD frame of the folded thick solid: 3D coordinates (mm), surface faces, and
    the part each face belongs to (``foldcore:faces_face``: the crease-pattern face
    of a panel face, ``foldcore:faces_edge``: the crease of a hinge-strip face;
    null for the other kind and for faces of no pattern item), so the solid can be
    checked part by part."""
    surface = surface_polygons(mesh)
    known = surface.source >= 0
    return {"frame_classes": ["foldedForm"], "frame_attributes": ["3D"],
            "frame_unit": "mm", "frame_parent": 0, "frame_inherit": False,
            "vertices_coords": np.asarray(positions).tolist(),
            "faces_vertices": [f.tolist() for f in surface.loops],
            FACE_PART_KEY: _items(surface.source, known & ~surface.is_hinge),
            EDGE_PART_KEY: _items(surface.source, known & surface.is_hinge)}


def _items(ids: np.ndarray, where: np.ndarray) -> list:
    """``ids`` as a JSON list of ints, null where ``where`` is False."""
    return [int(i) if w else None for i, w in zip(ids.tolist(), where.tolist())]


def series_frame(mesh, result, percent: float) -> dict:
    """One frame of a fold-percent series: the folded solid (as :func:`folded_frame`)
    and :func:`series_entries`."""
    return {**folded_frame(mesh, result.positions), **series_entries(result, percent)}


def series_entries(result, percent: float) -> dict:
    """A series frame's keys besides its folded form: its title and fold percent,
    per edge of the key frame's crease pattern the achieved angles (within FOLD's
    [−180°, 180°]) and the effective targets (degrees, null = passive), and the
    frame's verdict (``result``: a thick sheet's Result or a thin one's SheetFold)."""
    targets = result.target_angles_deg
    return {"frame_title": f"fold percent {percent:g}", SERIES_PERCENT_KEY: percent,
            SERIES_ANGLE_KEY: nullable(in_fold_range(result.fold_angles_deg)),
            SERIES_TARGET_KEY: None if targets is None else nullable(targets),
            "foldcore:converged": bool(result.converged),
            "foldcore:reason": result.reason,
            "foldcore:iterations": int(result.iterations)}


def in_fold_range(angles) -> np.ndarray:
    """Achieved angles (degrees) as a FOLD file holds them: within [−180°, 180°] (a
    crease past flat on its assigned side, −180.54°, is written −180°)."""
    return np.clip(angles, -180.0, 180.0)


def nullable(values) -> list:
    """Floats as a JSON list, None where not finite."""
    return [float(v) if np.isfinite(v) else None for v in np.asarray(values, dtype=float)]


def _strain_entries(result) -> dict:
    """Sub-strip surface strains (top, bottom; dimensionless) and hinge failures."""
    if result.strip_strains is None:
        return {}
    return {"strip_strains": {"top": result.strip_strains[:, 0].tolist(),
                              "bottom": result.strip_strains[:, 1].tolist()},
            "failures": result.failures}


def _iteration_cost(result) -> dict:
    """Mean strategy time per iteration (s) and its ratio to one bare K⁻¹ solve."""
    t = result.timings_s
    if not result.iterations or "bare_solve" not in t:
        return {}
    per_iteration = (t["projection"] + t["solve"]) / result.iterations
    return {"per_iteration_s": per_iteration,
            "per_iteration_vs_bare_solve": per_iteration / t["bare_solve"]
            if t["bare_solve"] > 0 else None}


#: Degrees by which a converged run's driven creases may miss their targets before it
#: is said to bind (its targets unreachable in this model) rather than to have folded.
MISS_WARNING_DEG = 1.0
#: Why targets bind, per model (:func:`run_summary`).
BINDING = {"rigid": "(with rigid panels: a pattern that is not rigidly foldable; "
                    "thickening.elastic_cells lets the panels bend)",
           "elastic": "(with elastic panels: meeting them needs the faces to stretch, or "
                      "hinge stiffness factors above the panels')",
           "sheet": "(in a thin sheet the creases are springs that the facets' bending "
                    "resists: a pattern that is not rigidly foldable, or targets that "
                    "are not compatible at this fold percent)"}


def run_summary(result, pattern, source: str, fold_percent: float,
                model: str = "rigid") -> tuple[str, list[str]]:
    """The one-line summary of a run (verdict, iterations, time, the driven creases'
    miss) and the warnings it calls for: nothing driven, or converged with targets
    missed by more than :data:`MISS_WARNING_DEG`, saying why in the terms of the
    ``model`` (:data:`BINDING`: ``rigid`` or ``elastic`` panels, thin ``sheet``)."""
    entries = actuation_entries(result, pattern)
    driven, worst = len(entries["creases"]), entries["largest_miss_deg"]
    verdict = "converged" if result.converged else f"not converged ({result.reason})"
    seconds = result.timings_s.get("total", float("nan"))
    line = (f"foldcore: {source}: {verdict} after {result.iterations} iterations in "
            f"{seconds:.3g} s; {driven} driven creases at fold percent {fold_percent:g}")
    if driven:
        line += f", miss max {worst:.3g}°, median {entries['median_miss_deg']:.3g}°"
    warns = []
    if not driven and not getattr(result, "position_targets", None):
        warns.append(f"{source}: no crease is driven (no target angles): the sheet stays "
                     "as it is; give edges_foldAngle, or M/V creases without angles "
                     "(and not reading.mv_without_angle='passive')")
    if entries["contact_blocked"]:
        blocked = entries["contact_blocked"]
        gap = result.contact["smallest_gap_mm"]
        near = (f"smallest gap {gap:.3g} mm" if gap is not None else
                "the next step would make two of them cross")
        warns.append(f"{source}: contact stops {len(blocked)} of {driven} driven creases short "
                     f"of their targets (edges {', '.join(map(str, blocked[:10]))}"
                     + (", …" if len(blocked) > 10 else "") + "): their panels or hinge "
                     f"strips touch others ({near}); the report's contact section "
                     "lists the touching parts and their forces")
    held = [t for t in (getattr(result, "position_targets", None) or [])
            if t["stopped_by"] == "contact"]
    if held:
        warns.append(f"{source}: contact holds {len(held)} position target"
                     + ("s" if len(held) > 1 else "") + " back ("
                     + ", ".join(f"{t['name']} by {t['miss_mm']:.3g} mm" for t in held[:5])
                     + (", …" if len(held) > 5 else "") + "): parts touch on the way; "
                     "the report's contact section lists them and their forces")
    if driven and entries["binding"]:
        missed, wrong = entries["missed"] - len(entries["contact_blocked"]), entries["wrong_side"]
        warns.append(f"{source}: converged, but {missed} of {driven} driven creases miss "
                     f"their targets by more than {MISS_WARNING_DEG:g}° (up to {worst:.3g}°"
                     + (f"; {wrong} folded to the other side" if wrong else "") + "): "
                     "the model binds there — these targets cannot all be met at once "
                     + BINDING[model] + "; the report's actuation lists each crease "
                     "(docs/guide/strategies.md#reached-or-binding)")
    return line, warns


def actuation_entries(result, pattern) -> dict:
    """Per actuated crease: effective target, achieved angle and miss (degrees); the
    largest and median miss, how many miss by more than :data:`MISS_WARNING_DEG`, how
    many ended on the other side of flat than their target (``wrong_side``, by more
    than that), and ``binding``: converged with some missed (the targets unreachable
    in this model)."""
    from .measure import wrapped_deg

    targets = result.target_angles_deg if result.target_angles_deg is not None \
        else np.array(pattern.fold_angles, dtype=float)
    driven = np.flatnonzero(np.isfinite(targets))
    miss = wrapped_deg(result.fold_angles_deg[driven] - targets[driven])
    is_missed = np.abs(miss) > MISS_WARNING_DEG
    contact = getattr(result, "contact", None) or {}
    touching = set(contact.get("touching_faces", []))
    strips = set(contact.get("touching_creases", []))
    by_contact = np.array([bool(touching & set(int(f) for f in pattern.edge_faces[e] if f >= 0))
                           or int(e) in strips for e in driven],
                          dtype=bool) & is_missed & bool(result.converged)
    stopped = np.where(by_contact, "contact",
                       np.where(is_missed & bool(result.converged), "binding", None))
    creases = [{"edge": int(e), "target_deg": float(t), "achieved_deg": float(a),
                "miss_deg": float(m), "stopped_by": s}
               for e, t, a, m, s in zip(driven, targets[driven],
                                        result.fold_angles_deg[driven], miss, stopped)]
    worst = float(np.abs(miss).max()) if len(miss) else 0.0
    missed = int(np.count_nonzero(is_missed))
    wrong = np.sign(targets[driven]) * result.fold_angles_deg[driven] < -MISS_WARNING_DEG
    return {"creases": creases, "largest_miss_deg": worst,
            "median_miss_deg": float(np.median(np.abs(miss))) if len(miss) else 0.0,
            "missed": missed, "miss_tolerance_deg": MISS_WARNING_DEG,
            "wrong_side": int(np.count_nonzero(wrong)),
            "contact_blocked": driven[by_contact].tolist(),
            "binding": bool(result.converged and missed > int(by_contact.sum()))}


def hinge_entries(result, pattern, mesh) -> dict:
    """Where the hinge model's idealisation breaks, with numbers: creases past the
    axis hinge's pivot angle (binding there), the panels' largest interpenetration
    at a crease (mm), the strips' largest misfit to their model shape (mm) and the
    largest surface strain (dimensionless)."""
    from .hinges import pivot_angle_deg
    from .measure import crease_overlaps

    models = mesh.hinge_model if mesh.hinge_model is not None else np.full(pattern.n_edges, "")
    angles = np.abs(result.fold_angles_deg)
    pivot = np.where(models == "axis", pivot_angle_deg(mesh.hinge_width, mesh.thickness),
                     np.nan)
    pivoting = np.flatnonzero(np.nan_to_num(angles - pivot, nan=-1.0) > 0)
    overlap = crease_overlaps(pattern, mesh, result.positions)
    out = {"model": [str(m) if m else None for m in models],
           "pivot_angle_deg": nullable(pivot), "pivoting_edges": pivoting.tolist(),
           "largest_overlap_mm": float(np.nanmax(overlap, initial=0.0)),
           "overlap_mm": nullable(overlap)}
    misfit = result.hinge_misfit_mm
    if misfit is not None and len(misfit):
        worst = int(np.argmax(misfit))
        out.update(largest_misfit_mm=float(misfit[worst]),
                   largest_misfit_edge=int(mesh.groups["bending_hinge"].source[worst]))
    if result.strip_strains is not None and len(result.strip_strains):
        out["largest_strip_strain"] = float(np.abs(result.strip_strains).max())
    return out


def report_dict(result, pattern, mesh, settings: dict, quantities: dict | None = None) -> dict:
    """The JSON report of a run, plus the settings used.

    Angles in degrees (valley > 0), lengths mm, times seconds. ``quantities``
    (a scene's own measurements) go under the key ``quantities``.
    """
    energy = result.energy
    return {
        "iterations": int(result.iterations),
        "converged": bool(result.converged),
        "reason": result.reason,
        "residual": float(result.residual) if np.isfinite(result.residual) else None,
        "energy": float(energy[-1]) if len(energy) else 0.0,
        "energy_history": energy.tolist(),
        "fold_angles_deg": nullable(result.fold_angles_deg),
        "target_angles_deg": nullable(result.target_angles_deg
                                       if result.target_angles_deg is not None
                                       else pattern.fold_angles),
        "actuation": actuation_entries(result, pattern),
        "hinges": hinge_entries(result, pattern, mesh),
        **({"contact": result.contact} if result.contact is not None else {}),
        **({"position_targets": result.position_targets}
           if getattr(result, "position_targets", None) else {}),
        "strip_angles_deg": result.strip_angles_deg.tolist(),
        **_strain_entries(result),
        "vertices": int(mesh.n_vertices),
        "elements": {name: len(g) for name, g in mesh.groups.items()},
        "hinge_width_mm": nullable(mesh.hinge_width),
        **_narrowed_entries(mesh),
        "subdivisions": mesh.subdivisions.tolist(),
        "timings_s": {k: float(v) for k, v in result.timings_s.items()},
        **_iteration_cost(result),
        "settings": settings,
        **({"quantities": quantities} if quantities else {}),
        "machine": machine_entries(),
    }


def _narrowed_entries(mesh) -> dict:
    """The hinges narrowed to fit small faces, each with the share of Eq. 7's width it
    kept (nothing when none was)."""
    share = getattr(mesh, "width_share", None)
    if share is None:
        return {}
    return {"narrowed_hinges": [{"edge": int(e), "width_mm": float(mesh.hinge_width[e]),
                                 "share_of_eq7": float(share[e])}
                                for e in np.flatnonzero(share < 1.0)]}


def machine_entries() -> dict:
    """What a report records of the software that ran it."""
    import numba

    from .linsolve import cholmod_available

    return {"python": platform.python_version(), "numba": numba.__version__,
            "numba_threads": numba.get_num_threads(), "cholmod": cholmod_available()}


def write_report(path, report: dict) -> None:
    """Write the report as indented JSON, atomically."""
    from .files import atomic_write

    with atomic_write(path) as fh:
        json.dump(report, fh, indent=1, allow_nan=False)
        fh.write("\n")


def _mesh_recipe(pattern, mesh) -> dict | None:
    """FOLD keys that let a reader rebuild a mesh thicken() cannot guess: the elastic
    faces' cell counts (``foldcore:faces_cells``, null for a rigid panel), the
    stretch hinges' Poisson ratios (``foldcore:edges_poisson``, null elsewhere)
    and the hinge model of every crease (``foldcore:edges_hinge``, null on
    boundary edges)."""
    from elements.stretch_hinge import STRETCH_PARAMS

    recipe = {}
    if mesh.hinge_model is not None:
        recipe[HINGE_KEY] = [str(m) if m else None for m in mesh.hinge_model]
    if mesh.elastic:
        cells = [None] * len(pattern.faces)
        for f, n in mesh.elastic.items():
            cells[f] = list(n) if isinstance(n, tuple) else int(n)
        recipe[CELLS_KEY] = cells
    stretch = mesh.groups.get("stretch_hinge")
    if stretch is not None and len(stretch):
        nu = [None] * pattern.n_edges
        for e, row in zip(stretch.source, stretch.params):
            nu[int(e)] = float(row[STRETCH_PARAMS.index("poisson")])
        recipe[POISSON_KEY] = nu
    return recipe or None


def write_result(result, pattern, mesh, thickness: float, settings: dict, *, fold=None,
                 report=None, png=None, quantities: dict | None = None,
                 partial: bool = False, series=None, sweep=None, picture=None) -> None:
    """Write the outputs asked for: FOLD (achieved angles + folded solid), JSON report, PNG.

    Parameters
    ----------
    result : Result
    pattern, mesh : the CreasePattern and ThickMesh the result came from
    thickness : float, mm (stored as ``foldcore:thickness`` in the FOLD file)
    settings : dict, recorded in the report
    fold, report, png : path or None
        None skips it (and, for ``png``, the pyvista import). The FOLD file's
        ``edges_foldAngle`` holds the achieved angles within FOLD's [−180°, 180°]
        (a crease folded past flat on its assigned side, e.g. −180.54°, is written
        −180°; the report keeps the measured value). The data files (FOLD,
        report, series) are written all or nothing: each to a temporary name
        first, renamed only when all are written
        (:func:`foldcore.files.all_or_nothing`). The PNG comes after them, on
        its own: a picture the renderer cannot make raises an OutputError naming
        it, with the data files written.
    quantities : dict, optional
        A scene's own measurements, stored in the report.
    partial : bool
        The run was interrupted: the FOLD file gets ``"foldcore:partial": true``
        and the report ``"partial": true`` (its ``reason`` is the Result's).
    picture : (H, W, 3) uint8, optional
        Written as the PNG instead of a render of ``result`` (a scene's gallery).
    series : path, optional
        With ``sweep`` (a list of (fold percent, Result), in order): one FOLD file
        whose key frame is the crease pattern with the last frame's achieved
        angles and whose ``file_frames`` are :func:`series_frame` of each (the
        last is what ``foldcore render`` draws).
    """
    from .files import all_or_nothing

    with all_or_nothing({"fold": fold, "report": report, "series": series}) as tmp:
        if series:
            from .io import write_fold
            write_fold(tmp["series"], pattern,
                       achieved_angles=in_fold_range(result.fold_angles_deg),
                       frames=[series_frame(mesh, r, p) for p, r in sweep],
                       thickness=thickness, extra=_mesh_recipe(pattern, mesh))
        if fold:
            from .io import write_fold
            extra = {**(_mesh_recipe(pattern, mesh) or {}),
                     **({PARTIAL_KEY: True} if partial else {})}
            write_fold(tmp["fold"], pattern,
                       achieved_angles=in_fold_range(result.fold_angles_deg),
                       frames=[folded_frame(mesh, result.positions)], thickness=thickness,
                       extra=extra or None)
        if report:
            write_report(tmp["report"], {**report_dict(result, pattern, mesh, settings,
                                                       quantities),
                                         **({"partial": True} if partial else {})})
    if png:
        write_picture(png, lambda path: _picture(path, pattern, mesh, result, picture),
                      written=[p for p in (fold, report, series) if p])


def _picture(png, pattern, mesh, result, picture) -> None:
    """``picture`` written as the PNG, or a render of ``result``."""
    if picture is not None:
        import imageio.v3 as iio

        from .files import atomic_path
        with atomic_path(png) as tmp:
            iio.imwrite(tmp, picture, extension=".png")
    else:
        from .render import render_png
        render_png(pattern, mesh, result.positions, png)


def write_picture(png, draw, written: list) -> None:
    """``draw(png)`` after the data files; an OutputError naming the PNG, and the
    files already written, if it fails (a run's result is not lost to its picture)."""
    from .files import OutputError

    try:
        draw(png)
    except Exception as exc:  # whatever the renderer raised: said, the data kept
        reason = " ".join(str(exc).split())[:300] or type(exc).__name__
        raise OutputError(f"{png}: the picture was not written ({reason})"
                          + (f"; the other outputs were: {', '.join(map(str, written))}"
                             if written else "")) from None
