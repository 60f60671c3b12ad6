"""Origami Simulator beside foldcore on its own Miura, folded flat, in one run.

The target: Origami Simulator's ``Tessellations/miura-ori.svg`` folded flat
(100 %) converged in ≤ 0.5 s, ≥ 10 × faster than Origami Simulator *in the
same run*. This benchmark runs both, interleaved, ``ROUNDS`` rounds:

* **Origami Simulator** (Amanda Ghassaei, MIT licence; not part of this
  project: read from a snapshot of github.com/amandaghassaei/OrigamiSimulator,
  a bare git dir or a checkout, ``--origami-simulator``): its own page, served
  from 127.0.0.1, in Debian's headless Chromium with software WebGL
  (SwiftShader, the flags of tests/test_view.py), with a harness script
  added after its ``main.js`` (and the analytics script it loads from
  Google left out: no network). The page loads its demo ``Tessellations/miura-ori.svg`` (182
  nodes) with its default settings; once the model is built the harness
  pauses the animation loop, resets the solver to the flat sheet, sets the
  fold to 100 % and calls ``globals.model.step()`` (its per-frame work:
  ``numSteps`` = 100 solver steps and the read-back that gives the mean
  node strain shown as "global error") until the mean strain is below each
  of ``STRAINS`` (percent) or ``OS_LIMIT_S`` passes (a threshold counts once
  the strain has risen to the first one: the sheet starts flat and unstrained). Time is
  ``performance.now()`` from the first step. The harness yields to the page
  between chunks of 100 steps, where the page may draw a frame, so the times
  can include drawing (in the app every 100 steps also draw a frame). At
  each threshold the node positions are taken, and the fold angle of every
  M/V crease is measured from them (Python side: the angle between the two
  triangles' normals) against its target (±180°).
* **foldcore**: the same layout (Miura 12 × 13, a = b = 80 mm, γ = 84°;
  H = 0.01a, arc hinges of Eq. 7's width W = πH/2 graded along each straight
  line by ``patterns.miura_flat_widths`` — the widths that let a thick Miura
  fold flat: docs/architecture.md#a-thick-miura-has-no-flat-state-with-equal-hinges
  — every crease driven to its rigid-fold angle at facet tilt 90°, default
  strategy, tolerance 1e-9), warm numba cache, one warm-up fold in this
  process first; ``seconds`` is ``Simulation(...).run()`` (the mesh is built
  once, outside the timing, as for Origami Simulator's page load). Its
  misses: the largest on the straight and on the zig-zag creases (degrees).

Reported per round: both times, their ratio (Origami Simulator / foldcore),
Origami Simulator's steps, strain and angle error at each threshold, and
foldcore's iterations and misses; ``others_busy`` before each run (share of
the cores other processes used). Writes bench/results/origami_simulator.json
and .png (Origami Simulator's mean strain against time, foldcore's fold time
marked).

Run: ``python bench/origami_simulator.py [--origami-simulator PATH]`` (~2 min;
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
FOLDCORE_CASE = "arc, graded W, H = 0.01a"
N, M, A, GAMMA, H_OVER_A = 12, 13, 80.0, 84.0, 0.01  # facets, mm, degrees
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
  function fold() {
    globals.simulationRunning = false;  // the harness steps the solver itself
    globals.model.reset();
    globals.setCreasePercent(1.0);
    globals.shouldChangeCreasePercent = true;
    var steps = 0, log = [], reached = [], left = STRAINS.slice(), armed = false;
    var t0 = performance.now();
    function chunk() {
      globals.model.step();
      steps += globals.numSteps;
      var t = (performance.now() - t0) / 1000;
      var strain = parseFloat(document.getElementById("globalError").textContent);
      log.push([steps, t, strain]);
      armed = armed || strain >= STRAINS[0];  // past the start, when the sheet is still flat
      while (armed && left.length && strain < left[0]) {
        reached.push({strain_below: left.shift(), seconds: t, steps: steps, strain: strain,
                      positions: Array.from(globals.model.getPositionsArray())});
      }
      if (left.length && t < LIMIT_S && isFinite(strain)) { setTimeout(chunk, 0); return; }
      post({nodes: globals.model.getNodes().length, num_steps: globals.numSteps,
            creases: creases(), log: log, reached: reached,
            final_positions: Array.from(globals.model.getPositionsArray()),
            original: globals.model.getNodes().map(function (n) {
              var p = n.getOriginalPosition(); return [p.x, p.y, p.z]; }),
            user_agent: navigator.userAgent});
    }
    setTimeout(chunk, 0);
  }
  (function wait() { if (built()) { setTimeout(fold, 200); } else { setTimeout(wait, 50); } })();
})();
"""


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


def foldcore_case():
    """(pattern, mesh, edge kinds) of the Miura with graded arc hinges, driven flat."""
    from foldcore import patterns, thicken

    thickness = H_OVER_A * A
    widths = patterns.miura_flat_widths(N, M, np.pi / 2 * thickness)
    pattern = patterns.miura(N, M, a=A, b=A, gamma=GAMMA).replace(
        widths=widths, fold_angles=patterns.miura_fold_angles(N, M, GAMMA, 90.0))
    return pattern, thicken(pattern, thickness, hinge="arc"), patterns.miura_edge_kinds(N, M)


def fold_once(pattern, mesh, kinds) -> dict:
    """One default fold of the case: seconds, iterations, verdict, misses (degrees)."""
    from foldcore import Simulation

    start = time.perf_counter()
    result = Simulation(mesh, pattern).run(tolerance=TOLERANCE, max_iterations=BUDGET)
    seconds = time.perf_counter() - start
    miss = np.abs(result.fold_angles_deg - pattern.fold_angles)
    return {"seconds": seconds, "iterations": result.iterations,
            "converged": result.converged, "reason": result.reason,
            "energy": float(result.energy[-1]) if len(result.energy) else 0.0,
            "straight_miss_deg": float(np.nanmax(miss[kinds == "straight"])),
            "zigzag_miss_deg": float(np.nanmax(miss[kinds == "zigzag"])),
            "thick_vertices": mesh.n_vertices}


def rounds_of(source: Path, q: dict, tmp: Path, case) -> tuple[str, list]:
    """Origami Simulator's commit and ``q["rounds"]`` interleaved rounds of both."""
    root = tmp / "OrigamiSimulator"
    root.mkdir()
    commit = extract(source, root)
    harness_page(root, q["strains"], q["limit_s"])
    rounds = []
    for k in range(q["rounds"]):
        busy_os = _meta.others_busy(1.0)
        simulator = run_origami_simulator(root, tmp / f"profile{k}")
        busy_fc = _meta.others_busy(1.0)
        ours = fold_once(*case)
        first = simulator["reached"][0]["seconds"] if simulator["reached"] else None
        rounds.append({"origami_simulator": simulator, "foldcore": ours,
                       "others_busy": {"origami_simulator": busy_os, "foldcore": busy_fc},
                       "ratio_first_strain": first / ours["seconds"] if first else None})
        reached = ", ".join(f"< {h['strain_below']:g} %: {h['seconds']:.2f} s "
                            f"({h['steps']} steps, max angle error "
                            f"{h['max_angle_error_deg']:.3g}°)" for h in simulator["reached"])
        print(f"round {k}: Origami Simulator {reached or 'no threshold reached'}; "
              f"foldcore {ours['seconds']:.3f} s, {ours['iterations']} iterations, "
              f"straight miss {ours['straight_miss_deg']:.2g}° (busy {busy_os:.2f}, "
              f"{busy_fc:.2f})", flush=True)
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
    case = foldcore_case()
    fold_once(*case)  # warm-up
    record = _meta.Record("origami_simulator", args, model=MODEL,
                          strains_percent=list(q["strains"]), foldcore_case=FOLDCORE_CASE,
                          rounds=q["rounds"], chromium_flags=FLAGS)
    with tempfile.TemporaryDirectory() as tmp:
        commit, rounds = rounds_of(source, q, Path(tmp), case)
    record.meta["origami_simulator_commit"] = commit
    record.write({"rounds": rounds}, plot)
    print(table({"meta": record.meta, "rounds": rounds}))


def summary(out: dict) -> dict:
    """Medians over the rounds: Origami Simulator's seconds and max angle error per
    threshold, foldcore's seconds, and the per-round ratios."""
    rounds = out["rounds"]
    per = {}
    for level in out["meta"]["strains_percent"]:
        hits = [h for r in rounds for h in r["origami_simulator"]["reached"]
                if h["strain_below"] == level]
        if len(hits) == len(rounds):
            per[level] = {"seconds": float(np.median([h["seconds"] for h in hits])),
                          "steps": int(np.median([h["steps"] for h in hits])),
                          "max_angle_error_deg": float(np.median([h["max_angle_error_deg"]
                                                                  for h in hits])),
                          "ratios": [h["seconds"] / r["foldcore"]["seconds"]
                                     for h, r in zip(hits, rounds)]}
    ours = [r["foldcore"] for r in rounds]
    return {"origami_simulator": per,
            "foldcore_seconds": float(np.median([o["seconds"] for o in ours])),
            "foldcore_straight_miss_deg": max(o["straight_miss_deg"] for o in ours),
            "foldcore_iterations": [o["iterations"] for o in ours]}


def table(out: dict) -> str:
    s = summary(out)
    rows = [[f"Origami Simulator, mean strain < {level:g} %", f"{v['seconds']:.2f}",
             f"{v['steps']} steps", f"{v['max_angle_error_deg']:.3g}",
             " / ".join(f"{r:.1f}" for r in v["ratios"])]
            for level, v in s["origami_simulator"].items()]
    rows.append(["foldcore (thick, graded arc hinges, tolerance 1e-9)",
                 f"{s['foldcore_seconds']:.2f}",
                 " / ".join(map(str, s["foldcore_iterations"])) + " iterations",
                 f"{s['foldcore_straight_miss_deg']:.2g}", "1"])
    return _meta.markdown_table(["run", "s (median)", "work", "max crease miss (°)",
                           "× foldcore's time, per round"], rows)


def plot(out: dict, path: Path) -> None:
    plt = _meta.pyplot()
    fig, ax = plt.subplots(figsize=(7, 4.2))
    for k, r in enumerate(out["rounds"]):
        log = np.array(r["origami_simulator"]["log"])
        ax.semilogy(log[:, 1], log[:, 2], color="C0", alpha=0.7,
                    label="Origami Simulator (mean node strain)" if k == 0 else None)
        ax.axvline(r["foldcore"]["seconds"], color="C3", ls="--",
                   label="foldcore: converged fold (tolerance 1e-9)" if k == 0 else None)
    for level in out["meta"]["strains_percent"]:
        ax.axhline(level, color="0.6", ls=":", lw=1)
    ax.set_xlabel("seconds (one run per round, interleaved)")
    ax.set_ylabel("mean strain, %")
    ax.set_title("Origami Simulator's miura-ori.svg folded flat", fontsize=9)
    ax.legend(fontsize=8)
    _meta.save(fig, path, dpi=120)


if __name__ == "__main__":
    main()
