"""Small random fold problems for the verdict's tests (tests/test_verdict.py).

Each problem is a crease pattern and its thickness, drawn from a seeded
generator: degree-4 vertices (one crease driven, or all four at their closed
form), vertices of degree 5–6 with two creases driven (often binding), single
hinges, rows of panels with one crease driven and small Miura sheets driven
by one crease; thickness over size from 1e-4 to 3e-2, log-uniform. Meshes
stay at a few hundred vertices so that every strategy runs each in well under
a second.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from foldcore import patterns
from foldcore.kinematics import degree4_deg
from foldcore.pattern import CreasePattern

KINDS = ("vertex4", "vertex4_all", "vertex_n", "hinge", "row", "miura")


@dataclass(frozen=True)
class Problem:
    """A pattern, its thickness (mm) and a name that says what was drawn."""

    name: str
    pattern: CreasePattern
    thickness: float

    def scaled(self, scale: float) -> "Problem":
        """The same problem with every length × ``scale`` (1e3: given in µm)."""
        p = self.pattern
        widths = None if p.widths is None else np.asarray(p.widths, float) * scale
        pattern = p.replace(vertices=np.asarray(p.vertices, float) * scale,
                            **({} if widths is None else {"widths": widths}))
        return Problem(self.name, pattern, self.thickness * scale)


def problem(rng: np.random.Generator, kind: str) -> Problem:
    """One problem of ``kind`` (one of :data:`KINDS`) drawn from ``rng``."""
    ratio = float(10.0 ** rng.uniform(-4.0, np.log10(3e-2)))  # H / size
    if kind in ("vertex4", "vertex4_all"):
        alpha, beta = rng.uniform(50.0, 130.0, size=2)
        if abs(alpha - beta) < 5.0:
            beta = alpha + 10.0
        mode = str(rng.choice(["A", "B"]))
        rho1 = float(rng.uniform(10.0, 100.0))
        sectors = (alpha, beta, 180.0 - alpha, 180.0 - beta)
        radius = 50.0
        if kind == "vertex4":
            pattern = patterns.degree4_vertex(sectors, radius=radius, widths=None, mode=mode,
                                              rho1=rho1)
        else:
            rho = degree4_deg(alpha, beta, rho1, mode)
            assignments = ["V" if a > 0 else "M" for a in rho]
            pattern = patterns.single_vertex(sectors, assignments, fold_angles=list(rho),
                                             radius=radius)
        name = f"{kind} {mode} α={alpha:.0f} β={beta:.0f} ρ1={rho1:.0f}"
        size = 2 * radius
    elif kind == "vertex_n":
        n = int(rng.integers(5, 7))
        raw = rng.uniform(0.6, 1.4, size=n)
        sectors = 360.0 * raw / raw.sum()
        assignments = list(rng.choice(["M", "V"], size=n))
        angles = [None] * n
        for i in rng.choice(n, size=2, replace=False):
            sign = 1.0 if assignments[i] == "V" else -1.0
            angles[i] = sign * float(rng.uniform(10.0, 60.0))
        pattern = patterns.single_vertex(sectors, assignments, fold_angles=angles, radius=50.0)
        name = f"vertex_n n={n} driven {[round(a) for a in angles if a is not None]}"
        size = 100.0
    elif kind == "hinge":
        angle = float(rng.uniform(10.0, 170.0))
        pattern = patterns.single_hinge(panel_length=10.0, depth=10.0, angle=angle)
        name = f"hinge {angle:.0f}°"
        size = 20.0
    elif kind == "row":
        lengths = rng.uniform(5.0, 15.0, size=3)
        angle = float(rng.uniform(20.0, 120.0))
        pattern = patterns.panel_row(lengths, depth=10.0, assignment="V")
        pattern = pattern.replace(fold_angles=[angle] + [None] * (pattern.n_edges - 1))
        name = f"row {angle:.0f}°"
        size = float(lengths.sum())
    elif kind == "miura":
        gamma = float(rng.uniform(50.0, 80.0))
        tilt = float(rng.uniform(10.0, 60.0))
        pattern = patterns.miura_one_crease(2, 2, a=20.0, b=20.0, gamma=gamma, tilt=tilt)
        name = f"miura 2×2 γ={gamma:.0f} tilt={tilt:.0f}"
        size = float(np.ptp(pattern.vertices, axis=0).max())
    else:
        raise ValueError(kind)
    return Problem(f"{name} H/size={ratio:.1e}", pattern, ratio * size)


def problem_set(count: int, seed: int) -> list[Problem]:
    """``count`` problems, the kinds in turn, drawn from ``seed``."""
    rng = np.random.default_rng(seed)
    return [problem(rng, KINDS[i % len(KINDS)]) for i in range(count)]
