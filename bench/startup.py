"""Start-up cost: ``import foldcore`` and time to the first iteration, cold vs warm numba cache.

Every measurement is a fresh interpreter (a subprocess of this script) with
this one's environment.

* ``import``: seconds of ``import foldcore`` inside the process (interpreter
  start excluded), median of IMPORT_RUNS, against the project's src/.
* ``first_iteration``: the small scene of tests/test_startup.py —
  ``patterns.single_hinge(panel_length=5, depth=2, angle=45, width=2)``,
  ``thicken(p, 1.0, subdivisions=2)``, ``Simulation(mesh, p)`` (the default
  strategy), one ``sim.run(max_iterations=1)`` — timed inside the process
  from before ``import foldcore`` to the end of that iteration, then
  ``sim.run()`` to convergence (``first_result``: everything the default
  strategy compiles for a whole fold); split into import / lazy submodules /
  pattern + thicken / Simulation(...) / step; ``process_s`` is the whole
  subprocess's wall time seen from here (interpreter start and exit
  included).

Cache states (numba ``cache=True`` writes ``__pycache__/*.nbi|*.nbc`` next to
the sources; the project's own cache is never touched):

* ``cold_copy``: src/ copied to a temp dir without its ``__pycache__``
  folders and put first on PYTHONPATH (checked via ``foldcore.__file__``); a
  fresh copy per run, COLD_RUNS runs;
* ``cold_numba_cache_dir``: the project's src/ with ``NUMBA_CACHE_DIR`` set to
  an empty temp dir (numba then reads and writes only there), one run;
* ``warm``: the last ``cold_copy`` copy again, its cache now filled; one
  warm-up run, then the median of WARM_RUNS runs.

The kernels a run compiled are read off the cache files it wrote (index
files ``module.function-line.pyXY.nbi``), beside the ``@njit`` functions
found in the sources: what the scene never calls is neither compiled nor
written. Before each subprocess this waits (up to PATIENCE_S) for other jobs to
use < 25 % of the cores and records ``others_busy_during`` per run (the share
of the cores other processes used meanwhile). Seconds throughout.

Run: ``python bench/startup.py`` (~1.5 min) or ``--quick`` (no cold runs:
imports and warm runs against the project's own cache); writes
bench/results/startup.json and .png; ``--table`` prints the table of
docs/benchmarks.md from the JSON.
"""
from __future__ import annotations

import json
import os
import re
import resource
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import _meta

SRC = _meta.ROOT / "src"
IMPORT_RUNS, COLD_RUNS, WARM_RUNS = 5, 2, 3
QUICK_IMPORT_RUNS, QUICK_WARM_RUNS = 3, 2
PATIENCE_S = 300.0  # longest wait for a quiet machine before each run (--quick: none)
PARTS = ("import", "submodules", "pattern_thicken", "simulation", "step", "first_result")

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
print(json.dumps({
    "seconds": {"import": t1 - t0, "submodules": t2 - t1, "pattern_thicken": t3 - t2,
                "simulation": t4 - t3, "step": t5 - t4, "first_iteration": t5 - t0,
                "first_result": t6 - t0},
    "file": foldcore.__file__,
    "modules": sorted(n for n in sys.modules
                      if n.startswith("foldcore") or n.startswith("elements"))}))
"""


def cache_files(root: Path) -> dict:
    """{path: mtime_ns} of numba's cache files under ``root``."""
    return {p: p.stat().st_mtime_ns for pattern in ("*.nbi", "*.nbc") for p in root.rglob(pattern)}


def kernel_name(index: Path) -> str:
    """``package.module.function`` of a numba index file ``module.function-line.pyXY.nbi``
    (next to the sources in ``__pycache__``; under NUMBA_CACHE_DIR in a folder
    ``<package>_<hash>``)."""
    stem = re.sub(r"-\d+\.py\d+\.nbi$", "", index.name)
    if index.parent.name != "__pycache__":
        return f"{index.parent.name.rsplit('_', 1)[0]}.{stem}"
    parts = index.parent.parent.parts  # the folder holding __pycache__
    package = parts[parts.index("src") + 1:] if "src" in parts else parts[-1:]
    return ".".join([*package, stem])


def probe(code: str, env: dict, cache_root: Path) -> dict:
    """One fresh interpreter running ``code``; its JSON, the process's wall time, the load,
    and the kernels whose cache files it wrote under ``cache_root``."""
    quiet = _meta.wait_for_quiet(patience_s=PATIENCE_S)
    before = cache_files(cache_root)
    start, busy0 = time.perf_counter(), _meta.busy_seconds()
    cpu0 = resource.getrusage(resource.RUSAGE_CHILDREN)
    proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                          env=env, timeout=900, check=True)
    out = json.loads(proc.stdout.strip().splitlines()[-1])
    out["process_s"] = wall = time.perf_counter() - start
    cpu1 = resource.getrusage(resource.RUSAGE_CHILDREN)
    own = cpu1.ru_utime + cpu1.ru_stime - cpu0.ru_utime - cpu0.ru_stime
    out["others_busy_before"] = quiet
    out["others_busy_during"] = max(0.0, (_meta.busy_seconds() - busy0 - own)
                                    / (wall * os.cpu_count()))
    written = [p for p, t in cache_files(cache_root).items() if before.get(p) != t]
    out["cache_files_written"] = len(written)
    out["compiled"] = sorted({kernel_name(p) for p in written if p.suffix == ".nbi"})
    return out


def environment(pythonpath: Path, cache_dir: Path | None = None) -> dict:
    env = dict(os.environ, PYTHONPATH=str(pythonpath))
    env.pop("NUMBA_CACHE_DIR", None)
    if cache_dir is not None:
        env["NUMBA_CACHE_DIR"] = str(cache_dir)
    return env


def source_kernels(src: Path) -> list[str]:
    """Every ``@njit`` function in the sources, as module.function."""
    found = []
    for path in sorted(src.rglob("*.py")):
        module = ".".join(path.relative_to(src).with_suffix("").parts)
        for match in re.finditer(r"^@(?:numba\.)?njit[^\n]*\n(?:@[^\n]*\n)*def (\w+)",
                                 path.read_text(), re.M):
            found.append(f"{module}.{match.group(1)}")
    return found


def summary(runs: list[dict]) -> dict:
    keys = runs[0]["seconds"]
    return {"median_s": {k: _meta.median(r["seconds"][k] for r in runs) for k in keys},
            "process_median_s": _meta.median(r["process_s"] for r in runs),
            "compiled": runs[0]["compiled"], "runs": runs}


def cold_and_warm(tmp: Path, quick: bool) -> tuple[dict, list]:
    """Runs of RUN_PROBE per cache state (module docstring) and the source kernels."""
    if quick:  # the project's own cache, as warm as the last run left it
        warm = _meta.repeat(lambda: probe(RUN_PROBE, environment(SRC), SRC), QUICK_WARM_RUNS)
        return {"warm": summary(warm)}, source_kernels(SRC)
    cold, copy = [], None
    for i in range(COLD_RUNS):
        copy = tmp / f"cold{i}" / "src"
        shutil.copytree(SRC, copy, ignore=shutil.ignore_patterns("__pycache__", "*.pyc"))
        cold.append(probe(RUN_PROBE, environment(copy), copy))
        assert cold[-1]["file"].startswith(str(copy)), cold[-1]["file"]
        print(f"cold (copy {i}): first result {cold[-1]['seconds']['first_result']:.2f} s, "
              f"compiled {len(cold[-1]['compiled'])}", flush=True)
    cache_dir = tmp / "numba_cache"
    cache_dir.mkdir()
    cold_dir = [probe(RUN_PROBE, environment(SRC, cache_dir), cache_dir)]
    warm = _meta.repeat(lambda: probe(RUN_PROBE, environment(copy), copy), WARM_RUNS)
    states = {"cold_copy": summary(cold), "cold_numba_cache_dir": summary(cold_dir),
              "warm": summary(warm)}
    for state in states.values():  # temp paths mean nothing once the dir is gone
        for r in state["runs"]:
            r["file"] = r["file"].replace(str(tmp), "<tmp>")
    return states, source_kernels(copy)


def table(data: dict) -> str:
    """Median seconds per cache state: first iteration, first result, and its parts."""
    rows = [["`import foldcore`", f"{data['import']['median_s'] * 1e3:.1f} ms", "", "", "",
             "", ""]]
    for state, label in (("cold_copy", "cold cache (fresh copy of src/)"),
                         ("cold_numba_cache_dir", "cold cache (empty NUMBA_CACHE_DIR)"),
                         ("warm", "warm cache")):
        if state not in data["first_iteration"]:
            continue
        s = data["first_iteration"][state]
        m = s["median_s"]
        rows.append([label, f"{m['first_iteration']:.2f} s", f"{m['first_result']:.2f} s",
                     f"{m['submodules']:.2f} s", f"{m['step']:.2f} s",
                     f"{s['process_median_s']:.2f} s", str(len(s["compiled"]))])
    return _meta.markdown_table(["run", "first iteration", "first result",
                                 "lazy submodules", "first step", "whole process",
                                 "kernels compiled"], rows)


def plot(data: dict, path) -> None:
    """Per cache state, the median first result split into its parts (log scale)."""
    plt = _meta.pyplot()
    states = list(data["first_iteration"])
    fig, ax = plt.subplots(figsize=(8, 1.2 + 0.8 * len(states)))
    for k, state in enumerate(states):
        m = dict(data["first_iteration"][state]["median_s"])
        m["first_result"] -= m["first_iteration"]  # the rest of the fold
        left = 0.0
        for j, part in enumerate(PARTS):
            label = "rest of the fold" if part == "first_result" else part.replace("_", " + ")
            ax.barh(k, m[part], left=left, color=f"C{j}", label=label if k == 0 else None)
            left += m[part]
    ax.set_yticks(range(len(states)), [s.replace("_", " ") for s in states], fontsize=8)
    ax.set_xlabel("seconds from before `import foldcore` to the first result (medians)")
    ax.legend(fontsize=7, ncol=3)
    ax.set_title(f"import foldcore: {data['import']['median_s'] * 1e3:.1f} ms (median)",
                 fontsize=9)
    _meta.save(fig, path)


def main() -> None:
    global PATIENCE_S
    args = _meta.parser(__doc__).parse_args()
    if _meta.stored("startup", args, table, plot):
        return
    if args.quick:
        PATIENCE_S = 0.0
    import_runs = QUICK_IMPORT_RUNS if args.quick else IMPORT_RUNS
    record = _meta.Record(
        "startup", args, import_runs=import_runs, cold_runs=0 if args.quick else COLD_RUNS,
        warm_runs=QUICK_WARM_RUNS if args.quick else WARM_RUNS,
        PYTHONDONTWRITEBYTECODE=os.environ.get("PYTHONDONTWRITEBYTECODE"),
        scene="single_hinge(panel_length=5, depth=2, angle=45, width=2), thicken(H=1, "
              "subdivisions=2), Simulation(mesh, p) (default strategy), run(max_iterations=1)",
        units="seconds")
    imports = [probe(IMPORT_PROBE, environment(SRC), SRC) for _ in range(import_runs)]
    print(f"import foldcore: {_meta.median(r['seconds'] for r in imports):.4f} s", flush=True)
    with tempfile.TemporaryDirectory(prefix="foldcore-startup-") as tmp:
        states, kernels = cold_and_warm(Path(tmp), args.quick)
    compiled = set(states.get("cold_copy", states["warm"])["compiled"])
    data = {"import": {"median_s": _meta.median(r["seconds"] for r in imports),
                       "runs_s": [r["seconds"] for r in imports],
                       "process_median_s": _meta.median(r["process_s"] for r in imports),
                       "numba_imported": imports[0]["numba_imported"]},
            "first_iteration": states, "kernels_in_sources": kernels}
    if "cold_copy" in states:
        data["cold_over_warm"] = (states["cold_copy"]["median_s"]["first_iteration"]
                                  / states["warm"]["median_s"]["first_iteration"])
        data["kernels_never_touched"] = sorted(k for k in kernels if k not in compiled)
    record.write(data, plot)
    print(table(data))


if __name__ == "__main__":
    main()
