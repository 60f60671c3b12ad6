"""What a fused projection + scatter would buy (issue 7's last 0.1–0.3×): a measured prototype.

DESIGN.md's element contract has every kernel write its rotated target into
its own rows of a targets array, and the rhs *gathered* per vertex afterwards
(race-free). The alternative measured here is outside that contract: elements
are coloured so that no two of one colour share a vertex, and each element
adds w·R·T straight into the (column-major) rhs as soon as it is projected —
one parallel loop per colour, no gather pass. ``contract`` is the engine's
own iteration (since the bending hinge's ``prepare``, actuated strips' bent
shapes are computed once, not per iteration); ``fused`` projects with the
plain kernels (bent shapes every iteration) and scatters; ``fused_cached``
takes every element's target shape from a per-slot array computed once and
scatters: the like-for-like comparison with ``contract`` (same shape work,
colour-scatter instead of gather).

Scene: the Miura-ori of ``bench/scaling.py`` (same builder), paper solver, the
Simulation's own thread count. Each round times, interleaved: the contract's
iteration by pieces (projection, gather + anchor pin, solve, take), the fused
iteration (zero the rhs, one parallel loop per colour per group, anchor pin,
solve, take), the fused one with cached bent shapes, and a bare solve; medians
over ROUNDS rounds after WARM rounds. Checks first that the fused rhs equals
the gathered one (relative 1e-12): the prototype computes the same iteration.

Run: ``.venv/bin/python bench/fused_prototype.py [--sizes 50 100 200]``
(~6 min); writes bench/results/fused_prototype.json and .png. Not part of the library: a
prototype to decide whether the contract change is worth it.
"""
from __future__ import annotations

import argparse
import json
import statistics
import sys
import time
from pathlib import Path

import numpy as np
from numba import njit, prange

from elements._rotation import fit_rotated

sys.path.insert(0, str(Path(__file__).parent))
from _meta import machine_meta  # noqa: E402
from scaling import project_and_gather, setup_once, solve_and_take  # noqa: E402

RESULTS = Path(__file__).parent / "results"
WARM, ROUNDS = 3, 20
MAX_COLOURS = 63


@njit(cache=True)
def colour_elements(indptrs, indices_list, n_vertices, colours_out):
    """Greedy colouring over all groups: no two elements of one colour share a vertex.

    Elements are visited group by group in index order; each takes the lowest
    colour none of its vertices has yet (a per-vertex bit mask). Returns the
    number of colours used, or -1 above MAX_COLOURS.
    """
    used = np.zeros(n_vertices, dtype=np.int64)
    n_colours = 0
    for g in range(len(indptrs)):
        indptr, indices, out = indptrs[g], indices_list[g], colours_out[g]
        for e in range(len(indptr) - 1):
            mask = 0
            for k in range(indptr[e], indptr[e + 1]):
                mask |= used[indices[k]]
            c = 0
            while mask & (1 << c):
                c += 1
            if c > MAX_COLOURS:
                return -1
            out[e] = c
            for k in range(indptr[e], indptr[e + 1]):
                used[indices[k]] |= 1 << c
            n_colours = max(n_colours, c + 1)
    return n_colours


def make_fused(project):
    """A parallel loop over some elements of a group: project, then add w·R·T into rhs."""

    @njit(parallel=True)
    def fused(x, indptr, indices, rest, params, weights, elements, targets, energy, state, rhs):
        for j in prange(len(elements)):
            e = elements[j]
            s, t = indptr[e], indptr[e + 1]
            energy[e] = project(x, indices[s:t], rest[s:t], params[e], targets[s:t], state[e])
            w = weights[e]
            for k in range(s, t):
                v = indices[k]
                rhs[v, 0] += w * targets[k, 0]
                rhs[v, 1] += w * targets[k, 1]
                rhs[v, 2] += w * targets[k, 2]

    return fused


@njit
def project_fixed_shape(x, ids, shape, params, out, state):
    """The element's precomputed (centred) target ``shape`` rotated onto x[ids]."""
    return fit_rotated(x, ids, shape, out)


fused_fixed_shape = make_fused(project_fixed_shape)


class Fused:
    """The fused iteration's data: per group, its elements split by colour."""

    def __init__(self, sim, cached: bool):
        from elements.bending_hinge import bent_shapes

        runs = sim._runs
        self.sim = sim
        colours = [np.empty(len(r.group), dtype=np.int64) for r in runs]
        from numba.typed import List
        self.n_colours = colour_elements(List([r.group.indptr for r in runs]),
                                         List([r.group.indices for r in runs]),
                                         sim.mesh.n_vertices, List(colours))
        assert self.n_colours > 0, "too many colours"
        self.by_colour = [[np.flatnonzero(c == k) for k in range(self.n_colours)]
                          for c in colours]
        self.kernels = [make_fused(r.etype.project) for r in runs]
        self.shapes = []
        for r in runs:
            g = r.group
            if cached and r.etype.name == "bending_hinge":
                assert not np.isnan(r.params[:, 2]).any(), "every strip actuated here"
                out = np.empty_like(g.rest)
                bent_shapes(g.indptr, g.rest, r.params, r.params[:, 2], out)
                self.shapes.append(out)
            elif cached and r.etype.name == "rigid_panel":
                self.shapes.append(np.ascontiguousarray(g.rest))
            else:
                self.shapes.append(None)

    def rhs(self, x, rhs):
        sim = self.sim
        rhs[:] = 0.0
        for k in range(self.n_colours):
            for gi, (r, w) in enumerate(zip(sim._runs, sim.system.weights)):
                elems = self.by_colour[gi][k]
                if not len(elems):
                    continue
                g, shapes = r.group, self.shapes[gi]
                kernel = self.kernels[gi] if shapes is None else fused_fixed_shape
                kernel(x, g.indptr, g.indices, g.rest if shapes is None else shapes,
                       r.params, w, elems, sim._targets[r.slots], r.energy, r.state, rhs)
        sim._add_pin_terms(rhs, x)
        return rhs


def contract_iteration(sim, x, t):
    """The engine's iteration by pieces (``scaling``'s helpers) into ``t``; new x."""
    t["contract_projection"], t["contract_gather"] = project_and_gather(sim, x, sim._rhs)
    new_x, solve, take = solve_and_take(sim, sim._rhs, x)
    t["contract"] = t["contract_projection"] + t["contract_gather"] + solve + take
    return new_x


def fused_iteration(sim, fused, x, t, key):
    """The fused iteration (projection + colour scatter, solve, take) into ``t``; new x."""
    t0 = time.perf_counter()
    rhs = fused.rhs(x, sim._rhs)
    scatter = time.perf_counter() - t0
    new_x, solve, take = solve_and_take(sim, rhs, x)
    t[key], t[key + "_projection_scatter"] = scatter + solve + take, scatter
    return new_x


def measure(n: int) -> dict:
    import numba

    _, mesh, pattern, sim = setup_once(n)
    numba.set_num_threads(sim.threads)
    plain, cached = Fused(sim, cached=False), Fused(sim, cached=True)
    x = sim.x.copy()
    reference = np.zeros_like(sim._rhs)
    project_and_gather(sim, x, reference)
    scale = np.abs(reference).max()
    errors = {}
    for name, f in (("fused", plain), ("fused_cached", cached)):
        got = f.rhs(x, np.zeros_like(sim._rhs, order="F")).copy()
        errors[name] = float(np.abs(got - reference).max() / scale)
        assert errors[name] < 1e-12, (name, errors[name])
    rounds = []
    for i in range(WARM + ROUNDS):
        t = {}
        x = contract_iteration(sim, x, t)
        fused_iteration(sim, plain, x, t, "fused")
        fused_iteration(sim, cached, x, t, "fused_cached")
        rhs = np.asfortranarray(x)
        t0 = time.perf_counter()
        sim.system.factor.solve(rhs)
        t["bare_solve"] = time.perf_counter() - t0
        if i >= WARM:
            rounds.append(t)
    med = {k: statistics.median(r[k] for r in rounds) for k in rounds[0]}
    return {"n": n, "thick_vertices": int(mesh.n_vertices), "threads": int(sim.threads),
            "colours": plain.n_colours, "rhs_relative_difference": errors,
            "median_s": med,
            "vs_bare_solve": {k: med[k] / med["bare_solve"]
                              for k in ("contract", "fused", "fused_cached")}}


def plot(rows, path: Path) -> None:
    """Per-iteration time of each variant as a multiple of the bare solve, per size."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    variants = ("contract", "fused", "fused_cached")
    fig, ax = plt.subplots(figsize=(7, 4.5))
    width = 0.8 / len(variants)
    for i, name in enumerate(variants):
        ax.bar([j + i * width for j in range(len(rows))],
               [r["vs_bare_solve"][name] for r in rows], width, label=name)
    ax.axhline(1.3, color="k", ls="--", lw=1, label="issue 7 target (1.3×)")
    ax.set_xticks([j + width for j in range(len(rows))])
    ax.set_xticklabels([f"{r['n']}×{r['n']}\n{r['thick_vertices']:,} vertices" for r in rows])
    ax.set_ylabel("iteration time / bare CHOLMOD solve")
    ax.set_ylim(1.0, None)
    ax.set_title("Gather (contract) vs colour-fused scatter, Miura n×n, medians")
    ax.legend()
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sizes", type=int, nargs="+", default=[50, 100, 200])
    args = parser.parse_args()
    import scipy.sparse.linalg  # noqa: F401  (scipy's BLAS loaded before the guard scans)

    import foldcore.simulation  # noqa: F401
    from foldcore.threads import blas_on_one_thread

    rows = []
    with blas_on_one_thread(refresh=True):
        for n in args.sizes:
            row = measure(n)
            print(json.dumps({k: row[k] for k in ("n", "colours", "vs_bare_solve")}), flush=True)
            rows.append(row)
    RESULTS.mkdir(exist_ok=True)
    (RESULTS / "fused_prototype.json").write_text(json.dumps(
        {"meta": machine_meta(), "rows": rows}, indent=1))
    plot(rows, RESULTS / "fused_prototype.png")


if __name__ == "__main__":
    main()
