"""Machine description shared by the benchmarks' JSON ``meta`` blocks (not a benchmark)."""
from __future__ import annotations

import glob
import os
import platform
import statistics


def cpu_model() -> str:
    """CPU model name from /proc/cpuinfo (Linux), else what ``platform`` knows."""
    try:
        with open("/proc/cpuinfo") as fh:
            for line in fh:
                if line.startswith("model name"):
                    return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor() or platform.machine()


def cpu_caches() -> dict:
    """Data/unified cache sizes of CPU 0 by level, e.g. {"L2": "2048K"} (Linux sysfs).

    Recorded because the memory-bound solve's speed changes between sessions
    of this shared virtual machine while the compute-bound projection's does
    not (the same code: 50 × 50 bare solve 9.3 ms in the stop-14 run,
    4.6–6.2 ms on 2026-11-25; another host or a quieter one, the guest cannot
    tell which), so results are compared on the caches they ran on.
    """
    caches = {}
    for index in sorted(glob.glob("/sys/devices/system/cpu/cpu0/cache/index*")):
        try:
            with open(f"{index}/type") as fh:
                kind = fh.read().strip()
            with open(f"{index}/level") as fh:
                level = fh.read().strip()
            with open(f"{index}/size") as fh:
                size = fh.read().strip()
        except OSError:
            continue
        if kind != "Instruction":
            caches[f"L{level}"] = size
    return caches


def machine_meta() -> dict:
    """CPU model and caches, core count, numba threads, Python/numba versions, backend."""
    import numba

    from foldcore.linsolve import cholmod_available

    return {"machine": cpu_model(), "caches": cpu_caches(), "cpus": os.cpu_count(),
            "numba_threads": numba.get_num_threads(), "python": platform.python_version(),
            "numba": numba.__version__, "backend": "cholmod" if cholmod_available() else "scipy"}


def markdown_table(header: list, rows: list) -> str:
    """A Markdown table (the README's) from a header row and rows of cell strings."""
    lines = ["| " + " | ".join(header) + " |", "|" + "---|" * len(header)]
    return "\n".join(lines + ["| " + " | ".join(row) + " |" for row in rows])


def median_run(rows: list) -> dict:
    """Copy of the run of median wall time among ``rows`` (dicts with "seconds"), its
    "seconds" the median and "seconds_runs" every run's."""
    times = [r["seconds"] for r in rows]
    row = dict(sorted(rows, key=lambda r: r["seconds"])[len(rows) // 2])
    row.update(seconds=statistics.median(times), seconds_runs=times)
    return row
