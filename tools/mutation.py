"""Mutation run: do the fast tests catch hand-written bugs in kernels and readers? (a dev tool)

Each mutant replaces one exact snippet of one source file (the snippet must occur
once) in a *temporary copy* of ``src/`` and ``tests/`` — never the working tree —
and runs a fast test subset there (``pytest -x``, a timeout per mutant):
``killed`` (a test failed), ``survived`` (all passed), ``timeout`` or ``error``
(the tests did not run: collection failed).

Kernel mutants (``src/elements``, ``rigid_normal.py``) run with
``NUMBA_DISABLE_JIT=1``: the kernels run as plain Python (no compile, the same
arithmetic). The others run compiled: the copy keeps ``__pycache__``, and numba's
cache (keyed on each file's content) stays valid for the files not mutated. An
unmutated baseline of every subset must pass first.

Writes ``tools/results/mutation.json`` (~10 min on 2 cores). Usage::

    python tools/mutation.py [--only ID,ID --out FILE]
    python tools/mutation.py --check   # every snippet still found once (after a refactor)

A mutant whose file no longer holds its snippet is applied to the one file of
src/ that holds it once (a refactor moved the code); ``--check`` lists those.
"""
from __future__ import annotations

import argparse
import json
import os
import re
import shutil
import subprocess
import sys
import tempfile
import time
from dataclasses import dataclass
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
OUT = ROOT / "tools" / "results" / "mutation.json"
TIMEOUT_S = 300

SUBSETS = {  # name: (test files, run kernels as plain Python)
    "kernels": (["tests/test_elements.py", "tests/test_rigid_normal.py"], True),
    "measure": (["tests/test_measure.py"], False),
    "readers": (["tests/test_io.py", "tests/test_pattern.py", "tests/test_fuzz_readers.py"],
                False),
    "results": (["tests/test_fabrication.py", "tests/test_fuzz_readers.py"], False),
}


@dataclass(frozen=True)
class Mutant:
    id: str
    file: str
    original: str
    replacement: str
    description: str
    subset: str


E, F = "src/elements/", "src/foldcore/"
MUTANTS = [
    Mutant("det-sign", E + "_rotation.py", "+ c * (d * h - e * g)", "- c * (d * h - e * g)",
           "3×3 determinant: wrong sign of the third cofactor", "kernels"),
    Mutant("newton-unscaled", E + "_rotation.py", "gamma = math.sqrt(n_y / n_x)", "gamma = 1.0",
           "polar Newton iteration without its scaling", "kernels"),
    Mutant("quaternion-entry", E + "_rotation.py", "2.0 * (xy - wz), 2.0 * (xz + wy)",
           "2.0 * (xy + wz), 2.0 * (xz + wy)", "quaternion→matrix: one entry's sign", "kernels"),
    Mutant("no-polish", E + "_rotation.py",
           "    w, x, y, z = polish_quaternion(a, b, c, d, e, f, g, h, i, w, x, y, z)\n", "",
           "quaternion fit without its polishing steps", "kernels"),
    Mutant("centroid-z", E + "_rotation.py", "return c0 / m, c1 / m, c2 / m",
           "return c0 / m, c1 / m, c2 / (m - 1)", "centroid: z divided by m − 1", "kernels"),
    Mutant("upper-bound", E + "_rotation.py", "sum_t += t0 * t0 + t1 * t1 + t2 * t2",
           "sum_t += t0 * t0 + t1 * t1", "Horn eigenvalue bound misses the target's z",
           "kernels"),
    Mutant("residual-z", E + "_rotation.py", "\n                     + (x[ids[k], 2] - c2 - o2) ** 2)",
           ")", "element residual (energy) without its z term", "kernels"),
    Mutant("strip-angle-sign", E + "bending_hinge.py", "d = 0.5 * (w_bot - w_top)",
           "d = 0.5 * (w_top - w_bot)", "Eq. 9 strip angle: valley/mountain swapped", "kernels"),
    Mutant("clamp-floor", E + "bending_hinge.py", "return min(max(phi, floor), max_angle)",
           "return min(max(phi, -floor), max_angle)",
           "passive valley strip may bend to the mountain side", "kernels"),
    Mutant("excess-sign", E + "bending_hinge.py", "                phi = -phi\n",
           "                phi = phi\n", "max-angle excess of a mountain strip unsigned",
           "kernels"),
    Mutant("eq8-sign", E + "bending_hinge.py", "(1.0 - 2.0 * y / width * math.tan(0.5 * phi))",
           "(1.0 + 2.0 * y / width * math.tan(0.5 * phi))", "Eq. 8 trapezoid bends the wrong way",
           "kernels"),
    Mutant("arc-thickness", E + "bending_hinge.py", "out[k, 1] = versine / kappa + y * cos_psi",
           "out[k, 1] = versine / kappa - y * cos_psi", "arc target: thickness offset mirrored",
           "kernels"),
    Mutant("smooth-max-offset", E + "bending_hinge.py", "+ gap * gap / (4.0 * delta) + 0.25 * delta",
           "+ gap * gap / (4.0 * delta) + 0.5 * delta", "axis-hinge pivot switch not continuous",
           "kernels"),
    Mutant("poisson-sign", E + "stretch_hinge.py", "lateral = ratio ** (-poisson)",
           "lateral = ratio ** poisson", "stretch hinge thickens instead of contracting",
           "kernels"),
    Mutant("strip-width-vertex", E + "_strip.py", "distance(x, ids[3], ids[2])",
           "distance(x, ids[3], ids[1])", "strip width measured across a wrong vertex pair",
           "kernels"),
    Mutant("normal-rotation-col", F + "rigid_normal.py",
           "evecs[0, 0], evecs[0, 1], evecs[0, 2] = 0.0, sw * t2, -sw * t1",
           "evecs[0, 0], evecs[0, 1], evecs[0, 2] = 0.0, -sw * t2, sw * t1",
           "rigid step: a rotation column of E with the wrong sign", "kernels"),
    Mutant("normal-panel-col", F + "rigid_normal.py",
           "vecs[n, 0], vecs[n, 1], vecs[n, 2] = 0.0, -al * a2, al * a1",
           "vecs[n, 0], vecs[n, 1], vecs[n, 2] = 0.0, al * a2, al * a1",
           "rigid step: one entry of −[a]× with the wrong sign", "kernels"),
    Mutant("reflection-fix", F + "measure.py", "    u[flip, :, 2] *= -1\n", "",
           "best_rotations returns a reflection when det(U Vᵀ) < 0 (audit mutant a)",
           "measure"),
    Mutant("reflection-row", F + "measure.py", "u[flip, :, 2] *= -1", "u[flip, 2, :] *= -1",
           "reflection fix flips a row: det +1 but not the best rotation", "measure"),
    Mutant("crease-direction", F + "measure.py",
           "pattern.vertices[pattern.edges[crease, 1]] - pattern.vertices[pattern.edges[crease, 0]]",
           "pattern.vertices[pattern.edges[crease, 0]] - pattern.vertices[pattern.edges[crease, 1]]",
           "fold angle measured along b→a: valley/mountain swapped (audit mutant c)", "measure"),
    Mutant("dihedral-order", F + "measure.py", "np.cross(n_right, n_left)",
           "np.cross(n_left, n_right)", "dihedral sign from the normals' wrong order", "measure"),
    Mutant("fold-z-below", F + "io/fold.py", "if len(xyz) == 3 and xyz[2] != 0:",
           "if len(xyz) == 3 and xyz[2] > 0:", "FOLD reader accepts z < 0 (audit mutant b)",
           "readers"),
    Mutant("obj-z-below", F + "io/obj.py", "if len(xyz) == 3 and xyz[2] != 0:",
           "if len(xyz) == 3 and xyz[2] > 0:", "OBJ reader accepts z < 0", "readers"),
    Mutant("pattern-z-below", F + "pattern.py", "np.flatnonzero(v[:, 2] != 0)",
           "np.flatnonzero(v[:, 2] > 0)", "CreasePattern accepts 3-D vertices with z < 0",
           "readers"),
    Mutant("angle-range", F + "pattern.py", "if abs(angle) > 180.0:", "if angle > 180.0:",
           "fold angles below −180° accepted", "readers"),
    Mutant("valley-contradiction", F + "pattern.py",
           'if kind == "M" and angle > 0 or kind == "V" and angle < 0:',
           'if kind == "M" and angle > 0:', "a valley with a negative angle accepted", "readers"),
    Mutant("huge-negative", F + "pattern.py", "(np.abs(v) > MAX_COORDINATE_MM)",
           "(v > MAX_COORDINATE_MM)", "huge negative coordinates accepted", "readers"),
    Mutant("hinge-width-zero", F + "io/obj.py", "if width is None or width <= 0:",
           "if width is None or width < 0:", "hinge file accepts width 0", "readers"),
    Mutant("reach-nan", F + "result_file.py", "far = np.flatnonzero(~(reach <= MAX_REACH * extent))",
           "far = np.flatnonzero(reach > MAX_REACH * extent)",
           "result reader accepts a NaN folded vertex", "results"),
    Mutant("no-thickness", F + "result_file.py", "    if fold.thickness is None:\n",
           "    if False:\n", "result reader accepts a file without foldcore:thickness",
           "results"),
]


def locate(root: Path, mutant: Mutant) -> tuple[str | None, int]:
    """The file under ``root`` holding ``mutant``'s snippet exactly once: its own
    ``file``, else the one file of src/ that does (a refactor moved it); and how many
    times the snippet occurs in the named file."""
    named = root / mutant.file
    count = named.read_text().count(mutant.original) if named.exists() else 0
    if count == 1:
        return mutant.file, count
    found = [p for p in sorted((root / "src").rglob("*.py"))
             if p.read_text().count(mutant.original) == 1]
    return (str(found[0].relative_to(root)) if len(found) == 1 else None), count


def make_copy(mutant: Mutant | None) -> Path:
    """Temporary root holding src/ (with its __pycache__), tests/, examples/ (the
    element tests register its plugin) and pyproject.toml, ``mutant`` applied."""
    root = Path(tempfile.mkdtemp(prefix="foldcore-mutant-"))
    shutil.copytree(ROOT / "src", root / "src")
    shutil.copytree(ROOT / "tests", root / "tests", ignore=shutil.ignore_patterns("__pycache__"))
    shutil.copytree(ROOT / "examples", root / "examples")
    shutil.copy(ROOT / "pyproject.toml", root)
    if mutant is not None:
        where, count = locate(root, mutant)
        if where is None:
            shutil.rmtree(root)
            raise SystemExit(f"mutant {mutant.id}: snippet found {count} times in "
                             f"{mutant.file} and in no other one file of src/ (needs exactly 1)")
        path = root / where
        path.write_text(path.read_text().replace(mutant.original, mutant.replacement))
    return root


def run_subset(root: Path, subset: str) -> dict:
    """Run ``subset``'s tests in ``root``: outcome, return code, seconds, first failure."""
    files, no_jit = SUBSETS[subset]
    env = dict(os.environ, PYTHONPATH=str(root / "src"), PYTHONDONTWRITEBYTECODE="1")
    env.pop("NUMBA_DISABLE_JIT", None)
    if no_jit:
        env["NUMBA_DISABLE_JIT"] = "1"
    start = time.perf_counter()
    try:
        proc = subprocess.run([sys.executable, "-m", "pytest", "-x", "-q", "-p", "no:cacheprovider",
                               *files], cwd=root, env=env, capture_output=True, text=True,
                              timeout=TIMEOUT_S, check=False)
    except subprocess.TimeoutExpired:
        return {"outcome": "timeout", "returncode": None,
                "seconds": round(time.perf_counter() - start, 1), "first_failure": None}
    failed = re.search(r"^(?:FAILED|ERROR) (\S+)", proc.stdout, re.MULTILINE)
    outcome = {0: "survived", 1: "killed"}.get(proc.returncode, "error")
    if "error during collection" in proc.stdout:  # the tests did not run
        outcome = "error"
    return {"outcome": outcome, "returncode": proc.returncode,
            "seconds": round(time.perf_counter() - start, 1),
            "first_failure": failed.group(1) if failed else None}


def run_one(mutant: Mutant | None, subset: str) -> dict:
    root = make_copy(mutant)
    try:
        return run_subset(root, subset)
    finally:
        shutil.rmtree(root, ignore_errors=True)


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--only", help="comma-separated mutant ids")
    parser.add_argument("--out", type=Path, default=OUT,
                        help="JSON written (with --only: only when given)")
    parser.add_argument("--check", action="store_true",
                        help="only check that every mutant's snippet occurs once in its file")
    args = parser.parse_args(argv)
    mutants = MUTANTS
    if args.only:
        wanted = set(args.only.split(","))
        mutants = [m for m in MUTANTS if m.id in wanted]
    if args.check:
        where = {m.id: locate(ROOT, m) for m in mutants}
        stale = [f"{m.id}: {where[m.id][1]} times in {m.file}, in no other one file"
                 for m in mutants if where[m.id][0] is None]
        moved = [f"{m.id}: {m.file} -> {where[m.id][0]}" for m in mutants
                 if where[m.id][0] not in (None, m.file)]
        print("\n".join(stale + moved) or f"all {len(mutants)} snippets found once")
        return 1 if stale else 0
    load = [os.getloadavg()[0]]
    start = time.perf_counter()
    baseline = {}
    for subset in sorted({m.subset for m in mutants}):
        baseline[subset] = run_one(None, subset)
        print(f"baseline {subset}: {baseline[subset]}", flush=True)
        if baseline[subset]["outcome"] != "survived":
            raise SystemExit(f"the unmutated {subset} tests do not pass; fix that first")
    rows = []
    for mutant in mutants:
        row = {"id": mutant.id, "file": mutant.file, "description": mutant.description,
               "subset": mutant.subset, **run_one(mutant, mutant.subset)}
        print(f"{row['outcome']:8s} {row['seconds']:6.1f} s  {mutant.id}: "
              f"{row['first_failure']}", flush=True)
        rows.append(row)
    load.append(os.getloadavg()[0])
    counts = {k: sum(r["outcome"] == k for r in rows)
              for k in ("killed", "survived", "timeout", "error")}
    print(counts, f"{time.perf_counter() - start:.0f} s")
    if args.only and args.out == OUT:
        return 0
    sys.path.insert(0, str(ROOT / "bench"))
    import _meta

    commit = subprocess.run(["git", "rev-parse", "--short", "HEAD"], cwd=ROOT, text=True,
                            capture_output=True, check=False).stdout.strip()
    args.out.write_text(json.dumps({
        "meta": {**_meta.machine(), "commit": commit,
                 "load_average_1min": load, "timeout_s": TIMEOUT_S,
                 "total_seconds": round(time.perf_counter() - start, 1),
                 "subsets": {k: {"tests": v[0], "numba_disable_jit": v[1]}
                             for k, v in SUBSETS.items()}},
        "baseline": baseline, "counts": counts, "total": len(rows), "mutants": rows,
    }, indent=1) + "\n")
    print(f"wrote {args.out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
