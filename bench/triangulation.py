"""Polygon triangulation: mapbox-earcut (foldcore.surface) against the Python ear clipping
it replaced.

The old implementation is a frozen copy below (:func:`old_triangulate`, the
ear clipping foldcore.fabrication had: O(n³) Python loops), so both run in
one interpreter on the same inputs. Inputs: ``POLYGONS`` random star-shaped
polygons of 16 to 30 vertices (angles evenly spaced with a random jitter of
up to 0.9 of a step, radii uniform in 0.3…1.0 × 50 mm: non-convex and
simple), half of them clockwise. Every triangulation of both is checked to
cover its polygon's area (relative 1e-9) before timing.

Timing: one warm-up pass of each (discarded), then ``RUNS`` passes over all
polygons, old and new interleaved so load changes hit both; the median
pass time is reported, with every pass's. ``new`` is
:func:`foldcore.surface.triangulate_polygon` called per polygon (earcut plus
its area, winding and vertex-count checks); ``new_batch``
:func:`foldcore.surface.triangulate_polygons` on all polygons at once (what
``surface_triangles`` calls: the checks vectorised); ``earcut_only`` the bare
``mapbox_earcut`` call per polygon. The
JSON records the CPU model, core count and ``os.getloadavg()`` before and
after (the machine is shared).

Run: ``.venv/bin/python bench/triangulation.py`` (about a minute). Writes
bench/results/triangulation.json.
"""
from __future__ import annotations

import json
import os
import statistics
import sys
import time
from pathlib import Path

import mapbox_earcut
import numpy as np

sys.path.insert(0, str(Path(__file__).parent))
from _meta import cpu_model  # noqa: E402

from foldcore.surface import triangulate_polygon, triangulate_polygons  # noqa: E402

RESULTS = Path(__file__).parent / "results"
POLYGONS = 2000
VERTICES = (16, 30)
RUNS = 7
SEED = 20
RADIUS_MM = 50.0


# ----------------------------------------------------------- the old implementation
def old_triangulate(xy) -> np.ndarray:
    """Frozen copy of the ear clipping foldcore used before mapbox-earcut (the code, not
    its error class): (n−2, 3) int64, each triangle in the polygon's orientation."""
    xy = np.asarray(xy, dtype=float)
    n = len(xy)
    area2 = float(np.sum(xy[:, 0] * np.roll(xy[:, 1], -1) - np.roll(xy[:, 0], -1) * xy[:, 1]))
    order = list(range(n)) if area2 >= 0 else list(range(n))[::-1]
    eps = 1e-12 * max(float(np.ptp(xy, axis=0).max()), 1e-300) ** 2
    tris = []
    while len(order) > 3:
        for t in range(len(order)):
            a, b, c = order[t - 1], order[t], order[(t + 1) % len(order)]
            if _cross2(xy[a], xy[b], xy[c]) > eps and not _any_inside(xy, order, a, b, c, eps):
                tris.append((a, b, c))
                del order[t]
                break
        else:
            raise ValueError("cannot triangulate a face: its polygon is not simple")
    tris.append(tuple(order))
    out = np.array(tris, dtype=np.int64)
    return out if area2 >= 0 else out[:, ::-1]


def _cross2(a, b, c) -> float:
    return float((b[0] - a[0]) * (c[1] - b[1]) - (b[1] - a[1]) * (c[0] - b[0]))


def _any_inside(xy, order, a, b, c, eps) -> bool:
    others = [i for i in order if i not in (a, b, c)]
    if not others:
        return False
    p = xy[others]
    inside = np.ones(len(others), dtype=bool)
    for u, v in ((a, b), (b, c), (c, a)):
        e = xy[v] - xy[u]
        inside &= e[0] * (p[:, 1] - xy[u][1]) - e[1] * (p[:, 0] - xy[u][0]) >= -eps
    return bool(inside.any())


# ----------------------------------------------------------- inputs and checks
def star_polygons(count: int, seed: int) -> list:
    """``count`` random star-shaped (simple, non-convex) polygons, (n, 2) mm each."""
    rng = np.random.default_rng(seed)
    out = []
    for i in range(count):
        n = int(rng.integers(VERTICES[0], VERTICES[1] + 1))
        angle = 2 * np.pi * (np.arange(n) + 0.9 * rng.uniform(0, 1, n)) / n
        radius = RADIUS_MM * rng.uniform(0.3, 1.0, n)
        xy = np.column_stack([radius * np.cos(angle), radius * np.sin(angle)])
        out.append(xy[::-1].copy() if i % 2 else xy)
    return out


def _area(xy) -> float:
    return 0.5 * float(np.sum(xy[:, 0] * np.roll(xy[:, 1], -1) - np.roll(xy[:, 0], -1) * xy[:, 1]))


def check(polygons, triangulate) -> None:
    """Every triangulation: n−2 triangles of the polygon's winding covering its area."""
    for xy in polygons:
        tris = triangulate(xy)
        areas = np.array([_area(xy[t]) for t in tris])
        assert len(tris) == len(xy) - 2
        assert (np.sign(_area(xy)) * areas > 0).all()
        assert abs(np.abs(areas).sum() - abs(_area(xy))) <= 1e-9 * abs(_area(xy))


def earcut_only(xy) -> np.ndarray:
    """The bare earcut call: flat (3(n−2),) uint32 indices."""
    return mapbox_earcut.triangulate_float64(xy, np.array([len(xy)], dtype=np.uint32))


def one_pass(polygons, triangulate) -> float:
    """Seconds to triangulate every polygon, one call each."""
    start = time.perf_counter()
    for xy in polygons:
        triangulate(xy)
    return time.perf_counter() - start


def batch_pass(polygons, _=None) -> float:
    """Seconds of one :func:`triangulate_polygons` call on every polygon."""
    start = time.perf_counter()
    triangulate_polygons(polygons)
    return time.perf_counter() - start


def main() -> None:
    load_before = os.getloadavg()
    polygons = star_polygons(POLYGONS, SEED)
    check(polygons, old_triangulate)
    check(polygons, triangulate_polygon)
    assert all((a == b).all() for a, b in zip(triangulate_polygons(polygons),
                                              map(triangulate_polygon, polygons)))
    methods = {"old": (one_pass, old_triangulate), "new": (one_pass, triangulate_polygon),
               "new_batch": (batch_pass, None), "earcut_only": (one_pass, earcut_only)}
    for timer, f in methods.values():                # warm-up
        timer(polygons, f)
    runs = {name: [] for name in methods}
    for _ in range(RUNS):
        for name, (timer, f) in methods.items():
            runs[name].append(timer(polygons, f))
    median = {name: statistics.median(t) for name, t in runs.items()}
    data = {"meta": {"machine": cpu_model(), "cpus": os.cpu_count(),
                     "loadavg_before": load_before, "loadavg_after": os.getloadavg(),
                     "python": sys.version.split()[0], "numpy": np.__version__,
                     "mapbox_earcut": mapbox_earcut.__version__,
                     "polygons": POLYGONS, "vertices": list(VERTICES), "runs": RUNS,
                     "seed": SEED},
            "vertices_total": int(sum(len(p) for p in polygons)),
            "seconds_median": median, "seconds_runs": runs,
            "us_per_polygon_median": {k: 1e6 * v / POLYGONS for k, v in median.items()},
            "speedup_vs_old": {k: median["old"] / v for k, v in median.items() if k != "old"}}
    RESULTS.mkdir(exist_ok=True)
    (RESULTS / "triangulation.json").write_text(json.dumps(data, indent=1) + "\n")
    for name, seconds in median.items():
        print(f"{name:12s} {seconds:.4f} s per {POLYGONS} polygons "
              f"({1e6 * seconds / POLYGONS:.1f} µs each)")
    for name, speedup in data["speedup_vs_old"].items():
        print(f"{name} is {speedup:.0f}× faster than old")


if __name__ == "__main__":
    main()
