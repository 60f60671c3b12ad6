"""Start-up contract: ``import foldcore`` is fast and light; kernels come from numba's cache.

Both run in fresh interpreters (subprocesses): the test process has already
imported everything.
"""
from __future__ import annotations

import json
import os
import subprocess
import sys

IMPORT_PROBE = """
import json, sys, time
t = time.perf_counter()
import foldcore
elapsed = time.perf_counter() - t
heavy = sorted(m for m in ("pyvista", "vtk", "numba", "scipy", "elements") if m in sys.modules)
print(json.dumps({"seconds": elapsed, "heavy": heavy}))
"""

RUN_PROBE = """
import json
import numba
from foldcore import patterns, thicken, Simulation
import elements.bending_hinge as bh, elements.rigid_panel as rp
from foldcore import system
p = patterns.single_hinge(panel_length=5.0, depth=2.0, angle=45.0, width=2.0)
sim = Simulation(thicken(p, 1.0, subdivisions=2), p)
sim.run(tolerance=0, max_iterations=3)
misses = {f.__name__ + "@" + f.__module__: sum(f.stats.cache_misses.values())
          for f in (bh.prepare, bh.prepared_batch, bh.limit_excess, rp.batch, system.gather)}
print(json.dumps(misses))
"""


def _run(code: str, env=None) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                          timeout=600, check=True, env=env)


def _last_json(proc: subprocess.CompletedProcess) -> dict:
    return json.loads(proc.stdout.strip().splitlines()[-1])


def _probe(code: str, env=None) -> dict:
    return _last_json(_run(code, env))


def test_import_is_fast_and_imports_no_heavy_module():
    probe = _probe(IMPORT_PROBE)
    assert probe["heavy"] == []
    assert probe["seconds"] < 0.5


def test_second_process_loads_kernels_from_the_cache():
    _probe(RUN_PROBE)                  # compiles (cold) or loads (warm)
    misses = _probe(RUN_PROBE)         # a new process: nothing may compile
    assert all(n == 0 for n in misses.values()), misses


CLI_PROBE = """
import json
from foldcore import patterns
from foldcore.cli import main
from foldcore.io import write_fold
from foldcore.warmup import _cache_counts
p = patterns.single_hinge(panel_length=5.0, depth=2.0, angle=90.0, width=2.0)
write_fold({src!r}, p, thickness=1.0)
assert main(["simulate", {src!r}, "-o", {out!r}]) == 0
print(json.dumps(_cache_counts()))
"""


def test_warmup_compiles_what_a_first_simulate_needs(tmp_path):
    """After ``python -m foldcore.warmup`` (the set-up's last step), a default
    ``foldcore simulate`` of a hinge in a new process compiles no kernel. Both
    run on an empty numba cache of their own (NUMBA_CACHE_DIR), so the project's
    warm cache cannot hide a kernel the warm-up misses (slow: a cold compile)."""
    env = {**os.environ, "NUMBA_CACHE_DIR": str(tmp_path / "numba")}
    subprocess.run([sys.executable, "-m", "foldcore.warmup"], capture_output=True,
                   timeout=600, check=True, env=env)
    code = CLI_PROBE.format(src=str(tmp_path / "h.fold"), out=str(tmp_path / "o.fold"))
    counts = _probe(code, env)
    assert counts["compiled"] == 0 and counts["loaded"] > 0, counts


def test_public_names_survive_submodule_imports():
    """``foldcore.thicken`` stays the function after its submodules are imported
    (a submodule named like a lazy attribute would replace it)."""
    import importlib
    import pkgutil

    import foldcore

    for info in pkgutil.iter_modules(foldcore.__path__):
        importlib.import_module(f"foldcore.{info.name}")
    assert callable(foldcore.thicken) and callable(foldcore.read)
    assert isinstance(foldcore.Simulation, type)


WAIT_POLICY_PROBE = """
import ctypes, json
import foldcore
gomp_before = any("libgomp" in line for line in open("/proc/self/maps"))
from foldcore import Simulation, patterns, thicken
p = patterns.miura_one_crease(4, 4, a=20.0, b=20.0, width=0.6)
Simulation(thicken(p, 0.2), p, solver="paper", threads=2).run(max_iterations=3)
ctypes.CDLL("libgomp.so.1").omp_display_env(1)    # verbose, to the process's stderr
print(json.dumps({"gomp_before": gomp_before}))
"""


def _gomp_spin_count(env: dict) -> tuple:
    """(libgomp loaded by ``import foldcore``?, the spin count libgomp runs with)."""
    proc = _run(WAIT_POLICY_PROBE, env)
    spins = [int(line.split("=", 1)[1].strip().strip("'")) for line in proc.stderr.splitlines()
             if line.strip().startswith("GOMP_SPINCOUNT")]
    return _last_json(proc)["gomp_before"], spins


def test_openmp_threads_wait_passively_unless_the_user_chose():
    """``import foldcore`` sets OMP_WAIT_POLICY=PASSIVE before anything loads GNU
    OpenMP, and the libgomp a simulation runs on took it: its own report shows
    no spinning (GOMP_SPINCOUNT 0; unset, 300 000 polls). A value the user set
    is kept (ACTIVE: far more). Why: ``bench/load.py``."""
    env = {k: v for k, v in os.environ.items()
           if k not in ("OMP_WAIT_POLICY", "GOMP_SPINCOUNT")}
    assert _gomp_spin_count(env) == (False, [0])
    loaded_before, spins = _gomp_spin_count({**env, "OMP_WAIT_POLICY": "ACTIVE"})
    assert not loaded_before and spins and spins[0] > 300_000
