"""Origami Simulator beside foldcore on its own Miura, folded flat, in one run.

Origami Simulator's ``Tessellations/miura-ori.svg`` folded flat (100 %), by
Origami Simulator and by foldcore, interleaved, ``ROUNDS`` rounds:

* **Origami Simulator** (Amanda Ghassaei, MIT licence; not part of this
  project: read from a snapshot of github.com/amandaghassaei/OrigamiSimulator,
  a bare git dir or a checkout, ``--origami-simulator``): its own page, served
  from 127.0.0.1, in Debian's headless Chromium with software WebGL
  (SwiftShader, the flags of tests/test_view.py), with a harness script
  added after its ``main.js`` (and the analytics script it loads from
  Google left out: no network). The page loads its demo ``Tessellations/miura-ori.svg`` (182
  nodes) with its default settings; ``load_seconds`` is the time from the
  page's navigation start to the model built (polled every 50 ms). The
  harness then pauses the app's own stepping, resets the solver to the flat
  sheet, sets the fold to 100 % and calls ``globals.model.step()`` (its
  per-frame work: ``numSteps`` = 100 solver steps and the read-back that
  gives the mean node strain shown as "global error") in one synchronous loop
  until the mean strain is below each of ``STRAINS`` (percent) or
  ``OS_LIMIT_S`` passes (a threshold counts once the strain has risen to the
  first one: the sheet starts flat and unstrained). The page gets no frame
  to draw inside the loop, so the times are the solver's. Time is
  ``performance.now()`` from the first step. At each threshold the node
  positions are taken, and the fold angle of every M/V crease is measured
  from them (Python side: the angle between the two triangles' normals)
  against its target (±180°).
* **foldcore, the file itself**: the same SVG read by foldcore's reader and
  folded as ``foldcore simulate miura-ori.svg --fold-percent 100`` folds it
  (no thickness: the thin sheet, defaults). In process, ``seconds`` is the
  sheet's building and its Newton steps (the reading is left out, as the
  page load is); its miss is the largest over the driven creases.
* **foldcore, the graded-width construction** (a second row, labelled as
  such): the same layout rebuilt in Python (Miura 12 × 13, a = b = 80 mm,
  γ = 84°; H = 0.01a, arc hinges of Eq. 7's width W = πH/2 graded along each
  straight line by ``patterns.miura_flat_widths`` — the widths that let a
  thick Miura fold flat:
  docs/architecture.md#a-thick-miura-has-no-flat-state-with-equal-hinges —
  every crease driven to its rigid-fold angle at facet tilt 90°, default
  strategy, tolerance 1e-9); ``seconds`` is ``Simulation(...).run()`` (the
  mesh is built once, outside the timing). Its misses: the largest on the
  straight and on the zig-zag creases (degrees).

Each foldcore row is also timed as the whole ``python -m foldcore simulate``
process (start-up, reading, building and writing the result included; the
graded pattern written as a FOLD with its widths and targets), against
Origami Simulator's page load plus its fold. Before the rounds, one fold of
each row in this process and one of each command warm the kernels and the
numba cache.

Reported per round: every time, the ratios (Origami Simulator / foldcore, at
the first threshold), Origami Simulator's steps, strain and angle error at
each threshold, and foldcore's iterations and misses; ``others_busy`` before
each run (share of the cores other processes used). Writes
bench/results/origami_simulator.json and .png (Origami Simulator's mean
strain against time, foldcore's fold times marked).

Run: ``python bench/origami_simulator.py [--origami-simulator PATH]`` (~1 min;
needs /usr/bin/chromium, which ``make test`` installs; skipped when either is
missing) or ``--quick`` (one round, the first threshold); ``--table`` prints
the table of docs/benchmarks.md from the JSON.
"""
from __future__ import annotations

import http.server
import json
import queue
import shutil
import subprocess
import tempfile
import threading
import time
from pathlib import Path

import numpy as np

import _meta

DEFAULT_SOURCE = Path("/work/.mirror/amandaghassaei+OrigamiSimulator/repo")
MODEL = "Tessellations/miura-ori.svg"
CHROMIUM = "/usr/bin/chromium"
FLAGS = ["--headless", "--no-sandbox", "--disable-gpu", "--enable-unsafe-swiftshader",
         "--use-angle=swiftshader", "--disable-background-networking",
         "--disable-component-update", "--disable-sync", "--no-first-run",
         "--disable-background-timer-throttling", "--disable-renderer-backgrounding",
         "--window-size=1280,800"]
ROUNDS = 3
STRAINS = (0.01, 0.001)  # mean node strain thresholds, percent
OS_LIMIT_S = 60.0        # Origami Simulator gives up after this long
QUICK = {"rounds": 1, "strains": STRAINS[:1], "limit_s": 30.0}
PAGE_TIMEOUT_S = 180.0
FOLDCORE_ROWS = {"file": "foldcore, the file itself (thin sheet, defaults)",
                 "graded": "foldcore, the graded-width construction (thick, arc hinges, "
                           "tolerance 1e-9)"}
N, M, A, GAMMA = 12, 13, 80.0, 84.0  # facets, mm, degrees
THICKNESS = 0.01 * A                 # mm
TOLERANCE, BUDGET = 1e-9, 5_000
HARNESS_PAGE = "foldcore_harness.html"
#: what the page needs: the app and every demo it ships (a snapshot may lack some
#: large files, e.g. a .fold demo: those are left out, see ``absent_files``)
PAGE_FILES = ("index.html", "favicon.ico", "js", "css", "dependencies", "fonts", "assets")

HARNESS_JS = """
(function () {
  var STRAINS = %(strains)s, LIMIT_S = %(limit)s;
  function post(result) {
    var xhr = new XMLHttpRequest();
    xhr.open("POST", "/result", true);
    xhr.send(JSON.stringify(result));
  }
  window.addEventListener("error", function (e) {
    post({error: String(e.message) + " at " + e.filename + ":" + e.lineno});
  });
  function built() {
    return typeof globals !== "undefined" && globals.model && globals.model.getNodes &&
      globals.model.getNodes().length > 0 && !globals.needsSync && !globals.simNeedsSync;
  }
  function creases() {
    return globals.model.getCreases().map(function (c) {
      return [c.edge.nodes[0].getIndex(), c.edge.nodes[1].getIndex(), c.node1.getIndex(),
              c.node2.getIndex(), c.targetTheta, c.type];
    });
  }
  function fold(loaded) {
    globals.simulationRunning = false;  // the harness steps the solver itself
    globals.model.reset();
    globals.setCreasePercent(1.0);
    globals.shouldChangeCreasePercent = true;
    var $error = document.getElementById("globalError");
    var steps = 0, log = [], reached = [], left = STRAINS.slice(), armed = false, t = 0;
    var t0 = performance.now();
    // one synchronous loop: the page gets no frame to draw until it ends
    while (left.length && t < LIMIT_S) {
      globals.model.step();
      steps += globals.numSteps;
      t = (performance.now() - t0) / 1000;
      var strain = parseFloat($error.textContent);
      log.push([steps, t, strain]);
      armed = armed || strain >= STRAINS[0];  // past the start, when the sheet is still flat
      while (armed && left.length && strain < left[0]) {
        reached.push({strain_below: left.shift(), seconds: t, steps: steps, strain: strain,
                      positions: Array.from(globals.model.getPositionsArray())});
      }
      if (!isFinite(strain)) break;
    }
    post({nodes: globals.model.getNodes().length, num_steps: globals.numSteps,
          load_seconds: loaded, creases: creases(), log: log, reached: reached,
          final_positions: Array.from(globals.model.getPositionsArray()),
          original: globals.model.getNodes().map(function (n) {
            var p = n.getOriginalPosition(); return [p.x, p.y, p.z]; }),
          user_agent: navigator.userAgent});
  }
  (function wait() {
    if (!built()) { setTimeout(wait, 50); return; }
    var loaded = performance.now() / 1000;  // from navigation start: the page and the model built
    setTimeout(function () { fold(loaded); }, 200);
  })();
})();
"""


def add_source_argument(parser) -> None:
    """``--origami-simulator PATH``: its snapshot (bare git dir or checkout), default
    ``DEFAULT_SOURCE``, for a benchmark that reads its files."""
    parser.add_argument("--origami-simulator", type=Path, default=DEFAULT_SOURCE,
                        help=f"Origami Simulator's snapshot (default {DEFAULT_SOURCE})")


def git(source: Path, *args: str, stdin: bytes | None = None) -> bytes:
    """Output of ``git --git-dir source args`` (raises on failure)."""
    return subprocess.run(["git", "--git-dir", str(source), *args], input=stdin,
                          capture_output=True, check=True).stdout


def absent_files(source: Path, paths=PAGE_FILES) -> list[str]:
    """Files under ``paths`` at HEAD of the bare git dir ``source`` whose content
    the snapshot lacks (a partial clone leaves out some large blobs)."""
    tree = git(source, "ls-tree", "-r", "-z", "HEAD", "--", *paths).decode()
    entries = [line.split("\t", 1) for line in tree.split("\0") if line]
    blobs = [(meta.split()[2], path) for meta, path in entries if meta.split()[1] == "blob"]
    check = git(source, "cat-file", "--batch-check=%(objectname) %(objecttype)",
                stdin="".join(f"{sha}\n" for sha, _ in blobs).encode()).decode().splitlines()
    return [path for (_, path), line in zip(blobs, check) if line.endswith(" missing")]


def extract(source: Path, into: Path) -> str:
    """Origami Simulator's files (``PAGE_FILES``, less ``absent_files``) from
    ``source`` (bare git dir or checkout) into ``into``; returns the commit (or
    "checkout")."""
    if (source / "index.html").exists():
        shutil.copytree(source, into, dirs_exist_ok=True)
        return "checkout"
    commit = git(source, "rev-parse", "HEAD").decode().strip()
    left_out = [f":(exclude){path}" for path in absent_files(source)]
    archive = git(source, "archive", "HEAD", "--", *PAGE_FILES, *left_out)
    subprocess.run(["tar", "-x", "-C", str(into)], input=archive, check=True)
    return commit


def page_with_script(root: Path, script: str, name: str = HARNESS_PAGE) -> None:
    """``name`` in ``root``: index.html without the script it loads from Google
    (its inline ``gtag`` stub, which the app calls, stays: it only queues), with
    ``script`` (JavaScript) after main.js."""
    html = (root / "index.html").read_text()
    start = html.index('<script async src="https://www.googletagmanager.com')
    end = html.index("</script>", start) + len("</script>")
    html = html[:start] + html[end:]
    anchor = '<script type="text/javascript" src="js/main.js"></script>'
    if anchor not in html:
        raise SystemExit("origami_simulator: index.html has no main.js script tag "
                         "(another Origami Simulator version?)")
    html = html.replace(anchor, anchor + "\n<script>" + script + "</script>")
    (root / name).write_text(html)


def harness_page(root: Path, strains, limit_s: float) -> None:
    """``HARNESS_PAGE`` in ``root``: the page with this benchmark's harness script
    (thresholds ``strains``, %, and ``limit_s``)."""
    page_with_script(root, HARNESS_JS % {"strains": json.dumps(list(strains)),
                                         "limit": limit_s})


class Server:
    """Static files of ``root`` on 127.0.0.1; the harness's POST lands in ``results``;
    a GET of a path in ``routes`` answers ``routes[path]()`` as JSON."""

    def __init__(self, root: Path, routes: dict | None = None):
        results: queue.Queue = queue.Queue()
        routes = routes or {}

        class Handler(http.server.SimpleHTTPRequestHandler):
            def __init__(self, *args, **kwargs):
                super().__init__(*args, directory=str(root), **kwargs)

            def do_GET(self):  # noqa: N802 (http.server's name)
                route = routes.get(self.path.split("?", 1)[0])
                if route is None:
                    super().do_GET()
                    return
                body = json.dumps(route()).encode()
                self.send_response(200)
                self.send_header("Content-Type", "application/json")
                self.send_header("Content-Length", str(len(body)))
                self.end_headers()
                self.wfile.write(body)

            def do_POST(self):  # noqa: N802 (http.server's name)
                body = self.rfile.read(int(self.headers["Content-Length"]))
                self.send_response(204)
                self.end_headers()
                results.put(json.loads(body))

            def log_message(self, *args):
                pass

        self.results = results
        self.httpd = http.server.ThreadingHTTPServer(("127.0.0.1", 0), Handler)
        self.port = self.httpd.server_address[1]
        threading.Thread(target=self.httpd.serve_forever, daemon=True).start()

    def close(self) -> None:
        self.httpd.shutdown()


def signed_fold_angles(creases, positions) -> np.ndarray:
    """(C,) fold angle in radians of each crease row ``[edge node 0, edge node 1,
    node 1, node 2, ...]`` (Origami Simulator's ``Crease``: nodes 1 and 2 are the
    triangles' tips on either side of the edge) at ``positions`` ((N, 3) or flat).

    Origami Simulator's own dihedral angle (its ``thetaCalc`` shader): atan2 of
    ((n1 × e) · n2, n1 · n2) with e the edge from node 0 to node 1 and n1, n2 the
    triangles' normals. The normals here are built from the nodes (n1 = e × (p − a),
    n2 = (q − a) × e), which turns both of a consistently oriented pair alike
    whichever side node 1 lies on, so the angle is the app's, sign included: its
    targets are FOLD's (valley positive), so is this. In (−π, π]: the app's own
    angle is unwrapped past ±π, a position cannot tell."""
    x = np.asarray(positions, dtype=float).reshape(-1, 3)
    c = np.asarray(creases, dtype=float)
    if c.size == 0:
        return np.zeros(0)
    a, b, p, q = (x[c[:, k].astype(int)] for k in range(4))
    e = b - a
    n1, n2 = np.cross(e, p - a), np.cross(q - a, e)
    e_unit = e / np.linalg.norm(e, axis=1, keepdims=True)
    sine = np.einsum("ij,ij->i", np.cross(n1, e_unit), n2)
    return np.arctan2(sine, np.einsum("ij,ij->i", n1, n2))


def crease_angle_errors(result: dict, positions) -> np.ndarray:
    """(C,) |fold angle − |target|| in degrees of every M/V crease (type 1) at
    ``positions`` (flat list, 3 per node), fold angle = angle between its two
    triangles' normals (0 flat)."""
    c = np.array([row for row in result["creases"] if row[5] == 1], dtype=float)
    angle = np.abs(signed_fold_angles(c, positions))
    return np.abs(np.degrees(angle) - np.degrees(np.abs(c[:, 4])))


def launch(url: str, profile: Path) -> subprocess.Popen:
    """Headless Chromium (``FLAGS``, profile folder ``profile``) on ``url``."""
    return subprocess.Popen([CHROMIUM, *FLAGS, f"--user-data-dir={profile}", url],
                            stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)


def close(browser: subprocess.Popen) -> None:
    """End a browser ``launch`` started (and wait for it)."""
    browser.terminate()
    try:
        browser.wait(timeout=30)
    except subprocess.TimeoutExpired:
        browser.kill()
        browser.wait(timeout=30)


def run_origami_simulator(root: Path, profile: Path) -> dict:
    """One Origami Simulator fold in a fresh Chromium (module docstring)."""
    server = Server(root)
    browser = launch(f"http://127.0.0.1:{server.port}/{HARNESS_PAGE}?model={MODEL}", profile)
    try:
        result = server.results.get(timeout=PAGE_TIMEOUT_S)
    except queue.Empty:
        raise SystemExit(f"origami_simulator: no result from the page in {PAGE_TIMEOUT_S:.0f} s")
    finally:
        close(browser)
        server.close()
    if "error" in result:
        raise SystemExit(f"origami_simulator: the page failed: {result['error']}")
    for hit in result["reached"]:
        errors = crease_angle_errors(result, hit.pop("positions"))
        hit["max_angle_error_deg"] = float(errors.max())
        hit["mean_angle_error_deg"] = float(errors.mean())
    final = crease_angle_errors(result, result.pop("final_positions"))
    result["final_max_angle_error_deg"] = float(final.max())
    result["mv_creases"] = int(len(final))
    for key in ("creases", "original"):
        result.pop(key)
    return result


def graded_case():
    """(pattern, mesh, edge kinds) of the Miura with graded arc hinges, driven flat."""
    from foldcore import patterns, thicken

    widths = patterns.miura_flat_widths(N, M, np.pi / 2 * THICKNESS)
    pattern = patterns.miura(N, M, a=A, b=A, gamma=GAMMA).replace(
        widths=widths, fold_angles=patterns.miura_fold_angles(N, M, GAMMA, 90.0))
    return pattern, thicken(pattern, THICKNESS, hinge="arc"), patterns.miura_edge_kinds(N, M)


def fold_graded(pattern, mesh, kinds) -> dict:
    """One default fold of the graded case: seconds, iterations, verdict, misses (degrees)."""
    from foldcore import Simulation

    start = time.perf_counter()
    sim = Simulation(mesh, pattern)
    result = sim.run(tolerance=TOLERANCE, max_iterations=BUDGET)
    seconds = time.perf_counter() - start
    certificate = sim.convergence.certificate
    miss = np.abs(result.fold_angles_deg - pattern.fold_angles)
    straight, zigzag = (float(np.nanmax(miss[kinds == k])) for k in ("straight", "zigzag"))
    return {"seconds": seconds, "iterations": result.iterations,
            "converged": result.converged, "reason": result.reason,
            "straight_miss_deg": straight, "zigzag_miss_deg": zigzag,
            "max_miss_deg": max(straight, zigzag), "thick_vertices": mesh.n_vertices,
            "certificate_seconds": certificate.seconds, "certificate_checks": certificate.checks}


def file_case(svg: Path):
    """(pattern, vertices as drawn) of Origami Simulator's file, read as ``simulate``
    reads it (the reading is left out of the timing, as the page load is)."""
    from foldcore.io import read_file

    loaded = read_file(svg)
    return loaded.pattern, loaded.drawing


def fold_file(pattern, drawing) -> dict:
    """One fold of the file as ``simulate FILE.svg --fold-percent 100`` folds it (a thin
    sheet): seconds (sheet building and Newton steps), iterations, verdict, the largest
    miss of a driven crease (degrees)."""
    from foldcore.sheet import SheetSolver, build_sheet

    start = time.perf_counter()
    result = SheetSolver(build_sheet(pattern, merge_straight=True, drawn=drawing), 100.0,
                         pattern_edges=pattern.n_edges).run()
    seconds = time.perf_counter() - start
    driven = np.isfinite(result.target_angles_deg)
    miss = np.abs(result.fold_angles_deg - result.target_angles_deg)[driven]
    return {"seconds": seconds, "iterations": result.iterations,
            "converged": result.converged, "reason": result.reason,
            "max_miss_deg": float(miss.max()), "driven_creases": int(driven.sum()),
            "sheet_nodes": int(len(result.positions))}


def foldcore_cases(root: Path, tmp: Path) -> dict:
    """Per foldcore row: (in-process fold, the ``foldcore`` command line of the same
    fold). The graded pattern is written as FOLD (widths and targets) for the CLI."""
    from foldcore.io.fold_write import write_fold

    svg = root / "assets" / MODEL
    thin = file_case(svg)
    graded = graded_case()
    graded_file = tmp / "miura_graded.fold"
    write_fold(graded_file, graded[0])
    out = ["-q", "-o", "out.fold"]
    return {"file": (lambda: fold_file(*thin),
                     ["simulate", svg, "--fold-percent", 100, *out]),
            "graded": (lambda: fold_graded(*graded),
                       ["simulate", graded_file, "--thickness", THICKNESS, "--hinge", "arc",
                        "--tolerance", TOLERANCE, "--max-iterations", BUDGET, *out])}


def one_round(root: Path, profile: Path, cases: dict) -> dict:
    """Origami Simulator, then each foldcore row in-process, then each as a whole
    process; the share of the cores other jobs used before each."""
    busy = {"origami_simulator": _meta.others_busy(1.0)}
    simulator = run_origami_simulator(root, profile)
    ours = {}
    for name, (fold, _) in cases.items():
        busy[name] = _meta.others_busy(1.0)
        ours[name] = fold()
    for name, (_, command) in cases.items():
        busy[name + "_process"] = _meta.others_busy(1.0)
        ours[name]["process_seconds"] = _meta.cli_seconds(command, check=True)
    return {"origami_simulator": simulator, "foldcore": ours, "others_busy": busy}


def rounds_of(source: Path, q: dict, tmp: Path) -> tuple[str, list]:
    """Origami Simulator's commit and ``q["rounds"]`` interleaved rounds of all rows."""
    root = tmp / "OrigamiSimulator"
    root.mkdir()
    commit = extract(source, root)
    harness_page(root, q["strains"], q["limit_s"])
    cases = foldcore_cases(root, tmp)
    for fold, command in cases.values():  # warm-up: this process's kernels, the CLI's cache
        fold()
        _meta.cli_seconds(command, check=True)
    rounds = []
    for k in range(q["rounds"]):
        r = one_round(root, tmp / f"profile{k}", cases)
        rounds.append(r)
        reached = ", ".join(f"< {h['strain_below']:g} %: {h['seconds']:.2f} s "
                            f"({h['steps']} steps, max angle error "
                            f"{h['max_angle_error_deg']:.3g}°)"
                            for h in r["origami_simulator"]["reached"])
        ours = "; ".join(f"{name} {o['seconds']:.3f} s / process {o['process_seconds']:.2f} s, "
                         f"{o['iterations']} iterations, miss {o['max_miss_deg']:.2g}°"
                         for name, o in r["foldcore"].items())
        print(f"round {k}: Origami Simulator (page load "
              f"{r['origami_simulator']['load_seconds']:.2f} s) {reached or 'no threshold'}; "
              f"foldcore {ours}", flush=True)
    return commit, rounds


def main() -> None:
    p = _meta.parser(__doc__)
    p.add_argument("--origami-simulator", type=Path, default=None,
                   help="Origami Simulator: a bare git dir or a checkout "
                        f"(default {DEFAULT_SOURCE}; skipped when absent)")
    args = p.parse_args()
    if _meta.stored("origami_simulator", args, table, plot):
        return
    source = args.origami_simulator or DEFAULT_SOURCE
    missing = [f"{p} not found" for p in (source, Path(CHROMIUM)) if not p.exists()]
    if missing and args.origami_simulator is None:  # e.g. under bench/run.py: not an error
        print(f"origami_simulator: skipped ({'; '.join(missing)}: give "
              "--origami-simulator, a checkout or bare git dir of "
              "github.com/amandaghassaei/OrigamiSimulator; make test installs Chromium)")
        return
    if missing:
        raise SystemExit(f"origami_simulator: {'; '.join(missing)}")
    q = QUICK if args.quick else {"rounds": ROUNDS, "strains": STRAINS, "limit_s": OS_LIMIT_S}
    record = _meta.Record("origami_simulator", args, model=MODEL,
                          strains_percent=list(q["strains"]), foldcore_rows=FOLDCORE_ROWS,
                          rounds=q["rounds"], chromium_flags=FLAGS)
    with tempfile.TemporaryDirectory() as tmp:
        commit, rounds = rounds_of(source, q, Path(tmp))
    record.meta["origami_simulator_commit"] = commit
    record.write({"rounds": rounds}, plot)
    print(table({"meta": record.meta, "rounds": rounds}))


def summary(out: dict) -> dict:
    """Medians over the rounds: Origami Simulator's seconds (stepping; page load plus
    stepping) and max angle error per threshold; each foldcore row's seconds (in
    process; whole process) and misses; per round, Origami Simulator's time at the
    first threshold over each row's (stepping over in-process, page load plus stepping
    over whole process)."""
    rounds = out["rounds"]
    per = {}
    for level in out["meta"]["strains_percent"]:
        hits = [(h, r["origami_simulator"]["load_seconds"]) for r in rounds
                for h in r["origami_simulator"]["reached"] if h["strain_below"] == level]
        if len(hits) == len(rounds):
            per[level] = {"seconds": _meta.median([h["seconds"] for h, _ in hits]),
                          "with_load_seconds": _meta.median([h["seconds"] + load
                                                             for h, load in hits]),
                          "steps": int(np.median([h["steps"] for h, _ in hits])),
                          "max_angle_error_deg": _meta.median([h["max_angle_error_deg"]
                                                               for h, _ in hits])}
    first = out["meta"]["strains_percent"][0]
    ours = {}
    for name in out["meta"]["foldcore_rows"]:
        runs = [r["foldcore"][name] for r in rounds]
        row = {"seconds": _meta.median([o["seconds"] for o in runs]),
               "process_seconds": _meta.median([o["process_seconds"] for o in runs]),
               "max_miss_deg": max(o["max_miss_deg"] for o in runs),
               "iterations": [o["iterations"] for o in runs],
               "reasons": sorted({o["reason"] for o in runs})}
        if "certificate_seconds" in runs[0]:
            row["certificate_seconds"] = _meta.median([o["certificate_seconds"] for o in runs])
        if first in per:
            hits = [next(h for h in r["origami_simulator"]["reached"] if h["strain_below"] == first)
                    for r in rounds]
            row["ratios"] = [h["seconds"] / r["foldcore"][name]["seconds"]
                             for h, r in zip(hits, rounds)]
            row["process_ratios"] = [(h["seconds"] + r["origami_simulator"]["load_seconds"])
                                     / r["foldcore"][name]["process_seconds"]
                                     for h, r in zip(hits, rounds)]
        ours[name] = row
    return {"origami_simulator": per, "foldcore": ours, "first_strain": first}


def table(out: dict) -> str:
    s = summary(out)
    rows = [[f"Origami Simulator, mean strain < {level:g} %", f"{v['seconds']:.2f}",
             f"{v['with_load_seconds']:.2f} (page load + fold)", f"{v['steps']} steps",
             f"{v['max_angle_error_deg']:.3g}", "", ""]
            for level, v in s["origami_simulator"].items()]
    for name, label in out["meta"]["foldcore_rows"].items():
        v = s["foldcore"][name]
        rows.append([label, f"{v['seconds']:.3f}", f"{v['process_seconds']:.2f}",
                     " / ".join(map(str, v["iterations"])) + " iterations",
                     f"{v['max_miss_deg']:.2g}",
                     " / ".join(f"{r:.1f}" for r in v.get("ratios", [])),
                     " / ".join(f"{r:.1f}" for r in v.get("process_ratios", []))])
    first = f"{s['first_strain']:g} %"
    text = _meta.markdown_table(
        ["run", "fold s (median)", "whole process s (median)", "work", "max crease miss (°)",
         f"OS fold (< {first}) ÷ this fold, per round",
         f"OS load + fold (< {first}) ÷ this process, per round"], rows)
    notes = [f"{out['meta']['foldcore_rows'][name]}: the equilibrium certificate at the "
             f"run's end took {v['certificate_seconds']:.3f} s of its fold (median)."
             for name, v in s["foldcore"].items() if "certificate_seconds" in v]
    return "\n\n".join([text, *notes])


def plot(out: dict, path: Path) -> None:
    plt = _meta.pyplot()
    fig, ax = plt.subplots(figsize=(7, 4.2))
    styles = {"file": ("C3", "--"), "graded": ("C2", ":")}
    for k, r in enumerate(out["rounds"]):
        log = np.array(r["origami_simulator"]["log"])
        ax.semilogy(log[:, 1], log[:, 2], color="C0", alpha=0.7,
                    label="Origami Simulator (mean node strain)" if k == 0 else None)
        for name, label in out["meta"]["foldcore_rows"].items():
            color, ls = styles.get(name, ("C4", "-."))
            ax.axvline(r["foldcore"][name]["seconds"], color=color, ls=ls,
                       label=f"{label}: fold" if k == 0 else None)
    for level in out["meta"]["strains_percent"]:
        ax.axhline(level, color="0.6", ls=":", lw=1)
    ax.set_xlabel("seconds of stepping / folding (one run per round, interleaved)")
    ax.set_ylabel("mean strain, %")
    ax.set_title("Origami Simulator's miura-ori.svg folded flat", fontsize=9)
    ax.legend(fontsize=7)
    _meta.save(fig, path, dpi=120)


if __name__ == "__main__":
    main()
