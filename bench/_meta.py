"""What every benchmark in bench/ shares (not a benchmark itself).

* the command line: ``--quick`` (small sizes, few runs, results in a temporary
  folder so the committed ones stay), ``--out DIR``, ``--table``;
* the machine (CPU model, cores, caches, virtual or not) and its load
  (``os.getloadavg`` before and after, the share of the cores other
  processes used), recorded in each JSON's ``meta`` block beside the command;
* warm-up, repeated runs, interleaved rounds of the runs that are compared,
  and the median;
* JSON, PNG and Markdown-table writing.

Benchmarks use foldcore's public API only (``foldcore.simulate``,
``foldcore.Simulation``, ``foldcore.thicken``, ``foldcore.patterns``,
``foldcore.read``, ``foldcore.kinematics``, the ``foldcore`` command line).
"""
from __future__ import annotations

import argparse
import glob
import importlib.util
import json
import os
import platform
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
RESULTS = ROOT / "bench" / "results"
QUICK_RESULTS = Path(tempfile.gettempdir()) / "foldcore-bench-quick"


# ------------------------------------------------------------------ command line
def parser(doc: str) -> argparse.ArgumentParser:
    """An argument parser with the options every benchmark has (see the module docstring)."""
    p = argparse.ArgumentParser(description=doc.strip().splitlines()[0])
    p.add_argument("--quick", action="store_true",
                   help="small sizes and few runs (well under a minute); writes to "
                        f"{QUICK_RESULTS}, not bench/results/")
    p.add_argument("--out", type=Path, default=None,
                   help="folder for the JSON and PNG (default bench/results/, with --quick "
                        f"{QUICK_RESULTS})")
    p.add_argument("--table", action="store_true",
                   help="print the Markdown table of docs/benchmarks.md from the stored JSON")
    p.add_argument("--plot", action="store_true", help="redraw the PNG from the stored JSON")
    return p


def output_dir(args) -> Path:
    """Where a run writes its JSON and PNG (created)."""
    out = args.out or (QUICK_RESULTS if args.quick else RESULTS)
    out.mkdir(parents=True, exist_ok=True)
    return out


def load_json(name: str, args=None) -> dict:
    """The stored ``name``.json (bench/results/, or ``--out`` when given)."""
    folder = args.out if args is not None and args.out is not None else RESULTS
    return json.loads((folder / f"{name}.json").read_text())


def stored(name: str, args, table=None, plot=None) -> bool:
    """``--table`` / ``--plot``: print the table of, or redraw the PNG of, the stored
    ``name``.json; returns whether one was asked for (then there is nothing to run)."""
    if not (args.table or args.plot):
        return False
    data = load_json(name, args)
    if args.table and table is not None:
        print(table(data))
        print(f"\n{machine_line(meta_of(data))}")
    if args.plot and plot is not None:
        path = (args.out or RESULTS) / f"{name}.png"
        plot(data, path)
        print(f"wrote {path}")
    return True


# ------------------------------------------------------------------ machine and load
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


def virtual_machine() -> bool:
    """Whether the CPU flags say a hypervisor runs this machine (Linux)."""
    try:
        with open("/proc/cpuinfo") as fh:
            return any(line.startswith("flags") and " hypervisor" in line for line in fh)
    except OSError:
        return False


def cpu_caches() -> dict:
    """Data/unified cache sizes of CPU 0 by level, e.g. {"L2": "2048K"} (Linux sysfs).

    Recorded because the memory-bound solve's speed follows the host's caches
    and memory while the compute-bound projection's does not: results are
    compared on the caches they ran on.
    """
    caches = {}
    for index in sorted(glob.glob("/sys/devices/system/cpu/cpu0/cache/index*")):
        try:
            kind, level, size = (Path(index, name).read_text().strip()
                                 for name in ("type", "level", "size"))
        except OSError:
            continue
        if kind != "Instruction":
            caches[f"L{level}"] = size
    return caches


def machine() -> dict:
    """CPU model, cores, architecture, caches, numba threads, versions, linear solver."""
    import numba

    return {"machine": cpu_model(), "cpus": os.cpu_count(), "arch": platform.machine(),
            "virtual": virtual_machine(), "caches": cpu_caches(),
            "numba_threads": numba.get_num_threads(), "python": platform.python_version(),
            "numba": numba.__version__,
            "backend": "cholmod" if importlib.util.find_spec("sksparse") else "scipy"}


def busy_seconds() -> float:
    """CPU seconds the whole machine spent busy since boot (/proc/stat, all cores)."""
    with open("/proc/stat") as fh:
        fields = [float(v) for v in fh.readline().split()[1:]]
    idle = fields[3] + fields[4]  # idle + iowait
    return (sum(fields[:8]) - idle) / os.sysconf("SC_CLK_TCK")


def others_busy(seconds: float = 2.0) -> float:
    """Share of all cores busy over ``seconds`` while this process sleeps."""
    b0, t0 = busy_seconds(), time.perf_counter()
    time.sleep(seconds)
    return (busy_seconds() - b0) / ((time.perf_counter() - t0) * os.cpu_count())


def wait_for_quiet(below: float = 0.25, patience_s: float = 300.0) -> float:
    """Wait (up to ``patience_s``) until other jobs use < ``below`` of the cores;
    returns the last share measured."""
    deadline = time.perf_counter() + patience_s
    busy = others_busy(min(2.0, max(patience_s, 0.5)))
    while busy > below and time.perf_counter() < deadline:
        busy = others_busy(5.0)
    return busy


class Record:
    """The ``meta`` block of one benchmark run: machine, load before/after, the
    command, ``quick`` and the run's settings; writes the JSON and the PNG."""

    def __init__(self, name: str, args, **settings):
        self.name, self.out = name, output_dir(args)
        self.meta = {**machine(), "load_before": list(os.getloadavg()),
                     "command": " ".join(["python", *sys.argv]).replace(str(ROOT) + "/", ""),
                     "quick": bool(args.quick), **settings}

    def write(self, data: dict, plot=None, indent: int | None = 1) -> Path:
        """``{"meta": ..., **data}`` as NAME.json (``indent`` None: compact, for long
        curves), then ``plot(json_dict, NAME.png)``."""
        self.meta["load_after"] = list(os.getloadavg())
        path = self.out / f"{self.name}.json"
        document = {"meta": self.meta, **data}
        path.write_text(json.dumps(document, indent=indent))
        if plot is not None:
            plot(document, path.with_suffix(".png"))
        print(f"wrote {path}" + (f" and {path.with_suffix('.png').name}" if plot else ""),
              flush=True)
        return path


def meta_of(data: dict) -> dict:
    """The machine and load block of a stored JSON (``meta``; older files of some
    benchmarks kept it as a top-level ``machine``)."""
    meta = data.get("meta")
    if isinstance(meta, dict) and "cpus" in meta:
        return meta
    return {**data.get("machine", {}), "load_before": data.get("load_before"),
            "load_after": data.get("load_after")}


def machine_line(meta: dict) -> str:
    """One line for a table's caption: cores, architecture, virtual or not (no vendor)."""
    arch = {"x86_64": "x86-64", "aarch64": "arm64"}.get(meta.get("arch", "x86_64"),
                                                         meta.get("arch"))
    kind = "virtual machine" if meta.get("virtual", True) else "machine"
    return f"machine: {meta.get('cpus', '?')}-core {arch} {kind}"


# ------------------------------------------------------------------ runs and medians
def repeat(run, runs: int, warmup: int = 1) -> list:
    """``runs`` results of ``run()`` after ``warmup`` discarded calls."""
    for _ in range(warmup):
        run()
    return [run() for _ in range(runs)]


def interleaved(cases: dict, runs: int, warmup: int = 1) -> dict:
    """Results of every case's callable, run in rounds (one call of each per round, so a
    change of the machine's load hits them alike), after ``warmup`` discarded rounds."""
    out = {name: [] for name in cases}
    for i in range(warmup + runs):
        for name, run in cases.items():
            result = run()
            if i >= warmup:
                out[name].append(result)
    return out


def timed(run):
    """(wall seconds, value) of ``run()``."""
    start = time.perf_counter()
    value = run()
    return time.perf_counter() - start, value


def cli_seconds(args: list, limit_s: float | None = None, check: bool = False) -> float | None:
    """Wall seconds of the whole ``python -m foldcore *args`` process (start-up, reading
    and writing included), run in a temporary folder; None past ``limit_s``. With
    ``check`` a failed run raises SystemExit with its last line of stderr."""
    with tempfile.TemporaryDirectory() as tmp:
        start = time.perf_counter()
        try:
            proc = subprocess.run([sys.executable, "-m", "foldcore", *map(str, args)],
                                  cwd=tmp, capture_output=True, text=True, check=False,
                                  timeout=limit_s)
        except subprocess.TimeoutExpired:
            return None
        seconds = time.perf_counter() - start
    if check and proc.returncode != 0:
        last = (proc.stderr.strip().splitlines() or ["(no message)"])[-1]
        raise SystemExit(f"foldcore {' '.join(map(str, args))}: exit {proc.returncode}: {last}")
    return seconds


def median(values) -> float:
    return float(statistics.median(values))


def median_run(rows: list, key: str = "seconds") -> dict:
    """Copy of the run of median ``key`` among ``rows`` (dicts), its ``key`` the median
    and ``key + "_runs"`` every run's."""
    times = [r[key] for r in rows]
    row = dict(sorted(rows, key=lambda r: r[key])[len(rows) // 2])
    row.update({key: statistics.median(times), key + "_runs": times})
    return row


# ------------------------------------------------------------------ output
def sig(value: float, digits: int = 3) -> str:
    """``value`` to ``digits`` significant digits, without an exponent from 1 to 10⁶."""
    text = f"{value:.{digits}g}"
    return f"{value:,.0f}" if "e" in text and 1 <= abs(value) < 1e6 else text


def markdown_table(header: list, rows: list) -> str:
    """A Markdown table from a header row and rows of cell strings."""
    lines = ["| " + " | ".join(header) + " |", "|" + "---|" * len(header)]
    return "\n".join(lines + ["| " + " | ".join(map(str, row)) + " |" for row in rows])


def pyplot():
    """matplotlib.pyplot on the Agg backend (no display)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def save(fig, path: Path, dpi: int = 110) -> None:
    """Write ``fig`` as PNG and close it."""
    fig.tight_layout()
    fig.savefig(path, dpi=dpi)
    pyplot().close(fig)
