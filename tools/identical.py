"""Bit-identical check of a refactor: meshes, coarse twins and every iterate.

Records, for a fixed set of cases, a SHA-256 of every array foldcore builds
(thick meshes of built-in, public and elastic patterns, their coarse and
rigid-panel twins) and of the positions after every iteration of every
strategy (single runs, the paper's scenes, the accuracy cases from the
command line's defaults, a fold-percent path with its predictor), with each
run's iterations, reason and residual. Two records compare equal only if
every number is the same to the last bit.

    python tools/identical.py record before.json
    python tools/identical.py compare before.json after.json

Uses the public API, plus the twin builders (looked up where they live).
"""
from __future__ import annotations

import argparse
import hashlib
import importlib
import json
import sys
import warnings
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
REAL = ROOT / "tests" / "data" / "real"


def digest(value) -> str:
    """SHA-256 of a value's numbers and structure (arrays by dtype, shape and bytes)."""
    h = hashlib.sha256()
    _feed(h, value, depth=0)
    return h.hexdigest()[:20]


def _feed(h, value, depth: int) -> None:
    if depth > 6:
        return
    if isinstance(value, np.ndarray):
        h.update(f"A{value.dtype}{value.shape}".encode())
        h.update(np.ascontiguousarray(value).tobytes() if value.dtype != object
                 else repr(value.tolist()).encode())
    elif isinstance(value, dict):
        for k in sorted(value, key=repr):
            h.update(repr(k).encode())
            _feed(h, value[k], depth + 1)
    elif isinstance(value, (list, tuple)):
        h.update(f"L{len(value)}".encode())
        for v in value:
            _feed(h, v, depth + 1)
    elif isinstance(value, (int, float, str, bool, type(None), np.generic)):
        h.update(repr(value).encode())
    elif hasattr(value, "__dict__"):
        _feed(h, {k: v for k, v in vars(value).items() if not k.startswith("_")}, depth + 1)


def mesh_digest(mesh) -> dict:
    out = {"points": digest(mesh.points)}
    for name, g in mesh.groups.items():
        out[f"group:{name}"] = digest({k: getattr(g, k) for k in
                                       ("indptr", "indices", "rest", "params", "weights",
                                        "source", "volumes", "kind")})
    for key in ("subdivisions", "hinge_width", "segments", "panel_of_face", "hinge_model",
                "thickness", "strips_of_crease", "panel_group", "elastic"):
        if hasattr(mesh, key):
            out[key] = digest(getattr(mesh, key))
    out["rest"] = digest(mesh.rest_positions)
    return out


def _find(names: list[str], attr: str):
    for name in names:
        try:
            module = importlib.import_module(name)
        except ImportError:
            continue
        if hasattr(module, attr):
            return getattr(module, attr)
    raise ImportError(f"{attr} not found in {names}")


TWIN_MODULES = ["foldcore.coarse", "foldcore.strategies.rigid.twin",
                "foldcore.strategies.rigid.coarse", "foldcore.strategies.twins",
                "foldcore.twins", "foldcore.strategies.hybrid.rings"]


def mesh_cases():
    from foldcore import patterns, read
    from foldcore.io import Reading

    p = patterns
    yield "d4v-thin-A", p.degree4_vertex(radius=10, widths=[0.03] * 4, rho1=70.0), 0.01, {}
    yield "d4v-pehrson", p.degree4_vertex(), 3.175, {}
    yield "d4v-arc", p.degree4_vertex(), 3.175, {"hinge": "arc"}
    yield "d4v-eq8", p.degree4_vertex(), 3.175, {"hinge": "eq8", "subdivisions": 4}
    yield "waterbomb", p.waterbomb(), 0.5, {}
    yield "miura4", p.miura(4, 4), 0.2, {}
    yield "miura-one", p.miura_one_crease(3, 3), 0.02, {}
    yield "hinge", p.single_hinge(angle=90), 1.0, {"hinge_width": 2.0, "subdivisions": 4}
    yield "grid", p.grid(3, 3), 0.5, {}
    yield "hinge-stretch", p.single_hinge(angle=None), 1.0, {"stretch": {0: 0.3}}
    for f in sorted(REAL.glob("*")):
        if f.suffix not in (".fold", ".svg") or f.name == "BoxPleatPyramid.fold":
            continue
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            try:
                pat = read(f, reading=Reading(size=100.0))
            except Exception as exc:  # noqa: BLE001 (recorded as such)
                yield f.name, exc, None, {}
                continue
        yield f.name, pat, 0.5, {}
        yield f.name + ":elastic", pat, 0.5, {"elastic": "facets", "cell_size": 20.0}


def record_meshes(out: dict) -> None:
    from foldcore import thicken

    twin_mesh = _find(TWIN_MODULES, "twin_mesh")
    rigid_twin_mesh = _find(TWIN_MODULES, "rigid_twin_mesh")
    for name, pattern, h, kw in mesh_cases():
        if isinstance(pattern, Exception):
            out[f"mesh:{name}"] = f"error {type(pattern).__name__}: {pattern}"
            continue
        try:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                mesh = thicken(pattern, h, **kw)
        except Exception as exc:  # noqa: BLE001
            out[f"mesh:{name}"] = f"error {type(exc).__name__}: {exc}"
            continue
        out[f"mesh:{name}"] = mesh_digest(mesh)
        twin = twin_mesh(mesh, pattern)
        out[f"twin:{name}"] = None if twin is None else mesh_digest(twin)
        rigid = rigid_twin_mesh(mesh, pattern)
        out[f"rigidtwin:{name}"] = None if rigid is None else mesh_digest(rigid)


class Recorder:
    """Wraps Simulation.run so that every run of every Simulation records its iterates."""

    def __init__(self):
        self.runs = []

    def install(self):
        from foldcore import simulation

        original = simulation.Simulation.run
        recorder = self

        def run(sim, *args, callback=None, **kwargs):
            trace = []

            def record(s, moved):
                trace.append(digest(np.asarray(s.positions)) + f"/{moved!r}")
                return None if callback is None else callback(s, moved)

            result = original(sim, *args, callback=record, **kwargs)
            recorder.runs.append({
                "iterates": digest(trace), "n": len(trace),
                "iterations": int(result.iterations), "reason": result.reason,
                "residual": repr(float(result.residual)), "positions": digest(result.positions),
                "angles": digest(result.fold_angles_deg), "energy": digest(result.energy),
                "strips": digest(result.strip_angles_deg),
                "misfit": digest(result.hinge_misfit_mm)})
            return result

        simulation.Simulation.run = run
        return original

    def take(self) -> list:
        runs, self.runs = self.runs, []
        return runs


def single_runs():
    from foldcore import patterns, thicken, Simulation

    p = patterns
    cases = {
        "hinge": (p.single_hinge(panel_length=5, angle=90), 1.0,
                  {"hinge_width": 2.0, "subdivisions": 4}),
        "d4v-thin": (p.degree4_vertex(radius=10, widths=[0.03] * 4, rho1=70.0), 0.01, {}),
        "d4v-thick-B": (p.degree4_vertex(mode="B", rho1=60.0), 3.175, {"hinge": "arc"}),
        "waterbomb": (p.waterbomb(), 0.5, {}),
        "miura3": (p.miura(3, 3), 0.2, {}),
    }
    budgets = {"paper": 300, "anderson": 300, "lbfgs": 600}
    for name, (pattern, h, kw) in cases.items():
        mesh = thicken(pattern, h, **kw)
        for solver in ("paper", "anderson", "lbfgs", "rigid", "hybrid", "newton"):
            for actuation in ("equal", "angle") if name == "d4v-thin" else ("equal",):
                key = f"run:{name}:{solver}:{actuation}"
                try:
                    sim = Simulation(mesh, pattern, solver=solver, actuation=actuation)
                    sim.set_fold_percent(50.0)
                    sim.run(tolerance=1e-8, max_iterations=budgets.get(solver, 2000))
                    sim.set_fold_percent(100.0)
                    sim.run(tolerance=1e-9, max_iterations=budgets.get(solver, 2000))
                    yield key, None
                except Exception as exc:  # noqa: BLE001
                    yield key, f"error {type(exc).__name__}: {exc}"


def pinned_runs():
    from foldcore import patterns, thicken, Simulation

    pattern = patterns.single_hinge(panel_length=5, angle=None)
    mesh = thicken(pattern, 1.0, hinge_width=2.0, subdivisions=4)
    for solver in ("paper", "lbfgs", "rigid", "hybrid", "newton"):
        sim = Simulation(mesh, pattern, solver=solver)
        far = sim.nearest_vertex(mesh.rest_positions.max(axis=0))
        sim.add_position_target([far], mesh.rest_positions[far] + [0, 0, 2.0], name="pull")
        sim.run(tolerance=1e-8, max_iterations=500)
        sim.move_position_target("pull", mesh.rest_positions[far] + [0, 0, 4.0])
        sim.run(tolerance=1e-8, max_iterations=500)
        yield f"pinned:{solver}", None


def elastic_runs():
    from foldcore import read, thicken, Simulation
    from foldcore.io import Reading

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        pattern = read(REAL / "simpleVertex.svg", reading=Reading(size=100.0))
    mesh = thicken(pattern, 0.5, elastic="facets", cell_size=20.0)
    for solver in ("hybrid", "newton", "lbfgs"):
        sim = Simulation(mesh, pattern, solver=solver)
        sim.set_fold_percent(30.0)
        sim.run(tolerance=1e-8, max_iterations=400)
        yield f"elastic:{solver}", None


def path_runs():
    from foldcore import patterns, thicken, Simulation
    from foldcore.animate import fold_sweep

    pattern = patterns.miura(3, 3)
    mesh = thicken(pattern, 0.02)
    for solver in ("rigid", "hybrid"):
        sim = Simulation(mesh, pattern, solver=solver)
        fold_sweep(sim, np.linspace(0, 60, 7), tolerance=1e-8, max_iterations=2000,
                   progress=False)
        yield f"path:{solver}", None


def scene_runs(names):
    from foldcore import scenes

    for name in names:
        try:
            scene = scenes.run(name, quick=True)
            yield f"scene:{name}", {"quantities": digest(_untimed(scene.quantities))}
        except Exception as exc:  # noqa: BLE001
            yield f"scene:{name}", f"error {type(exc).__name__}: {exc}"


def _untimed(value):
    """A scene's quantities without wall times (the only numbers that vary by run)."""
    if isinstance(value, dict):
        return {k: _untimed(v) for k, v in value.items()
                if not any(t in k for t in ("second", "time", "wall"))}
    if isinstance(value, list):
        return [_untimed(v) for v in value]
    return value


def stretch_runs():
    from foldcore import patterns, thicken, Simulation

    pattern = patterns.single_hinge(angle=None)
    mesh = thicken(pattern, 1.0, stretch={0: 0.3})
    for solver in ("paper", "lbfgs", "hybrid"):
        sim = Simulation(mesh, pattern, solver=solver)
        sim.set_stretch_ratios({0: 1.3})
        sim.run(tolerance=1e-8, max_iterations=500)
        yield f"stretch:{solver}", None


def accuracy_runs(tmp: Path):
    """The accuracy cases' folds as the command line does them (job.simulate defaults)."""
    from foldcore import patterns, simulate
    from foldcore.io import write_fold

    cases = {f"vertex-{i}-{mode}": patterns.degree4_vertex(
        sectors=s, radius=10, widths=[0.03] * 4, mode=mode, rho1=70.0)
        for i, s in enumerate([(135.0, 90.0, 45.0, 90.0), (150.0, 60.0, 30.0, 120.0)])
        for mode in "AB"}
    cases["miura5"] = patterns.miura_one_crease(5, 5)
    for name, pattern in cases.items():
        src = tmp / f"{name}.fold"
        write_fold(src, pattern)
        thickness = 0.01 if name.startswith("vertex") else 0.02
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            try:
                simulate(src, thickening={"thickness": thickness})
            except TypeError:  # the keyword API before option groups
                simulate(src, thickness=thickness)
        yield f"accuracy:{name}", None


def record(path: Path, scenes: list[str]) -> None:
    import tempfile

    out: dict = {}
    record_meshes(out)
    rec = Recorder()
    rec.install()
    with tempfile.TemporaryDirectory() as tmp:
        groups = [single_runs(), pinned_runs(), stretch_runs(), elastic_runs(), path_runs(),
                  accuracy_runs(Path(tmp)), scene_runs(scenes)]
        for gen in groups:
            for key, extra in gen:
                out[key] = {"extra": extra, "runs": rec.take()}
                print(key, len(out[key]["runs"]), "runs", file=sys.stderr, flush=True)
    path.write_text(json.dumps(out, indent=1, sort_keys=True))


def _unrooted(text: str) -> str:
    """A record with the checkout's path taken out of its messages (worktrees)."""
    return text.replace(str(ROOT), "<root>")


def compare(a: Path, b: Path) -> int:
    left, right = (json.loads(_unrooted(p.read_text())) for p in (a, b))
    bad = 0
    for key in sorted(set(left) | set(right)):
        if left.get(key) != right.get(key):
            bad += 1
            print(f"DIFFERS {key}:\n  {json.dumps(left.get(key))[:600]}\n  "
                  f"{json.dumps(right.get(key))[:600]}")
    print(f"{len(set(left) | set(right))} entries, {bad} differ")
    return 1 if bad else 0


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    sub = parser.add_subparsers(dest="command", required=True)
    rec = sub.add_parser("record")
    rec.add_argument("out", type=Path)
    rec.add_argument("--scenes", default="d4v,waterbomb,miura,hinge-study,groove-bar,chain,box")
    cmp_ = sub.add_parser("compare")
    cmp_.add_argument("a", type=Path)
    cmp_.add_argument("b", type=Path)
    args = parser.parse_args(argv)
    if args.command == "record":
        record(args.out, [s for s in args.scenes.split(",") if s])
        return 0
    return compare(args.a, args.b)


if __name__ == "__main__":
    sys.exit(main())
