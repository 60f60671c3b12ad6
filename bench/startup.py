"""Start-up cost: ``import foldcore`` and time to the first iteration, cold vs warm numba cache.

Every measurement is a fresh interpreter (subprocess of this script), with the
environment of this one (``PYTHONDONTWRITEBYTECODE`` as set there).

* ``import``: seconds of ``import foldcore`` inside the process (interpreter
  start excluded), median of IMPORT_RUNS, against the project's src/.
* ``first_iteration``: the small scene of tests/test_startup.py —
  ``patterns.single_hinge(panel_length=5, depth=2, angle=45, width=2)``,
  ``thicken(p, 1.0, subdivisions=2)``, ``Simulation(mesh, p)`` (the
  default strategy), one ``sim.run(max_iterations=1)`` (with ``hybrid`` a
  rigid-body step) — timed inside the process from before ``import
  foldcore`` to the end of that iteration — then ``sim.run()`` to
  convergence (``first_result``: everything the default strategy compiles
  for a whole fold, its L-BFGS phase's kernels included), split into import / lazy submodules / pattern +
  thicken / Simulation(...) / step; ``process_s`` is the whole subprocess
  wall time seen from here (interpreter start and exit included).

Cache states (numba ``cache=True`` writes ``__pycache__/*.nbi|*.nbc`` next
to the sources; the project's own cache is never touched):

* ``cold_copy``: src/ copied to a temp dir without its ``__pycache__``
  folders and put first on PYTHONPATH (the editable install is a plain .pth
  path entry, which PYTHONPATH precedes; checked via ``foldcore.__file__``).
  A fresh copy per run, COLD_RUNS runs.
* ``cold_numba_cache_dir``: the project's src/ with ``NUMBA_CACHE_DIR`` set
  to an empty temp dir (numba then reads and writes only there), one run.
* ``warm``: the last ``cold_copy`` copy again, its cache now filled; median
  of WARM_RUNS runs.

Each run reports every numba dispatcher of the loaded ``foldcore``/``elements``
modules with its compiled signatures, cache hits (loaded) and cache misses
(compiled), beside the list of ``@njit`` functions found in the sources: what
the scene never calls is neither compiled nor loaded. Seconds throughout.
The machine is shared: before each subprocess this waits (up to 300 s, see
``scaling.wait_for_quiet``) for other jobs to use < 25 % of the cores and
records ``others_busy_during`` per run (share of the cores other processes
used meanwhile). Writes bench/results/startup.json.

Run: ``.venv/bin/python bench/startup.py`` (~1 min on a quiet machine).
"""
from __future__ import annotations

import json
import os
import re
import resource
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from foldcore.strategies import DEFAULT_SOLVER

ROOT = Path(__file__).resolve().parent.parent
SRC = ROOT / "src"
RESULTS = Path(__file__).parent / "results"
IMPORT_RUNS = 5
COLD_RUNS = 2
WARM_RUNS = 3

IMPORT_PROBE = """
import json, sys, time
t = time.perf_counter()
import foldcore
elapsed = time.perf_counter() - t
print(json.dumps({"seconds": elapsed, "file": foldcore.__file__,
                  "numba_imported": "numba" in sys.modules}))
"""

RUN_PROBE = """
import time
t0 = time.perf_counter()
import foldcore
t1 = time.perf_counter()
from foldcore import patterns, thicken, Simulation
t2 = time.perf_counter()
p = patterns.single_hinge(panel_length=5.0, depth=2.0, angle=45.0, width=2.0)
mesh = thicken(p, 1.0, subdivisions=2)
t3 = time.perf_counter()
sim = Simulation(mesh, p)
t4 = time.perf_counter()
sim.run(tolerance=0.0, max_iterations=1)
t5 = time.perf_counter()
sim.run()
t6 = time.perf_counter()

import json, sys
from numba.core.registry import CPUDispatcher
kernels = {}
for name, module in sorted(sys.modules.items()):
    if not (name.startswith("foldcore") or name.startswith("elements")) or module is None:
        continue
    for attr, value in vars(module).items():
        if isinstance(value, CPUDispatcher) and value.__module__ == name:
            stats = value.stats
            kernels[name + "." + attr] = {
                "signatures": len(value.signatures),
                "cache_hits": sum(stats.cache_hits.values()),
                "cache_misses": sum(stats.cache_misses.values()),
                "cache_path": stats.cache_path}
print(json.dumps({
    "seconds": {"import": t1 - t0, "submodules": t2 - t1, "pattern_thicken": t3 - t2,
                "simulation": t4 - t3, "step": t5 - t4, "first_iteration": t5 - t0,
                "first_result": t6 - t0},
    "file": foldcore.__file__,
    "modules": sorted(n for n in sys.modules
                      if n.startswith("foldcore") or n.startswith("elements")),
    "kernels": kernels}))
"""


def probe(code: str, env: dict) -> dict:
    from scaling import busy_seconds, wait_for_quiet

    quiet = wait_for_quiet()
    start, busy0 = time.perf_counter(), busy_seconds()
    cpu0 = resource.getrusage(resource.RUSAGE_CHILDREN)
    proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                          env=env, timeout=900, check=True)
    out = json.loads(proc.stdout.strip().splitlines()[-1])
    out["process_s"] = wall = time.perf_counter() - start
    cpu1 = resource.getrusage(resource.RUSAGE_CHILDREN)
    own = cpu1.ru_utime + cpu1.ru_stime - cpu0.ru_utime - cpu0.ru_stime
    out["others_busy_before"] = quiet
    out["others_busy_during"] = max(0.0, (busy_seconds() - busy0 - own) / (wall * os.cpu_count()))
    return out


def environment(pythonpath: Path | None = None, cache_dir: Path | None = None) -> dict:
    env = dict(os.environ)
    env.pop("NUMBA_CACHE_DIR", None)
    if pythonpath is not None:
        env["PYTHONPATH"] = str(pythonpath)
    if cache_dir is not None:
        env["NUMBA_CACHE_DIR"] = str(cache_dir)
    return env


def fresh_copy(tmp: Path, tag: str) -> Path:
    dest = tmp / tag / "src"
    shutil.copytree(SRC, dest, ignore=shutil.ignore_patterns("__pycache__", "*.pyc"))
    return dest


def source_kernels(src: Path) -> list[str]:
    """Every ``@njit`` function in the sources, as module.function."""
    found = []
    for path in sorted(src.rglob("*.py")):
        module = ".".join(path.relative_to(src).with_suffix("").parts)
        text = path.read_text()
        for match in re.finditer(r"^@(?:numba\.)?njit[^\n]*\n(?:@[^\n]*\n)*def (\w+)", text,
                                 re.M):
            found.append(f"{module}.{match.group(1)}")
    return found


def summary(runs: list[dict]) -> dict:
    keys = runs[0]["seconds"]
    return {"median_s": {k: statistics.median(r["seconds"][k] for r in runs) for k in keys},
            "process_median_s": statistics.median(r["process_s"] for r in runs),
            "compiled": sorted(k for k, v in runs[0]["kernels"].items() if v["cache_misses"]),
            "loaded": sorted(k for k, v in runs[0]["kernels"].items() if v["cache_hits"]),
            "runs": runs}


def main() -> None:
    sys.path.insert(0, str(Path(__file__).parent))
    from _meta import machine_meta

    project = environment(SRC)
    imports = [probe(IMPORT_PROBE, project) for _ in range(IMPORT_RUNS)]
    print(f"import foldcore: {statistics.median(r['seconds'] for r in imports):.4f} s",
          flush=True)

    with tempfile.TemporaryDirectory(prefix="foldcore-startup-") as tmp:
        tmp = Path(tmp)
        cold, copy = [], None
        for i in range(COLD_RUNS):
            copy = fresh_copy(tmp, f"cold{i}")
            cold.append(probe(RUN_PROBE, environment(copy)))
            assert cold[-1]["file"].startswith(str(copy)), cold[-1]["file"]
            print(f"cold (copy {i}): first result {cold[-1]['seconds']['first_result']:.2f} s, "
                  f"first iteration {cold[-1]['seconds']['first_iteration']:.2f} s"
                  f", compiled {sum(v['cache_misses'] > 0 for v in cold[-1]['kernels'].values())}",
                  flush=True)
        cache_dir = tmp / "numba_cache"
        cache_dir.mkdir()
        cold_dir = [probe(RUN_PROBE, environment(SRC, cache_dir))]
        print(f"cold (NUMBA_CACHE_DIR): first result {cold_dir[0]['seconds']['first_result']:.2f}"
              f" s, first iteration {cold_dir[0]['seconds']['first_iteration']:.2f} s", flush=True)
        warm = [probe(RUN_PROBE, environment(copy)) for _ in range(WARM_RUNS)]
        print(f"warm: first result "
              f"{statistics.median(r['seconds']['first_result'] for r in warm):.2f} s, first "
              f"iteration {statistics.median(r['seconds']['first_iteration'] for r in warm):.2f} s",
              flush=True)
        kernels = source_kernels(copy)

    for runs in (cold, cold_dir, warm):
        for r in runs:  # temp paths mean nothing once the dir is gone
            r["file"] = r["file"].replace(str(tmp), "<tmp>")
            for v in r["kernels"].values():
                v["cache_path"] = (v["cache_path"] or "").replace(str(tmp), "<tmp>")
    cold_kernels = cold[0]["kernels"]
    data = {
        "meta": {**machine_meta(), "import_runs": IMPORT_RUNS, "cold_runs": COLD_RUNS,
                 "warm_runs": WARM_RUNS,
                 "PYTHONDONTWRITEBYTECODE": os.environ.get("PYTHONDONTWRITEBYTECODE"),
                 "scene": "single_hinge(panel_length=5, depth=2, angle=45, width=2), "
                          "thicken(H=1, subdivisions=2), Simulation(mesh, p) (default "
                          f"solver, {DEFAULT_SOLVER}), run(max_iterations=1)",
                 "units": "seconds"},
        "import": {"median_s": statistics.median(r["seconds"] for r in imports),
                   "runs_s": [r["seconds"] for r in imports],
                   "process_median_s": statistics.median(r["process_s"] for r in imports),
                   "numba_imported": imports[0]["numba_imported"]},
        "first_iteration": {"cold_copy": summary(cold),
                            "cold_numba_cache_dir": summary(cold_dir),
                            "warm": summary(warm)},
        "cold_over_warm": (statistics.median(r["seconds"]["first_iteration"] for r in cold)
                           / statistics.median(r["seconds"]["first_iteration"] for r in warm)),
        "kernels_in_sources": kernels,
        # cold: every kernel the scene reaches is compiled (callees too); warm: only the
        # entry points are loaded, their callees are linked into the cached code
        "kernels_never_touched": sorted(
            k for k in kernels
            if k not in cold_kernels or not cold_kernels[k]["signatures"]),
    }
    RESULTS.mkdir(exist_ok=True)
    (RESULTS / "startup.json").write_text(json.dumps(data, indent=1))
    print("compiled cold:", data["first_iteration"]["cold_copy"]["compiled"])
    print("never touched:", data["kernels_never_touched"])


if __name__ == "__main__":
    main()
