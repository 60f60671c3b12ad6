"""Fuzz the readers and the command line with corrupted inputs (a dev tool).

Readers (in-process, the public ones): FOLD (``foldcore.io.read_fold_file``,
what ``foldcore simulate`` reads), OBJ, STL (ASCII and binary) and hinge
files (``foldcore.read``) and result files
(``foldcore.result_file.read_result``), each corrupted 1–3 times by plain
random mutations (fixed seed) of real files: the hinge scene and a degree-4
vertex (their result files written by ``foldcore simulate -o``). Counted per
reader: accepted, refused (a FoldcoreError), unhandled (any other
exception, by type), hangs (longer than ``--case-seconds``, SIGALRM),
multi-line refusals and refusals not naming the file.

CLI (subprocesses): ``simulate`` on corrupted FOLD and OBJ patterns (small
iteration budget), ``render`` and ``export`` on corrupted result files,
each in a fresh output folder. Counted: exit codes other than 0 and 2,
tracebacks on stderr, hangs (``--process-seconds``), refusals of more than
one line, leftovers (after a refusal any file in the folder; after any exit
a temporary file).

Run: ``python tools/fuzz.py`` (a few minutes: READER_CASES per reader,
CLI_CASES per command) or ``--long`` (the recorded run: 5 000 per reader, 15
per command, ~4 min on 2 cores; writes tools/results/fuzz.json);
``--reader-cases N``, ``--cli-cases N``, ``--out FILE`` set them. Exits 1 if
anything unhandled, hung, left over or refused in more than one line.
"""
from __future__ import annotations

import argparse
import copy
import json
import os
import random
import signal
import struct
import subprocess
import sys
import tempfile
import time
import warnings
from collections import Counter
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
RESULTS = ROOT / "tools" / "results"
READER_CASES, CLI_CASES = 500, 5
LONG_READER_CASES, LONG_CLI_CASES = 5000, 15
NASTY = [float("nan"), float("inf"), -float("inf"), 1e308, -1e308, 5e-324, 1e-300, 1e300,
         0.0, -0.0, -1.0, 10 ** 400, -(2 ** 63), 2 ** 64, True, False, None, "", "x", "1",
         [], {}, [[]], [None], [1, 2, 3], {"a": [1]}, 0.5, 180.0, 360.0, 3, -3]
TOKENS = ["nan", "inf", "-inf", "1e308", "-1e308", "5e-324", "1e-300", "0", "-0", "-1",
          "1e999", "x", "", "#", "v", "f", "M", "V", "B", "F", "U", "auto", "max=0",
          "max=181", "999999999999999999999", "1/2/3", "0x10", "\u00b5", "\x00"]


class Hang(Exception):
    pass


def _alarm(signum, frame):
    raise Hang()


# ------------------------------------------------------------------ mutations
def mutate_json(rng: random.Random, d):
    """One random corruption of a JSON value, in place where possible; returns it."""
    if isinstance(d, dict) and d and rng.random() < 0.8:
        key = rng.choice(sorted(d))
        how = rng.randrange(4)
        if how == 0:
            del d[key]
        elif how == 1:
            d[key] = copy.deepcopy(rng.choice(NASTY))
        else:
            d[key] = mutate_json(rng, d[key])
        return d
    if isinstance(d, list) and d and rng.random() < 0.85:
        i = rng.randrange(len(d))
        how = rng.randrange(6)
        if how == 0:
            return d[:i]
        if how == 1:
            return d + [copy.deepcopy(d[i])]
        if how == 2:
            return [d] if rng.random() < 0.5 else [[x] for x in d]
        d[i] = mutate_json(rng, d[i])
        return d
    if isinstance(d, float) and rng.random() < 0.5:
        return d * rng.choice([1e-300, 1e-9, -1.0, 1.001, 1e9, 1e300])
    return copy.deepcopy(rng.choice(NASTY))


def mutate_text(rng: random.Random, text: str) -> str:
    """One random corruption of a line-based text file."""
    lines = text.split("\n")
    i = rng.randrange(len(lines))
    how = rng.randrange(6)
    if how == 0:
        del lines[i]
    elif how == 1:
        lines.insert(i, lines[rng.randrange(len(lines))])
    elif how == 2:
        tokens = lines[i].split() or [""]
        tokens[rng.randrange(len(tokens))] = rng.choice(TOKENS)
        lines[i] = " ".join(tokens)
    elif how == 3:
        lines[i] = lines[i] + " " + rng.choice(TOKENS)
    elif how == 4:
        return text[:rng.randrange(len(text) + 1)]
    else:
        lines[i] = "".join(chr(rng.randrange(1, 0x2FF)) for _ in range(rng.randrange(1, 12)))
    return "\n".join(lines)


def mutate_bytes(rng: random.Random, data: bytes) -> bytes:
    """One random corruption of a binary file: bytes flipped, cut or appended."""
    b = bytearray(data)
    how = rng.randrange(3)
    if how == 0 and b:
        for _ in range(rng.randrange(1, 8)):
            b[rng.randrange(len(b))] = rng.randrange(256)
    elif how == 1:
        del b[rng.randrange(len(b) + 1):]
    else:
        b += bytes(rng.randrange(256) for _ in range(rng.randrange(1, 60)))
    return bytes(b)


def json_bytes(d) -> bytes:
    try:
        return json.dumps(d).encode("utf-8", "surrogatepass")
    except (TypeError, ValueError, RecursionError):
        return b"{}"


# ------------------------------------------------------------------ base files
def base_files(folder: Path) -> dict:
    """Real files of the hinge scene and a degree-4 vertex; result files by simulate -o."""
    from foldcore import patterns, write_fold
    from foldcore.io import write_hinges, write_obj

    scenes = {"hinge": (patterns.single_hinge(panel_length=5.0, depth=2.0, angle=90.0,
                                              width=2.0), "4"),
              "d4": (patterns.degree4_vertex(radius=20.0, widths=[2.0] * 4, mode="A",
                                             rho1=60.0), "2")}
    out = {"fold": [], "obj": [], "hinges": [], "stl_ascii": [], "stl_binary": [],
           "result": []}
    for name, (p, k) in scenes.items():
        write_fold(folder / f"{name}.fold", p, thickness=1.0)
        write_obj(folder / f"{name}.obj", p)
        write_hinges(folder / f"{name}.hinges", p)
        subprocess.run([sys.executable, "-m", "foldcore", "simulate", str(folder / f"{name}.fold"),
                        "-o", str(folder / f"{name}.result.fold"), "--subdivisions", k,
                        "--max-iterations", "30"], env=child_env(), capture_output=True,
                       check=True)
        out["fold"].append(json.loads((folder / f"{name}.fold").read_text()))
        out["result"].append(json.loads((folder / f"{name}.result.fold").read_text()))
        out["obj"].append((folder / f"{name}.obj").read_text())
        out["hinges"].append(((folder / f"{name}.obj").read_text(),
                              (folder / f"{name}.hinges").read_text()))
        v = p.vertices.tolist()
        tris = [[v[f[0]], v[f[j]], v[f[j + 1]]] for f in p.faces for j in range(1, len(f) - 1)]
        out["stl_ascii"].append(_ascii_stl(tris))
        out["stl_binary"].append(_binary_stl(tris))
        out[f"hinges_of_stl_{name}"] = _stl_hinges(tris)
    return out


def child_env() -> dict:
    """This environment with the project's src/ first on PYTHONPATH."""
    return {**os.environ, "PYTHONPATH": str(ROOT / "src")}


def _stl_hinges(tris) -> str:
    """A hinge file for a triangulated sheet: every interior edge a flat crease, numbered
    as hinge files number a mesh's edges (unique face sides in order of first
    appearance; the STL's vertices are its float32 coordinates)."""
    first, sides = {}, Counter()
    for t in tris:
        corners = [tuple(struct.unpack("<2f", struct.pack("<2f", *xy))) for xy in t]
        for a, b in zip(corners, corners[1:] + corners[:1]):
            key = tuple(sorted((a, b)))
            first.setdefault(key, len(first))
            sides[key] += 1
    return "".join(f"{e} auto F\n" for key, e in first.items() if sides[key] == 2)


def _ascii_stl(tris) -> str:
    body = "".join("facet normal 0 0 1\nouter loop\n" + "".join(
        f"vertex {x!r} {y!r} 0\n" for x, y in t) + "endloop\nendfacet\n" for t in tris)
    return f"solid s\n{body}endsolid s\n"


def _binary_stl(tris) -> bytes:
    records = b"".join(struct.pack("<12fH", 0, 0, 1,
                                   *[c for x, y in t for c in (x, y, 0.0)], 0) for t in tris)
    return b"\0" * 80 + struct.pack("<I", len(tris)) + records


def generated(kind: str, bases: dict, rng: random.Random):
    """(file name -> bytes) of one corrupted input of ``kind``."""
    n = rng.randint(1, 3)
    if kind in ("fold", "result"):
        d = copy.deepcopy(rng.choice(bases[kind]))
        for _ in range(n):
            if kind == "result" and rng.random() < 0.6 and isinstance(d, dict) \
                    and isinstance(d.get("file_frames"), list) and d["file_frames"]:
                d["file_frames"][-1] = mutate_json(rng, d["file_frames"][-1])
            else:
                d = mutate_json(rng, d)
        return {f"in.{'result.' if kind == 'result' else ''}fold": json_bytes(d)}
    if kind == "obj":
        i = rng.randrange(len(bases["obj"]))
        text = bases["obj"][i]
        for _ in range(n):
            text = mutate_text(rng, text)
        return {"in.obj": text.encode("utf-8", "surrogatepass"),
                "in.hinges": bases["hinges"][i][1].encode()}
    if kind == "hinges":
        obj, text = rng.choice(bases["hinges"])
        for _ in range(n):
            text = mutate_text(rng, text)
        return {"in.obj": obj.encode(), "in.hinges": text.encode("utf-8", "surrogatepass")}
    i = rng.randrange(2)
    hinges = bases[f"hinges_of_stl_{['hinge', 'd4'][i]}"].encode()
    if kind == "stl_ascii":
        text = bases["stl_ascii"][i]
        for _ in range(n):
            text = mutate_text(rng, text)
        return {"in.stl": text.encode("utf-8", "surrogatepass"), "in.hinges": hinges}
    data = bases["stl_binary"][i]
    for _ in range(n):
        data = mutate_bytes(rng, data)
    return {"in.stl": data, "in.hinges": hinges}


# ------------------------------------------------------------------ readers
def read(kind: str, folder: Path):
    import foldcore
    from foldcore.result_file import read_result
    from foldcore.io import read_fold_file

    if kind == "fold":
        return read_fold_file(folder / "in.fold")
    if kind == "result":
        return read_result(folder / "in.result.fold")
    mesh = "in.obj" if kind in ("obj", "hinges") else "in.stl"
    return foldcore.read(folder / mesh, hinges=folder / "in.hinges")


def fuzz_reader(kind: str, bases: dict, cases: int, seed: int, seconds: int) -> dict:
    from foldcore import FoldcoreError

    rng = random.Random(seed)
    counts = Counter()
    unhandled = Counter()
    first = {}
    signal.signal(signal.SIGALRM, _alarm)
    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp)
        for case in range(cases):
            files = generated(kind, bases, rng)
            for name, data in files.items():
                (folder / name).write_bytes(data)
            signal.alarm(seconds)
            try:
                with warnings.catch_warnings():
                    warnings.simplefilter("ignore")
                    read(kind, folder)
                counts["accepted"] += 1
            except Hang:
                counts["hangs"] += 1
            except FoldcoreError as exc:
                counts["refused"] += 1
                message = str(exc)
                if "\n" in message:
                    counts["multi_line"] += 1
                if str(folder) not in message:
                    counts["not_naming_the_file"] += 1
                    first.setdefault("not_naming_the_file", message[:200])
            except Exception as exc:  # noqa: BLE001  (counted, the point of the bench)
                unhandled[type(exc).__name__] += 1
                first.setdefault(type(exc).__name__, f"case {case}: {str(exc)[:200]}")
            finally:
                signal.alarm(0)
            for name in files:
                os.unlink(folder / name)
    return {"cases": cases, **{k: counts[k] for k in ("accepted", "refused", "hangs",
                                                        "multi_line", "not_naming_the_file")},
            "unhandled": sum(unhandled.values()), "unhandled_by_type": dict(unhandled),
            "first_messages": first}


# ------------------------------------------------------------------ CLI
def cli_command(kind: str, folder: Path) -> list:
    if kind == "simulate_fold":
        return ["simulate", "in.fold", "-o", "out/o.fold", "--report", "out/r.json",
                "--max-iterations", "20"]
    if kind == "simulate_obj":
        return ["simulate", "in.obj", "--hinges", "in.hinges", "--thickness", "1",
                "-o", "out/o.fold", "--report", "out/r.json", "--max-iterations", "20"]
    if kind == "render":
        return ["render", "in.result.fold", "-o", "out/o.png", "--size", "64x48"]
    return ["export", "in.result.fold", "--svg", "out/o.svg", "--stl", "out/o.stl"]


def fuzz_cli(kind: str, bases: dict, cases: int, seed: int, seconds: int) -> dict:
    rng = random.Random(seed)
    source = {"simulate_fold": "fold", "simulate_obj": "obj"}.get(kind, "result")
    counts = Counter()
    first = {}
    env = child_env()
    for case in range(cases):
        with tempfile.TemporaryDirectory() as tmp:
            folder = Path(tmp)
            (folder / "out").mkdir()
            for name, data in generated(source, bases, rng).items():
                (folder / name).write_bytes(data)
            try:
                run = subprocess.run([sys.executable, "-m", "foldcore", *cli_command(kind, folder)],
                                     cwd=folder, env=env, capture_output=True, text=True,
                                     timeout=seconds)
            except subprocess.TimeoutExpired:
                counts["hangs"] += 1
                continue
            left = sorted(os.listdir(folder / "out"))
            counts[f"exit_{run.returncode}"] += 1
            if run.returncode not in (0, 2):
                counts["bad_exit"] += 1
                first.setdefault("bad_exit", run.stderr[-300:])
            if "Traceback" in run.stderr:
                counts["tracebacks"] += 1
                first.setdefault("traceback", run.stderr[-300:])
            if run.returncode == 2:
                errors = [ln for ln in run.stderr.splitlines() if not ln.startswith(
                    ("foldcore: warning", "  warnings.warn")) and "Warning" not in ln]
                if len(errors) != 1:
                    counts["multi_line"] += 1
                    first.setdefault("multi_line", run.stderr[-300:])
                if left:
                    counts["leftovers"] += 1
                    first.setdefault("leftovers", f"{left}: {run.stderr[-200:]}")
            if any(n.endswith(".tmp") or n.startswith(".") for n in left):
                counts["temp_files"] += 1
    return {"cases": cases, "exit_0": counts["exit_0"], "exit_2": counts["exit_2"],
            **{k: counts[k] for k in ("bad_exit", "tracebacks", "hangs", "multi_line",
                                      "leftovers", "temp_files")},
            "first_messages": first}


def failures(data: dict) -> int:
    """Cases that broke a promise: unhandled, hung, multi-line, not naming the file,
    exit codes but 0/2, tracebacks, leftovers, temporary files."""
    keys = ("unhandled", "hangs", "multi_line", "not_naming_the_file", "bad_exit",
            "tracebacks", "leftovers", "temp_files")
    return sum(block.get(k, 0) for part in ("readers", "cli") for block in data[part].values()
               for k in keys)


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--long", action="store_true",
                        help=f"{LONG_READER_CASES} cases per reader, {LONG_CLI_CASES} per "
                             "command, written to tools/results/fuzz.json")
    parser.add_argument("--reader-cases", type=int, help=f"per reader (default {READER_CASES})")
    parser.add_argument("--cli-cases", type=int, help=f"per CLI command (default {CLI_CASES})")
    parser.add_argument("--seed", type=int, default=18)
    parser.add_argument("--case-seconds", type=int, default=20)
    parser.add_argument("--process-seconds", type=int, default=120)
    parser.add_argument("--out", type=Path, help="JSON written (default with --long: "
                                                 "tools/results/fuzz.json)")
    args = parser.parse_args(argv)
    reader_cases = args.reader_cases or (LONG_READER_CASES if args.long else READER_CASES)
    cli_cases = args.cli_cases or (LONG_CLI_CASES if args.long else CLI_CASES)
    out = args.out or (RESULTS / "fuzz.json" if args.long else None)
    sys.path.insert(0, str(ROOT / "bench"))
    import _meta

    start = time.perf_counter()
    with tempfile.TemporaryDirectory() as tmp:
        bases = base_files(Path(tmp))
    readers = {}
    for i, kind in enumerate(["fold", "obj", "stl_ascii", "stl_binary", "hinges", "result"]):
        t = time.perf_counter()
        readers[kind] = fuzz_reader(kind, bases, reader_cases, args.seed + i, args.case_seconds)
        readers[kind]["seconds"] = round(time.perf_counter() - t, 1)
        print(kind, {k: v for k, v in readers[kind].items() if k != "first_messages"},
              flush=True)
    cli = {}
    for i, kind in enumerate(["simulate_fold", "simulate_obj", "render", "export"]):
        t = time.perf_counter()
        cli[kind] = fuzz_cli(kind, bases, cli_cases, args.seed + 100 + i, args.process_seconds)
        cli[kind]["seconds"] = round(time.perf_counter() - t, 1)
        print(kind, {k: v for k, v in cli[kind].items() if k != "first_messages"}, flush=True)
    data = {"meta": {**_meta.machine(), "seed": args.seed, "case_seconds": args.case_seconds,
                     "process_seconds": args.process_seconds,
                     "seconds": round(time.perf_counter() - start, 1)},
            "readers": readers, "cli": cli}
    if out is not None:
        out.parent.mkdir(parents=True, exist_ok=True)
        out.write_text(json.dumps(data, indent=1))
        print("wrote", out)
    bad = failures(data)
    print(f"{bad} broken promises")
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
