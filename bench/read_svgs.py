"""Every SVG of a folder through the SVG reader (issue 19, item 2): read or refused, why.

For a folder of crease patterns drawn elsewhere — Origami Simulator's
``assets/`` (``fetch`` amandaghassaei/OrigamiSimulator, then ``git show`` its
SVGs into a folder, path separators as ``__``) — each file is read with
:func:`foldcore.io.read` and sorted into: read (vertices, edges, seconds), or
refused, grouped by the message's kind (curved segment, cut, overlapping
types, not connected, boundary/faces, other), or crashed (any other
exception: the reader's bug). Writes bench/results/read_svgs.json.

Run: ``.venv/bin/python bench/read_svgs.py DIR``.
"""
from __future__ import annotations

import collections
import json
import sys
import time
import warnings
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
KINDS = (("curved", "curved"), ("cut", "is a cut"), ("overlap", "overlap with different"),
         ("not connected", "not connected"), ("boundary/faces", "boundary"),
         ("boundary/faces", "both sides"), ("dangling", "dangling"),
         ("not an SVG", "not a readable SVG"))


def kind(message: str) -> str:
    return next((k for k, needle in KINDS if needle in message), "other")


def main(folder: str) -> None:
    from foldcore.errors import FoldcoreError
    from foldcore.io import read

    files, counts = [], collections.Counter()
    for path in sorted(Path(folder).glob("*.svg")):
        start = time.perf_counter()
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            try:
                p = read(path)
                entry = {"read": True, "vertices": len(p.vertices), "edges": int(p.n_edges)}
                counts["read"] += 1
            except FoldcoreError as exc:
                message = str(exc).split(": ", 1)[-1]
                entry = {"read": False, "kind": kind(message), "message": message}
                counts["refused: " + entry["kind"]] += 1
            except Exception as exc:  # a crash is the reader's bug: counted, shown
                entry = {"read": False, "kind": "crash", "message": repr(exc)}
                counts["crash"] += 1
        entry.update(file=path.name, seconds=time.perf_counter() - start)
        files.append(entry)
    out = {"folder": str(folder), "files": len(files), "counts": dict(counts), "each": files}
    (ROOT / "bench" / "results" / "read_svgs.json").write_text(json.dumps(out, indent=1))
    print(json.dumps(dict(counts), indent=1))


if __name__ == "__main__":
    main(sys.argv[1])
