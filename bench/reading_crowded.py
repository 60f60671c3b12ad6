"""Twin-vertex refusal at 10⁶ vertices before/after the crowded-vertex pair test.

One-off companion of ``bench/reading.py`` (same inputs and child process,
``reading.run_child``): the 1000 × 1000 grid, valid and with a twin of vertex
0, read by two source trees interleaved run by run (warm-up + 3 runs each,
median). Writes bench/results/reading_crowded.json.

Run: ``.venv/bin/python bench/reading_crowded.py BEFORE_SRC [--inputs DIR]``.
"""
from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))

import reading  # noqa: E402
from _meta import machine_meta  # noqa: E402


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("before", type=Path)
    parser.add_argument("--inputs", type=Path, default=Path("/tmp/foldcore-reading"))
    args = parser.parse_args()
    args.inputs.mkdir(parents=True, exist_ok=True)
    trees = {"before": args.before.resolve(), "after": reading.ROOT / "src"}
    rows = []
    for row in reading.write_inputs(args.inputs, [1000]):
        if row["format"] != "fold" or row["case"] == "cross":
            continue
        runs = {name: [] for name in trees}
        for k in range(reading.RUNS + 1):  # the first round is the warm-up
            for name, src in trees.items():
                r = reading.run_child(src, "fold", row["path"])
                if k:
                    runs[name].append(r)
        result = {name: reading.summary(r) for name, r in runs.items()}
        print(row["case"], {n: (round(r["seconds"], 2), r["others_busy"]) for n, r in
                            result.items()}, flush=True)
        rows.append({k: v for k, v in row.items() if k != "path"} | result)
    out = {"meta": {**machine_meta(), "date": time.strftime("%Y-%m-%d"),
                    "before": str(args.before), "runs": reading.RUNS}, "rows": rows}
    (HERE / "results" / "reading_crowded.json").write_text(json.dumps(out, indent=1))


if __name__ == "__main__":
    main()
