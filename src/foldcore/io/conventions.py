"""How crease patterns from the origami ecosystem are read: Origami Simulator's
conventions, and the options that turn them off.

Most public FOLD and SVG files are made for Origami Simulator (Ghassaei et
al. 2018), so foldcore reads them as it does (its ``js/importer.js`` and
``js/pattern.js``):

* **An M/V crease without an angle folds.** A FOLD file with no
  ``edges_foldAngle`` (and no ``foldcore:edges_targetAngle``) gets target
  angles from its assignments: ``M`` −180°, ``V`` +180°, ``F`` 0°, others
  passive; the fold percent scales them. :attr:`Reading.mv_without_angle`
  ``"passive"`` keeps foldcore's older meaning (every crease passive). Where
  the key is present, a ``null`` entry stays passive: the file said so.
* **A flat sheet in any plane** is rotated into z = 0 (Origami Simulator
  exports lie in its xz-plane). The normal is the one about which the faces
  run counter-clockwise (right-hand rule; without faces, the normal whose
  first non-zero component of (z, −y, x) is positive), so the faces' top
  side — the side valleys fold towards — stays on top.
* **A folded form** (``frame_classes`` ``foldedForm``, or coordinates off a
  plane) is read through its ``vertices_flatUnfoldCoords``; without them it is
  unfolded from its faces (:mod:`.unfold`), or refused with a message saying
  which keys would do. A key frame labelled a
  folded form whose ``file_frames`` hold a frame labelled ``creasePattern``
  (Rabbit Ear's files) is read from that frame (:func:`crease_pattern_frame`).
* **Lengths**: ``frame_unit`` as before; a FOLD file that declares no unit
  (``frame_unit`` absent or ``"unit"``: most are unit squares) is read
  :data:`~foldcore.limits.UNITLESS_SHEET_MM` across (said once); :attr:`Reading.scale`
  multiplies every length of the file (a unitless file's unit taken as mm),
  or :attr:`Reading.size` sets the sheet's larger extent in mm.
* **Angles against their assignment** are refused; :attr:`Reading.
  trust_assignment` gives them the assignment's sign instead (said once).
* **Driving some creases only**: :attr:`Reading.drive` lists the edges that
  keep their targets; every other M, V or U crease with a target is left
  passive (said once with the count). ``F`` edges keep theirs (0°: flat
  facets, not folds).

Every change is said once per file as a :class:`foldcore.errors.PatternWarning`
(the command line prints one line per kind).
"""
from __future__ import annotations

import math
import warnings
from dataclasses import dataclass

import numpy as np

from ..errors import PatternError, PatternWarning
from ..limits import MAX_DRIVEN, UNITLESS_SHEET_MM

#: Out-of-plane spread, relative to the sheet's extent, below which a 3D sheet is flat
#: (Origami Simulator's exports: coordinates printed to 6–17 digits).
PLANE_TOLERANCE = 1e-6
#: Target angle, degrees, of an assigned crease without one (Origami Simulator's).
ASSIGNED_ANGLE = {"M": -180.0, "V": 180.0, "F": 0.0}


@dataclass(frozen=True)
class Reading:
    """Options of reading a crease-pattern file (module docstring).

    Attributes
    ----------
    mv_without_angle : {"fold", "passive"}
        What an M/V crease of a file without angles does: fold to ±180° × the
        fold percent (Origami Simulator's convention, default) or stay passive.
    trust_assignment : bool
        An angle whose sign contradicts its M/V assignment takes the
        assignment's sign (default False: refused, naming the edge).
    scale : float or None
        Every length of the file (after ``frame_unit``) × this (dimensionless).
    size : float or None
        Alternatively, the sheet's larger extent in mm (the file's lengths are
        scaled to it).
    drive : tuple of int or None
        Edge ids (the pattern's, as read: a FOLD file's own order) of the
        creases that keep their target angles; every other crease with a
        target, ``F`` edges aside, is left passive. None (default) drives
        every crease with a target. Each id must be a crease with a target
        (:func:`drive_only`).
    """

    mv_without_angle: str = "fold"
    trust_assignment: bool = False
    scale: float | None = None
    size: float | None = None
    drive: tuple | None = None

    def __post_init__(self):
        if self.mv_without_angle not in ("fold", "passive"):
            raise ValueError(f"mv_without_angle must be 'fold' or 'passive', "
                             f"got {self.mv_without_angle!r}")
        if self.scale is not None and self.size is not None:
            raise ValueError("give scale or size, not both")
        for name in ("scale", "size"):
            value = getattr(self, name)
            if value is not None and not (value > 0 and math.isfinite(value)):
                raise ValueError(f"{name} must be a positive finite number, got {value!r}")
        if self.drive is not None:
            ids = tuple(self.drive) if isinstance(self.drive, (list, tuple)) else None
            if ids is not None and len(ids) > MAX_DRIVEN:
                raise ValueError(f"drive lists {len(ids):,} edge ids; at most {MAX_DRIVEN:,}")
            if not ids or not all(isinstance(e, (int, np.integer)) and not isinstance(e, bool)
                                  and e >= 0 for e in ids):
                raise ValueError(f"drive must be a non-empty list of edge ids (integers "
                                 f"≥ 0), got {self.drive!r}")
            object.__setattr__(self, "drive", tuple(int(e) for e in ids))

    def unitless_size(self, unit: str) -> float | None:
        """The sheet's larger extent, mm, that a file of ``unit`` gets by default:
        :data:`UNITLESS_SHEET_MM` when it declares no unit of length (``"unit"``) and
        neither a size nor a scale is given; else None."""
        given = self.size is not None or self.scale is not None
        return UNITLESS_SHEET_MM if unit == "unit" and not given else None

    def factor(self, extent_mm: float, default_size: float | None = None) -> float:
        """The factor every length is multiplied by, for a sheet ``extent_mm`` wide:
        to :attr:`size` (or ``default_size``, :meth:`unitless_size`) when there is
        one, else :attr:`scale` (default 1)."""
        size = self.size if self.size is not None else default_size
        if size is not None:
            return size / extent_mm if extent_mm > 0 else 1.0
        return 1.0 if self.scale is None else self.scale


#: Key suffixes of per-element arrays (a frame's geometry), with or without a prefix.
ELEMENT_KEYS = ("vertices_", "edges_", "faces_")


def crease_pattern_frame(d: dict, source: str) -> dict:
    """The FOLD object whose frame is the crease pattern: ``d`` itself, or, from its
    ``file_frames`` (said once, over the key frame's file-level keys — and over its
    geometry too where the frame inherits from it: ``frame_inherit`` with
    ``frame_parent`` 0 or absent):

    * when its key frame is labelled ``foldedForm`` without
      ``vertices_flatUnfoldCoords``, the frame labelled ``creasePattern``;
    * when its key frame holds no vertices at all, the frame labelled
      ``creasePattern``, else the first frame with ``vertices_coords``."""
    from .fold_json import ARRAY, has_class

    frames = d.get("file_frames")
    if not isinstance(frames, ARRAY):
        return d
    empty = d.get("vertices_coords") is None and d.get("vertices_flatUnfoldCoords") is None
    folded = has_class(d.get("frame_classes"), "foldedForm") and \
        d.get("vertices_flatUnfoldCoords") is None
    if not (empty or folded):
        return d
    found = [(i, f) for i, f in enumerate(frames) if isinstance(f, dict)
             and has_class(f.get("frame_classes"), "creasePattern")]
    if not found and empty:
        found = [(i, f) for i, f in enumerate(frames) if isinstance(f, dict)
                 and f.get("vertices_coords") is not None]
    if not found:
        return d
    i, frame = found[0]
    inherits = frame.get("frame_inherit") is True and frame.get("frame_parent", 0) == 0
    base = {k: v for k, v in d.items() if k not in ("file_frames", "frame_classes")
            and (inherits or not str(k).split(":")[-1].startswith(ELEMENT_KEYS))}
    why = "holds no vertices" if empty else "is a folded form"
    labelled = has_class(frame.get("frame_classes"), "creasePattern")
    label = "frame_classes: creasePattern" if labelled else "its first frame with vertices"
    note(source, f"the key frame {why}: the crease pattern is read from "
                 f"file_frames[{i}] ({label})")
    return {**base, **frame}


def note(source: str, message: str) -> None:
    """Say once that the file was read with a convention the user should know of."""
    warnings.warn(f"{source}: {message}", PatternWarning, stacklevel=3)


def assigned_angles(assignments, source: str, reading: Reading,
                    max_angles=None) -> list | None:
    """Target angles (degrees, None = passive) of a file without angles, or None to
    leave every crease passive (``max_angles``: per edge, degrees, None = 180; an
    M/V crease folds to its own largest angle where that is below 180°)."""
    if reading.mv_without_angle == "passive":
        return None
    kinds = np.asarray(assignments, dtype=object)
    mv = int(np.count_nonzero((kinds == "M") | (kinds == "V")))
    if not mv:
        return None
    note(source, f"no edges_foldAngle: {mv} M/V creases fold to ±180° × the fold percent "
                 "(Origami Simulator's convention; reading.mv_without_angle='passive' keeps them passive)")
    limits = [None] * len(assignments) if max_angles is None else max_angles
    return [None if a not in ASSIGNED_ANGLE else
            ASSIGNED_ANGLE[a] * min(180.0, 180.0 if m is None else m) / 180.0
            for a, m in zip(assignments, limits)]


def drive_only(pattern, drive, source: str):
    """``pattern`` with only the creases ``drive`` (edge ids) keeping their target
    angles, every other M, V or U crease left passive (said once); ``pattern``
    itself for ``drive`` None. PatternError naming the first id that is not an
    edge, is a boundary or cut, or has no target to drive."""
    if drive is None:
        return pattern
    kinds, angles = pattern.assignments, pattern.fold_angles
    for e in drive:
        if e >= pattern.n_edges:
            raise PatternError(f"{source}: cannot drive edge {e}: the pattern has "
                               f"{pattern.n_edges} edges (ids 0 … {pattern.n_edges - 1})")
        if kinds[e] in ("B", "C"):
            raise PatternError(f"{source}: cannot drive edge {e}: it is a "
                               f"{'boundary' if kinds[e] == 'B' else 'cut'} edge, not a crease")
        if math.isnan(angles[e]):
            raise PatternError(f"{source}: cannot drive edge {e}: it has no target angle "
                               "(passive in the file); give it one in the file")
    keep = np.zeros(pattern.n_edges, dtype=bool)
    keep[list(drive)] = True
    released = ~keep & ~np.isnan(angles) & (kinds != "F")
    if not released.any():
        return pattern
    count = int(released.sum())
    note(source, f"{count} crease{'s' if count != 1 else ''} with a target left passive: "
                 f"only the {len(set(drive))} given in reading.drive are driven")
    return pattern.replace(fold_angles=np.where(released, np.nan, angles))


def trust_signs(angles: list, assignments, source: str) -> list:
    """``angles`` with every sign that contradicts its M/V assignment flipped (said)."""
    flipped = 0
    out = list(angles)
    for e, (angle, kind) in enumerate(zip(angles, assignments)):
        if angle is not None and (kind == "M" and angle > 0 or kind == "V" and angle < 0):
            out[e] = -angle
            flipped += 1
    if flipped:
        note(source, f"{flipped} fold angles took their assignment's sign "
                     "(reading.trust_assignment=True)")
    return out


@dataclass(frozen=True)
class PlaneFit:
    """The plane nearest points (V, 3): its unit ``normal``, the largest distance of a
    point from it (``spread``) and the points' ``extent`` (same units)."""

    normal: np.ndarray
    spread: float
    extent: float

    @classmethod
    def of(cls, xyz: np.ndarray) -> "PlaneFit":
        centre = xyz.mean(axis=0)
        _, _, rows = np.linalg.svd(xyz - centre, full_matrices=False)
        return cls(rows[2], float(np.abs((xyz - centre) @ rows[2]).max()),
                   float(np.ptp(xyz, axis=0).max()))

    @property
    def flat(self) -> bool:
        """Whether the points lie on the plane, within :data:`PLANE_TOLERANCE` of their
        extent."""
        return self.spread <= PLANE_TOLERANCE * self.extent


def into_plane(xyz: np.ndarray, faces, source: str, fit: PlaneFit | None = None) -> np.ndarray:
    """(V, 2) coordinates of a flat sheet given in 3D in any plane, rotated into z = 0.

    Parameters
    ----------
    xyz : (V, 3) float
        Vertex coordinates, mm.
    faces : list of lists of int or None
        ``faces_vertices``, which fix the normal (module docstring).
    fit : PlaneFit, optional
        The points' plane, when the caller has it.

    Raises
    ------
    PatternError
        The vertices are not on one plane (a folded form).
    """
    fit = PlaneFit.of(xyz) if fit is None else fit
    spread, extent = fit.spread, fit.extent
    if not fit.flat:
        raise PatternError(
            f"{source}: the vertices are not on one plane (off it by up to {spread:g}, "
            f"{spread / extent:.1e} of the sheet): a folded form; foldcore reads the crease "
            "pattern from vertices_flatUnfoldCoords or a 2D key frame")
    normal = _oriented_normal(xyz, faces, fit.normal)
    rotated = xyz @ _rotation_onto_z(normal).T  # z is now the plane's offset: dropped
    angle = math.degrees(math.acos(max(-1.0, min(1.0, float(normal[2])))))
    note(source, f"a flat sheet off the z = 0 plane (normal {_vector(normal)}): rotated "
                 f"by {angle:.4g}° into it, faces' top side up")
    return rotated[:, :2]


def _oriented_normal(xyz: np.ndarray, faces, normal: np.ndarray) -> np.ndarray:
    """``normal`` or its opposite: the one the faces run counter-clockwise about."""
    if faces:
        area = np.zeros(3)
        for face in faces:
            p = xyz[np.asarray(face, dtype=np.int64)]
            area += np.cross(p, np.roll(p, -1, axis=0)).sum(axis=0)
        if float(area @ normal) != 0.0:
            return normal if float(area @ normal) > 0 else -normal
    for component, sign in ((2, 1.0), (1, -1.0), (0, 1.0)):
        if abs(normal[component]) > PLANE_TOLERANCE:
            return normal if sign * normal[component] > 0 else -normal
    return normal


def _rotation_onto_z(n: np.ndarray) -> np.ndarray:
    """(3, 3) rotation taking the unit vector ``n`` to +z (about n × z; a half-turn
    about x for n = −z)."""
    z = np.array([0.0, 0.0, 1.0])
    axis, cos = np.cross(n, z), float(n @ z)
    if np.linalg.norm(axis) < 1e-15:
        return np.eye(3) if cos > 0 else np.diag([1.0, -1.0, -1.0])
    k = np.array([[0.0, -axis[2], axis[1]], [axis[2], 0.0, -axis[0]],
                  [-axis[1], axis[0], 0.0]])
    return np.eye(3) + k + k @ k / (1.0 + cos)


def _vector(v: np.ndarray) -> str:
    return "(" + ", ".join(f"{x:.3g}" if abs(x) > 1e-12 else "0" for x in v) + ")"
