"""Run every benchmark of bench/, each in its own process (results in bench/results/).

    python bench/run.py            # all of them, full
    python bench/run.py --quick    # small sizes, few runs (results in a temp folder)
    python bench/run.py accuracy paths --quick   # some of them

A benchmark that fails is reported and the others still run; the exit status
is 1 if any failed. docs/benchmarks.md says what each one measures.
"""
from __future__ import annotations

import argparse
import subprocess
import sys
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
BENCHMARKS = ("startup", "scaling", "time_to_solution", "convergence", "accuracy",
              "real_patterns", "paths", "load", "reading", "origami_simulator", "flat_vertex",
              "contact", "study")


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("names", nargs="*", metavar="NAME",
                        help=f"benchmarks to run (default all: {', '.join(BENCHMARKS)})")
    parser.add_argument("--quick", action="store_true", help="each with --quick")
    args = parser.parse_args()
    unknown = sorted(set(args.names) - set(BENCHMARKS))
    if unknown:
        parser.error(f"unknown benchmark(s) {', '.join(unknown)}")
    failed = []
    for name in args.names or BENCHMARKS:
        extra = ["--quick"] if args.quick else []
        runs = [[name, *extra]] + ([[name, "--elastic", *extra]] if name == "real_patterns"
                                   else [])
        for argv in runs:
            print(f"== {' '.join(argv)}", flush=True)
            start = time.perf_counter()
            done = subprocess.run([sys.executable, str(HERE / f"{argv[0]}.py"), *argv[1:]])
            print(f"== {' '.join(argv)}: {'ok' if done.returncode == 0 else 'FAILED'} "
                  f"in {time.perf_counter() - start:.0f} s", flush=True)
            if done.returncode:
                failed.append(" ".join(argv))
    if failed:
        print("failed: " + ", ".join(failed))
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
