"""Origami Simulator's own settled states of every SVG pattern it ships, recorded.

Origami Simulator (Amanda Ghassaei, MIT licence; not part of this project: read
from a snapshot of github.com/amandaghassaei/OrigamiSimulator, a bare git dir or
a checkout, ``--origami-simulator``) is run on its own page, in headless
Chromium with software WebGL, as bench/origami_simulator.py runs it (its page,
server, browser and snapshot extraction are used from there). One page load
serves the whole library: the harness script added after main.js

* keeps the app from drawing: the animation loop the app starts with its first
  model (``threeView.startAnimation``, a ``requestAnimationFrame`` loop that
  syncs a new model, steps the solver when ``simulationRunning`` and renders)
  is never started, ``simulationRunning`` is false, and the harness syncs a
  newly read model itself (``model.sync``, which also syncs the solver);
* asks the server for the next file (GET ``/next``) and reads it through the
  app's own demo loader, as its Examples menu does (``importer.importDemoFile``,
  vertex merge tolerance 3; the curved-crease loader for the menu entries the
  menu marks so, with its discretisation settings; the straight-line loader for
  files the menu does not list); the read time (fetch, parse, triangulation,
  model and solver set-up) is recorded apart from the stepping;
* for each fold percent in ``PERCENTS``, with the app's default settings (axial
  stiffness 20, crease 0.7, panel 0.7, face 0.2, damping 0.45, 100 steps per
  frame, Euler): resets the solver to the flat sheet, sets the crease percent
  and calls ``globals.model.step()`` (one frame's work: 100 solver steps and
  the read-back giving positions and the mean node strain, "global error") in
  a synchronous loop, giving the page back only every ``YIELD_S`` (nothing
  draws then). Two moments are recorded: (a) the mean strain first below
  ``STRAIN`` % after it has risen to it (the sheet starts flat, unstrained; a
  fold that never strains that much has no (a)), and (b) equilibrium: the
  largest node displacement over ``STILL_STEPS`` steps, once the rigid motion
  that best maps the earlier positions onto the later is taken out, below
  ``STILL`` (the app's normalised units: its model's bounding sphere has
  radius 1; the model has no fixed node, and a strained one can keep drifting
  as a rigid body at constant speed, ~2e-5 per 1000 steps, after its shape has
  stopped: the largest plain displacement is recorded too), or
  ``LIMIT_S`` seconds of stepping or ``MAX_STEPS`` steps, whichever is first
  (then ``settled`` is false). Seconds are ``performance.now()`` over the
  stepping only.

Per file, one gzip'd JSON in ``STATES`` (tests/data/origami_simulator/, named
after the asset path): the app's model (nodes' original positions in its
normalised frame, triangles, beams, creases as [edge node 0, edge node 1,
node 1, node 2, target angle (rad), type (1 M/V, 0 facet), face 1, face 2]),
its processed FOLD data (the triangulated one the model is built from, in the
SVG's units with y = 0, and the one before triangulation and cut splitting),
its normalisation (``scale``, ``center``: original = (vertex − center) ×
scale) and per percent the positions at (a) and at (b) (rounded to
``DECIMALS``), steps, seconds and strains; a file the app cannot read records
its error. ``load_state`` reads one back with numpy arrays; ``fold_angles``
gives the M/V creases' signed fold angles (degrees, valley positive) from
positions. bench/results/os_library.json sums up the run: per file and
percent the times, steps, settled flag and sizes, and the machine's load.

Run: ``python bench/os_library.py [--origami-simulator PATH] [--files GLOB]
[--limit-s S]`` (the whole library takes about an hour; skipped when the snapshot or
/usr/bin/chromium is missing); ``--quick``: three small files, 10 s per fold,
states to a temporary folder; ``--table`` prints the summary table.
"""
from __future__ import annotations

import fnmatch
import gzip
import json
import os
import queue
import re
import statistics
import tempfile
import threading
import time
from pathlib import Path

import numpy as np

import _meta
import origami_simulator as osim

STATES = _meta.ROOT / "tests" / "data" / "origami_simulator"
PERCENTS = (30, 60, 90)
STRAIN = 0.01          # (a): mean node strain below this, percent
STILL = 1e-7           # (b): largest node displacement (rigid motion out) over STILL_STEPS
STILL_STEPS = 1000
#: (b) gives up after this many seconds of stepping ... (a cap: most of the library's
#: folds take longer, and at 60 s the 252 folds would take some four hours here)
LIMIT_S = 15.0
MAX_STEPS = 200_000    # ... or this many steps
YIELD_S = 1.0          # the harness gives the page back this often
DECIMALS = 7           # positions and coordinates stored rounded to 1e-7
QUICK_FILES = ("SimpleFolds/simpleVertex.svg", "Origami/hypar.svg",
               "Tessellations/miura-ori.svg")
QUICK = {"limit_s": 10.0, "max_steps": 50_000}
PAGE = "foldcore_library.html"
LOAD_TIMEOUT_S = 120.0  # a file that takes longer to read is recorded as failed
SETTINGS = {"axialStiffness": 20, "creaseStiffness": 0.7, "panelStiffness": 0.7,
            "faceStiffness": 0.2, "percentDamping": 0.45, "numSteps": 100,
            "integrationType": "euler", "vertTol": 3}
CURVED_SETTINGS = {"vertInt": 20, "apprCurve": 0.2}  # the Examples menu's, for its curved entries

HARNESS_JS = """
(function () {
  var CFG = %(config)s;
  var errors = [], warnings = [], loading = null;
  function post(result, then) {
    var xhr = new XMLHttpRequest();
    xhr.open("POST", "/result", true);
    if (then) xhr.onloadend = then;
    xhr.send(JSON.stringify(result));
  }
  function getJSON(path, then) {
    var xhr = new XMLHttpRequest();
    xhr.open("GET", path, true);
    xhr.onload = function () { then(JSON.parse(xhr.responseText)); };
    xhr.send();
  }
  window.addEventListener("error", function (e) {
    errors.push(String(e.message) + " at " + e.filename + ":" + e.lineno);
  });
  function text(e) { return String(e && e.stack ? e.stack : e); }

  function install() {
    // no animation loop: nothing draws, the harness syncs and steps the model itself
    globals.threeView.startAnimation = function () {};
    globals.simulationRunning = false;
    globals.warn = function (msg) { warnings.push(String(msg)); };
    var build = globals.model.buildModel;
    globals.model.buildModel = function (fold, creaseParams) {
      build(fold, creaseParams);
      if (loading && globals.needsSync) loading.built = true;
    };
    var load = THREE.SVGLoader.prototype.load;
    THREE.SVGLoader.prototype.load = function (url, onLoad, onProgress, onError) {
      return load.call(this, url, function (svg) {
        try { onLoad(svg); } catch (e) { errors.push(text(e)); }
        if (loading) loading.done = true;
      }, onProgress, function (e) {
        try { if (onError) onError(e); } catch (e2) { errors.push(text(e2)); }
        if (loading) loading.done = true;
      });
    };
    for (var key in CFG.settings) globals[key] = CFG.settings[key];
  }

  function readFile(job, then) {
    errors = []; warnings = [];
    globals.includeCurves = job.curved;
    for (var key in CFG.settings) globals[key] = CFG.settings[key];
    if (job.curved) for (var k in CFG.curved) globals[k] = CFG.curved[k];
    globals.needsSync = false; globals.simNeedsSync = false;
    loading = {done: false, built: false};
    var t0 = performance.now();
    try { globals.importer.importDemoFile(job.url); }
    catch (e) { errors.push(text(e)); loading.done = true; }
    (function poll() {
      if (!loading.done) { setTimeout(poll, 5); return; }
      var built = loading.built;
      loading = null;
      if (built) {
        try {
          globals.model.sync();  // the model, and the solver (model.syncSolver)
          if (globals.simNeedsSync) globals.model.syncSolver();
        } catch (e) { errors.push(text(e)); built = false; }
      }
      then(built && !errors.length, (performance.now() - t0) / 1000);
    })();
  }

  function foldOf(fold) {
    var out = {};
    ["vertices_coords", "edges_vertices", "edges_assignment", "edges_foldAngle",
     "faces_vertices"].forEach(function (key) { if (fold && fold[key]) out[key] = fold[key]; });
    return out;
  }

  function modelOf(job) {
    var m = globals.model;
    var loader = job.curved ? globals.curvedFolding : globals.pattern;
    return {
      nodes: m.getNodes().map(function (n) {
        var p = n.getOriginalPosition(); return [p.x, p.y, p.z]; }),
      faces: m.getFaces(),
      beams: m.getEdges().map(function (e) {
        return [e.nodes[0].getIndex(), e.nodes[1].getIndex()]; }),
      creases: m.getCreases().map(function (c) {
        return [c.edge.nodes[0].getIndex(), c.edge.nodes[1].getIndex(), c.node1.getIndex(),
                c.node2.getIndex(), c.targetTheta, c.type, c.face1Index, c.face2Index]; }),
      scale: globals.scale,
      fold: foldOf(loader.getFoldData(false)),
      fold_raw: foldOf(loader.getFoldData(true)),
      settings: {axialStiffness: globals.axialStiffness, creaseStiffness: globals.creaseStiffness,
                 panelStiffness: globals.panelStiffness, faceStiffness: globals.faceStiffness,
                 percentDamping: globals.percentDamping, numSteps: globals.numSteps,
                 integrationType: globals.integrationType, vertTol: globals.vertTol,
                 includeCurves: globals.includeCurves, vertInt: globals.vertInt,
                 apprCurve: globals.apprCurve, dt: parseFloat($("#deltaT").text())}
    };
  }

  function largestMove(a, b) {
    var most = 0;
    for (var i = 0; i < a.length; i += 3) {
      var dx = a[i] - b[i], dy = a[i + 1] - b[i + 1], dz = a[i + 2] - b[i + 2];
      var d = dx * dx + dy * dy + dz * dz;
      if (!(d <= most)) most = d;  // NaN propagates
    }
    return Math.sqrt(most);
  }

  // largest node displacement from b to a once the rigid motion that best maps b
  // onto a (least squares) is taken out: Horn's unit quaternion, the eigenvector
  // of the largest eigenvalue of his 4 × 4 matrix (cyclic Jacobi)
  function bestRotation(S) {
    var N = [[S[0][0] + S[1][1] + S[2][2], S[1][2] - S[2][1], S[2][0] - S[0][2], S[0][1] - S[1][0]],
             [S[1][2] - S[2][1], S[0][0] - S[1][1] - S[2][2], S[0][1] + S[1][0], S[2][0] + S[0][2]],
             [S[2][0] - S[0][2], S[0][1] + S[1][0], -S[0][0] + S[1][1] - S[2][2], S[1][2] + S[2][1]],
             [S[0][1] - S[1][0], S[2][0] + S[0][2], S[1][2] + S[2][1], -S[0][0] - S[1][1] + S[2][2]]];
    var V = [[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]], p, q, k;
    for (var sweep = 0; sweep < 50; sweep++) {
      var off = 0, scale = 0;
      for (p = 0; p < 4; p++) for (q = 0; q < 4; q++) {
        if (p !== q) off += N[p][q] * N[p][q]; else scale += N[p][q] * N[p][q];
      }
      if (off <= 1e-30 * scale || off === 0) break;
      for (p = 0; p < 3; p++) for (q = p + 1; q < 4; q++) {
        if (N[p][q] === 0) continue;
        var theta = (N[q][q] - N[p][p]) / (2 * N[p][q]);
        var t = (theta >= 0 ? 1 : -1) / (Math.abs(theta) + Math.sqrt(theta * theta + 1));
        var c = 1 / Math.sqrt(t * t + 1), s = t * c;
        for (k = 0; k < 4; k++) {  // N <- N J (columns p, q)
          var nkp = N[k][p], nkq = N[k][q];
          N[k][p] = c * nkp - s * nkq; N[k][q] = s * nkp + c * nkq;
        }
        for (k = 0; k < 4; k++) {  // N <- J^T N (rows p, q)
          var npk = N[p][k], nqk = N[q][k];
          N[p][k] = c * npk - s * nqk; N[q][k] = s * npk + c * nqk;
        }
        for (k = 0; k < 4; k++) {
          var vkp = V[k][p], vkq = V[k][q];
          V[k][p] = c * vkp - s * vkq; V[k][q] = s * vkp + c * vkq;
        }
      }
    }
    var best = 0;
    for (k = 1; k < 4; k++) if (N[k][k] > N[best][best]) best = k;
    var w = V[0][best], x = V[1][best], y = V[2][best], z = V[3][best];
    var n = Math.sqrt(w * w + x * x + y * y + z * z);
    w /= n; x /= n; y /= n; z /= n;
    return [[w * w + x * x - y * y - z * z, 2 * (x * y - w * z), 2 * (x * z + w * y)],
            [2 * (x * y + w * z), w * w - x * x + y * y - z * z, 2 * (y * z - w * x)],
            [2 * (x * z - w * y), 2 * (y * z + w * x), w * w - x * x - y * y + z * z]];
  }

  function largestShapeMove(a, b) {
    var n = a.length / 3, ca = [0, 0, 0], cb = [0, 0, 0], i, j, k;
    for (i = 0; i < n; i++) for (k = 0; k < 3; k++) { ca[k] += a[3*i+k] / n; cb[k] += b[3*i+k] / n; }
    var S = [[0, 0, 0], [0, 0, 0], [0, 0, 0]];
    for (i = 0; i < n; i++) for (j = 0; j < 3; j++) for (k = 0; k < 3; k++)
      S[j][k] += (b[3*i+j] - cb[j]) * (a[3*i+k] - ca[k]);
    var R = bestRotation(S), most = 0;
    for (i = 0; i < n; i++) {
      var d = 0;
      for (j = 0; j < 3; j++) {
        var r = ca[j] - a[3*i+j];
        for (k = 0; k < 3; k++) r += R[j][k] * (b[3*i+k] - cb[k]);
        d += r * r;
      }
      if (!(d <= most)) most = d;
    }
    return Math.sqrt(most);
  }

  function fold(percent, then) {
    var m = globals.model, $error = document.getElementById("globalError");
    globals.simulationRunning = false;
    m.reset();
    globals.setCreasePercent(percent / 100);
    globals.shouldChangeCreasePercent = true;
    var steps = 0, busy = 0, armed = false, a = null, peak = 0, strain = NaN;
    var still = Float32Array.from(m.getPositionsArray()), stillSteps = 0, moved = null;
    var shape = null;
    var settled = false, reason = null, log = [];
    function block() {
      var t0 = performance.now(), now = t0;
      while (true) {
        m.step();
        steps += globals.numSteps;
        now = performance.now();
        strain = parseFloat($error.textContent);
        if (strain > peak) peak = strain;
        armed = armed || strain >= CFG.strain;
        if (armed && a === null && strain < CFG.strain) {
          a = {steps: steps, seconds: busy + (now - t0) / 1000, strain: strain,
               positions: Array.from(m.getPositionsArray())};
        }
        if (steps - stillSteps >= CFG.still_steps) {
          var positions = m.getPositionsArray();
          moved = largestMove(positions, still);
          shape = largestShapeMove(positions, still);
          still = Float32Array.from(positions);
          stillSteps = steps;
          log.push([steps, busy + (now - t0) / 1000, strain, moved, shape]);
          if (shape < CFG.still) { settled = true; reason = "still"; break; }
        }
        // blown up: the app's strain read-back turns negative or huge, positions ~1e38
        if (!(strain >= 0 && strain < 1e6) || !(shape === null || (isFinite(shape) && moved < 100))) {
          reason = "diverged"; break;
        }
        if (busy + (now - t0) / 1000 >= CFG.limit_s) { reason = "time limit"; break; }
        if (steps >= CFG.max_steps) { reason = "step limit"; break; }
        if (now - t0 >= CFG.yield_s * 1000) {
          busy += (now - t0) / 1000;
          setTimeout(block, 0);
          return;
        }
      }
      busy += (now - t0) / 1000;
      then({percent: percent, a: a, armed: armed, peak_strain: peak,
            b: {steps: steps, seconds: busy, settled: settled, reason: reason,
                largest_move: moved, largest_shape_move: shape, strain: strain,
                positions: Array.from(m.getPositionsArray())},
            log: log});
    }
    setTimeout(block, 0);
  }

  function next() {
    getJSON("/next", function (job) {
      if (job.done) { post({kind: "done"}); return; }
      post({kind: "start", svg: job.svg});
      readFile(job, function (ok, seconds) {
        var head = {kind: "model", svg: job.svg, load_seconds: seconds, warnings: warnings,
                    errors: errors, user_agent: navigator.userAgent};
        if (!ok) { head.error = errors.length ? errors.join("; ") :
                     (warnings.length ? warnings.join("; ") : "no model built");
                   post(head, next); return; }
        try { Object.assign(head, modelOf(job)); }
        catch (e) { head.error = text(e); post(head, next); return; }
        post(head, function () {
          var k = 0;
          (function one() {
            if (k >= CFG.percents.length) { next(); return; }
            var percent = CFG.percents[k++];
            try {
              fold(percent, function (result) {
                result.kind = "fold"; result.svg = job.svg;
                post(result, one);
              });
            } catch (e) {
              post({kind: "fold", svg: job.svg, percent: percent, error: text(e)}, one);
            }
          })();
        });
      });
    });
  }

  $(function () { install(); setTimeout(next, 0); });
})();
"""


# ------------------------------------------------------------------ the library
def library(root: Path) -> list[dict]:
    """Every ``assets/**/*.svg`` of the extracted app in ``root``, sorted: its demo
    url (relative to assets/), whether the Examples menu lists it and whether
    the menu reads it with the curved-crease loader (its entries of class cc)."""
    html = (root / "index.html").read_text()
    menu = {}
    for tag in re.findall(r"<a\b[^>]*>", html):
        url = re.search(r'data-url="([^"]*)"', tag)
        classes = re.search(r'class="([^"]*)"', tag)
        if url and classes and "demo" in classes.group(1).split():
            menu[url.group(1)] = "cc" in classes.group(1).split()
    assets = root / "assets"
    return [{"svg": f"assets/{p.relative_to(assets).as_posix()}",
             "url": p.relative_to(assets).as_posix(),
             "in_menu": p.relative_to(assets).as_posix() in menu,
             "curved": menu.get(p.relative_to(assets).as_posix(), False)}
            for p in sorted(assets.rglob("*.svg"))]


def state_name(svg: str) -> str:
    """The state file's name for an asset path: assets/Origami/hypar.svg ->
    Origami__hypar.json.gz (spaces as _)."""
    stem = svg.removeprefix("assets/").removesuffix(".svg")
    return re.sub(r"[^A-Za-z0-9._-]", "_", stem.replace("/", "__")) + ".json.gz"


def rounded(values, decimals: int = DECIMALS):
    """Nested lists of floats rounded (None, ints and strings kept)."""
    if isinstance(values, float):
        return round(values, decimals) if np.isfinite(values) else None
    if isinstance(values, list):
        return [rounded(v, decimals) for v in values]
    return values


def triples(flat) -> list:
    """A flat position list as rounded [x, y, z] rows."""
    x = np.asarray(flat, dtype=float).reshape(-1, 3)
    return rounded(x.tolist())


# ------------------------------------------------------------------ reading states back
def load_state(path) -> dict:
    """A state file as a dict, arrays as numpy: ``nodes`` (N, 3) original
    positions in the app's normalised frame, ``faces`` (F, 3), ``beams`` (E, 2),
    ``creases`` (C, 8) float rows [edge node 0, edge node 1, node 1, node 2,
    target (rad), type, face 1, face 2], ``center`` (3,), FOLD arrays of ``fold``
    and ``fold_raw`` (vertices_coords, edges_vertices, ``fold``'s faces_vertices:
    the model's beams and faces; assignments as lists, fold angles as float
    arrays with NaN for none), and per entry of ``folds`` (one per
    percent) ``positions_a`` / ``positions_b`` (N, 3) or None."""
    with gzip.open(path, "rt") as fh:
        state = json.load(fh)
    if "error" in state:
        return state
    for key, dtype in (("nodes", float), ("faces", int), ("beams", int), ("creases", float),
                       ("center", float)):
        state[key] = np.asarray(state[key], dtype=dtype)
    # the FOLD data's edges and faces, stored once as the model's beams and triangles
    if state.pop("fold_edges_are_beams", False):
        state["fold"]["edges_vertices"] = state["beams"]
    if state.pop("fold_faces_are_faces", False):
        state["fold"]["faces_vertices"] = state["faces"]
    for key in ("fold", "fold_raw"):
        fold = state.get(key, {})
        for name, dtype in (("vertices_coords", float), ("edges_vertices", int)):
            if name in fold:
                fold[name] = np.asarray(fold[name], dtype=dtype)
        if "edges_foldAngle" in fold:
            fold["edges_foldAngle"] = np.array([np.nan if v is None else v
                                                for v in fold["edges_foldAngle"]], dtype=float)
    for entry in state.get("folds", []):
        for key in ("positions_a", "positions_b"):
            if entry.get(key) is not None:
                entry[key] = np.asarray(entry[key], dtype=float)
    return state


def fold_angles(state: dict, positions, all_creases: bool = False) -> np.ndarray:
    """(C,) fold angle in degrees, FOLD's sign (valley positive), of every M/V crease
    of ``state`` (its creases of type 1; every crease, the facet diagonals too, with
    ``all_creases``) at ``positions`` ((N, 3)): Origami Simulator's dihedral angle
    (``origami_simulator.signed_fold_angles``), which its targets share."""
    creases = state["creases"] if all_creases else state["creases"][state["creases"][:, 5] == 1]
    return np.degrees(osim.signed_fold_angles(creases, positions))


def targets(state: dict, percent: float, all_creases: bool = False) -> np.ndarray:
    """(C,) the app's target angle in degrees of the creases ``fold_angles`` gives,
    at fold ``percent`` (its creases drive to target × percent / 100)."""
    creases = state["creases"] if all_creases else state["creases"][state["creases"][:, 5] == 1]
    return np.degrees(creases[:, 4]) * percent / 100.0


# ------------------------------------------------------------------ the run
class Run:
    """The jobs the page asks for (GET /next) and what it posts back, per file."""

    def __init__(self, jobs: list[dict]):
        self.jobs = list(jobs)
        self.lock = threading.Lock()
        self.busy: dict[str, dict] = {}

    def next(self) -> dict:
        with self.lock:
            if not self.jobs:
                return {"done": True}
            job = self.jobs.pop(0)
        # the page waits for this answer: the machine's load, without this run's stepping
        self.busy[job["svg"]] = {"others_busy": _meta.others_busy(0.5),
                                 "loadavg": list(os.getloadavg())}
        return job


def state_of(job: dict, model: dict, folds: list, commit: str) -> dict:
    """The state file's content for one file (module docstring)."""
    state = {"svg": job["svg"], "origami_simulator_commit": commit,
             "repository": "https://github.com/amandaghassaei/OrigamiSimulator",
             "loader": "curved" if job["curved"] else "straight", "in_menu": job["in_menu"],
             "load_seconds": model.get("load_seconds"), "warnings": model.get("warnings", [])}
    if "error" in model:
        state["error"] = model["error"]
        return state
    nodes = np.asarray(model["nodes"], dtype=float)
    fold = model["fold"]
    coords = np.asarray(fold["vertices_coords"], dtype=float)
    center = (coords - nodes / model["scale"]).mean(axis=0) if len(coords) == len(nodes) else None
    if center is not None:
        miss = np.abs((coords - center) * model["scale"] - nodes).max()
        state["center_residual"] = float(miss)
    beams, faces = model["beams"], model["faces"]
    fold_out = {k: rounded(v) for k, v in fold.items()}
    # the model's beams and triangles are the FOLD data's edges and faces: stored once
    if fold_out.get("edges_vertices") == beams:
        fold_out.pop("edges_vertices")
        state["fold_edges_are_beams"] = True
    if fold_out.get("faces_vertices") == faces:
        fold_out.pop("faces_vertices")
        state["fold_faces_are_faces"] = True
    state.update({"scale": model["scale"],
                  "center": None if center is None else rounded(center.tolist(), 9),
                  "settings": model["settings"], "nodes": triples(model["nodes"]),
                  "faces": faces, "beams": beams,
                  "creases": [row[:4] + [round(row[4], 9)] + row[5:] for row in model["creases"]],
                  "fold": fold_out,
                  "fold_raw": {k: rounded(v) for k, v in model["fold_raw"].items()},
                  "folds": []})
    for f in folds:
        if "error" in f:
            state["folds"].append({"percent": f["percent"], "error": f["error"]})
            continue
        a, b = f["a"], f["b"]
        state["folds"].append({
            "percent": f["percent"], "armed": f["armed"], "peak_strain": f["peak_strain"],
            "a_steps": a and a["steps"], "a_seconds": a and a["seconds"],
            "a_strain": a and a["strain"],
            "b_steps": b["steps"], "b_seconds": b["seconds"], "settled": b["settled"],
            "b_reason": b["reason"], "largest_move": b["largest_move"],
            "largest_shape_move": b["largest_shape_move"],
            "final_strain": b["strain"],
            "positions_a": a and triples(a["positions"]), "positions_b": triples(b["positions"])})
    return state


def summary_row(job: dict, state: dict, busy: dict, folds: list) -> dict:
    row = {"svg": job["svg"], "loader": state.get("loader"), "in_menu": job["in_menu"],
           "load_seconds": state.get("load_seconds"), **busy}
    if "error" in state:
        row["error"] = state["error"]
        return row
    row.update({"nodes": len(state["nodes"]), "faces": len(state["faces"]),
                "beams": len(state["beams"]),
                "mv_creases": sum(1 for c in state["creases"] if c[5] == 1),
                "facet_creases": sum(1 for c in state["creases"] if c[5] == 0),
                "warnings": len(state.get("warnings", [])), "folds": []})
    for entry, raw in zip(state["folds"], folds):
        if "error" in entry:
            row["folds"].append({"percent": entry["percent"], "error": entry["error"]})
            continue
        keep = {k: entry[k] for k in ("percent", "armed", "peak_strain", "a_steps", "a_seconds",
                                      "b_steps", "b_seconds", "settled", "b_reason",
                                      "largest_move", "largest_shape_move",
                                      "final_strain")}
        log = np.asarray(raw.get("log") or np.zeros((0, 5)), dtype=float)
        if len(log):  # [steps, largest move, largest shape move], thinned to ~10 rows
            pick = np.unique(np.linspace(0, len(log) - 1, min(len(log), 10)).astype(int))
            keep["moves"] = [[int(log[i, 0]), float(f"{log[i, 3]:.3g}"), float(f"{log[i, 4]:.3g}")]
                             for i in pick]
        row["folds"].append(keep)
    return row


def run_library(root: Path, jobs: list[dict], commit: str, cfg: dict, states: Path,
                tmp: Path) -> list[dict]:
    """Every job through one page (a fresh one after a page that stops answering);
    writes each file's state as it completes; returns the summary rows."""
    run = Run(jobs)
    server = osim.Server(root, routes={"/next": run.next})
    rows, launches = [], 0
    watchdog = max(LOAD_TIMEOUT_S, cfg["limit_s"] * 1.5 + 30.0)
    try:
        while True:
            if launches > len(jobs) + 2:
                raise SystemExit("os_library: the page keeps failing")
            browser = osim.launch(f"http://127.0.0.1:{server.port}/{PAGE}?model=none",
                                  tmp / f"profile{launches}")
            launches += 1
            current, model, folds, finished = None, None, [], False
            try:
                while True:
                    try:
                        msg = server.results.get(timeout=watchdog)
                    except queue.Empty:
                        break
                    kind = msg.get("kind")
                    if kind == "done":
                        finished = True
                        break
                    if kind == "start":
                        current = next(j for j in jobs if j["svg"] == msg["svg"])
                        model, folds = None, []
                        continue
                    if kind == "model":
                        model = msg
                        if "error" in msg:
                            rows.append(finish(current, model, [], commit, states, run))
                            current = None
                        continue
                    if kind == "fold":
                        folds.append(msg)
                        f = msg
                        print(f"  {msg['svg']} {f['percent']} %: " + (
                            f["error"] if "error" in f else
                            f"(a) {f['a']['seconds']:.2f} s / {f['a']['steps']} steps, "
                            if f["a"] else "(a) none, ") + (
                            "" if "error" in f else
                            f"(b) {f['b']['seconds']:.2f} s / {f['b']['steps']} steps "
                            f"{'settled' if f['b']['settled'] else f['b']['reason']}"),
                            flush=True)
                        if len(folds) == len(cfg["percents"]):
                            rows.append(finish(current, model, folds, commit, states, run))
                            current = None
            finally:
                osim.close(browser)
            if finished:
                break
            if current is not None:  # the page stopped answering on this file
                model = model or {"svg": current["svg"]}
                model.setdefault("error", f"the page gave no answer in {watchdog:.0f} s "
                                          f"({len(folds)} of the folds done)")
                if "nodes" in model and folds:
                    model.pop("error")
                    folds += [{"percent": p, "error": f"the page gave no answer in "
                                                      f"{watchdog:.0f} s"}
                              for p in cfg["percents"][len(folds):]]
                rows.append(finish(current, model, folds, commit, states, run))
    finally:
        server.close()
    return rows


def finish(job: dict, model: dict, folds: list, commit: str, states: Path, run: Run) -> dict:
    state = state_of(job, model, folds, commit)
    path = states / state_name(job["svg"])
    with gzip.open(path, "wt", compresslevel=9) as fh:
        json.dump(state, fh, separators=(",", ":"))
    size = path.stat().st_size
    print(f"{job['svg']}: " + (f"failed: {state['error'][:200]}" if "error" in state else
                               f"{len(state['nodes'])} nodes, read in "
                               f"{state['load_seconds']:.2f} s") + f" -> {path.name} "
          f"({size / 1024:.0f} kB)", flush=True)
    row = summary_row(job, state, run.busy.get(job["svg"], {}), folds)
    row["state_bytes"] = size
    return row


def main() -> None:
    p = _meta.parser(__doc__)
    p.add_argument("--origami-simulator", type=Path, default=None,
                   help="Origami Simulator: a bare git dir or a checkout "
                        f"(default {osim.DEFAULT_SOURCE}; skipped when absent)")
    p.add_argument("--files", default=None,
                   help="only the assets matching this glob (relative to assets/)")
    p.add_argument("--limit-s", type=float, default=None,
                   help=f"seconds of stepping per fold before giving up (default {LIMIT_S:g})")
    p.add_argument("--states", type=Path, default=None,
                   help=f"folder for the state files (default {STATES.relative_to(_meta.ROOT)}; "
                        "with --quick a temporary folder)")
    args = p.parse_args()
    if _meta.stored("os_library", args, table):
        return
    source = args.origami_simulator or osim.DEFAULT_SOURCE
    missing = [f"{p} not found" for p in (source, Path(osim.CHROMIUM)) if not p.exists()]
    if missing and args.origami_simulator is None:
        print(f"os_library: skipped ({'; '.join(missing)})")
        return
    if missing:
        raise SystemExit(f"os_library: {'; '.join(missing)}")
    cfg = {"percents": list(PERCENTS), "strain": STRAIN, "still": STILL,
           "still_steps": STILL_STEPS, "limit_s": LIMIT_S, "max_steps": MAX_STEPS,
           "yield_s": YIELD_S, "settings": SETTINGS, "curved": CURVED_SETTINGS}
    if args.quick:
        cfg.update(QUICK)
    if args.limit_s is not None:
        cfg["limit_s"] = args.limit_s
    states = args.states or (_meta.QUICK_RESULTS / "os_library_states" if args.quick else STATES)
    states.mkdir(parents=True, exist_ok=True)
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        root = tmp / "OrigamiSimulator"
        root.mkdir()
        commit = osim.extract(source, root)
        left_out = osim.absent_files(source) if commit != "checkout" else []
        jobs = library(root)
        if args.quick and args.files is None:
            jobs = [j for j in jobs if j["url"] in QUICK_FILES]
        if args.files:
            jobs = [j for j in jobs if fnmatch.fnmatch(j["url"], args.files)]
        osim.page_with_script(root, HARNESS_JS % {"config": json.dumps(cfg)}, PAGE)
        record = _meta.Record("os_library", args, origami_simulator_commit=commit,
                              snapshot_left_out=left_out, files=len(jobs),
                              chromium_flags=osim.FLAGS,
                              harness={k: v for k, v in cfg.items()},
                              states=str(states.relative_to(_meta.ROOT))
                              if states.is_relative_to(_meta.ROOT) else str(states))
        start = time.perf_counter()
        rows = run_library(root, jobs, commit, cfg, states, tmp)
    record.meta["wall_seconds"] = time.perf_counter() - start
    record.write({"files": rows, "totals": totals(rows, cfg["percents"])}, indent=None)
    print(table({"meta": record.meta, "files": rows}))


def totals(rows: list[dict], percents) -> dict:
    """Counts and medians over the files, per percent."""
    out = {"files": len(rows), "read": sum("error" not in r for r in rows),
           "failed": [r["svg"] for r in rows if "error" in r], "per_percent": {}}
    for percent in percents:
        folds = [f for r in rows if "error" not in r for f in r["folds"]
                 if f["percent"] == percent and "error" not in f]
        a = [f["a_seconds"] for f in folds if f["a_seconds"] is not None]
        b = [f["b_seconds"] for f in folds if f["settled"]]
        out["per_percent"][str(percent)] = {
            "folds": len(folds), "settled": len(b), "reached_a": len(a),
            "median_a_seconds": statistics.median(a) if a else None,
            "median_a_steps": statistics.median([f["a_steps"] for f in folds
                                                 if f["a_steps"] is not None]) if a else None,
            "median_b_seconds_settled": statistics.median(b) if b else None,
            "median_b_steps_settled": statistics.median([f["b_steps"] for f in folds
                                                         if f["settled"]]) if b else None}
    return out


def table(out: dict) -> str:
    percents = out["meta"]["harness"]["percents"]
    t = totals(out["files"], percents)
    rows = []
    for percent in percents:
        v = t["per_percent"][str(percent)]
        fmt = (lambda x: "–" if x is None else f"{x:.2f}")
        rows.append([f"{percent} %", f"{v['folds']}", f"{v['reached_a']}", fmt(v["median_a_seconds"]),
                     f"{v['settled']}", fmt(v["median_b_seconds_settled"])])
    busy = [r["others_busy"] for r in out["files"] if "others_busy" in r]
    head = (f"{t['read']} of {t['files']} files read"
            + (f" (failed: {', '.join(t['failed'])})" if t["failed"] else "")
            + f"; stepping capped at {out['meta']['harness']['limit_s']:g} s per fold"
            + (f"; other jobs used a median {statistics.median(busy):.0%} of the cores"
               if busy else ""))
    return head + "\n\n" + _meta.markdown_table(
        ["fold", "folds run", "(a) reached", "(a) median s", "(b) settled",
         "(b) median s (settled)"], rows)


if __name__ == "__main__":
    main()
