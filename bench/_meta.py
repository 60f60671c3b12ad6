"""Machine description shared by the benchmarks' JSON ``meta`` blocks (not a benchmark)."""
from __future__ import annotations

import os
import platform


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


def machine_meta() -> dict:
    """CPU model, core count, numba threads, Python/numba versions, solver backend."""
    import numba

    from foldcore.linsolve import cholmod_available

    return {"machine": cpu_model(), "cpus": os.cpu_count(),
            "numba_threads": numba.get_num_threads(), "python": platform.python_version(),
            "numba": numba.__version__, "backend": "cholmod" if cholmod_available() else "scipy"}
