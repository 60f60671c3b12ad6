"""Design studies with the real components: points, an in-process and a LocalCluster
study, a scheduler and two workers started as ``dask`` processes, a worker killed
mid-study, a study interrupted and resumed.

Every row must equal a direct :func:`foldcore.simulate` of the same options
(same iterations, the same misses to the bit: the same code on the same
inputs; the workers run numba on one thread, as the direct runs here).
"""
from __future__ import annotations

import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("distributed")
pd = pytest.importorskip("pandas")

from foldcore import study  # noqa: E402
from foldcore.study.points import StudyError  # noqa: E402

DASK = Path(sys.executable).with_name("dask")
GRID = {"thickness": [0.1, 0.2], "hinge-width": [0.3, 0.5, 0.7]}


@pytest.fixture
def vertex_file(tmp_path):
    """Pehrson's vertex at R = 20 mm, crease 1 driven to 70° (the others passive)."""
    from foldcore import patterns
    from foldcore.io import write_fold

    path = tmp_path / "vertex.fold"
    write_fold(path, patterns.degree4_vertex(radius=20.0, widths=[np.nan] * 4, rho1=70.0))
    return path


def direct(path, point: dict) -> dict:
    """miss_max_deg and iterations of ``foldcore.simulate`` at a point."""
    import foldcore
    from foldcore.outputs import actuation_entries
    from foldcore.study.points import option_groups

    groups = option_groups(point)
    result = foldcore.simulate(path, **groups)
    from foldcore.io import read_file

    pattern = read_file(path).pattern
    return {"iterations": result.iterations,
            "miss_max_deg": actuation_entries(result, pattern)["largest_miss_deg"],
            "fold_angles": result.fold_angles_deg}


def assert_rows_equal_direct(frame, path) -> None:
    names = list(GRID)
    for _, row in frame.iterrows():
        point = {n: row[n] for n in names if n in row}
        want = direct(path, point)
        assert row["error"] == "", row["error"]
        assert row["iterations"] == want["iterations"], point
        assert row["miss_max_deg"] == want["miss_max_deg"], point


# ------------------------------------------------------------------ points
def test_set_values_are_parsed_as_numbers_lists_and_words():
    assert study.parse_set("thickness=0.1,0.2") == ("thickness", [0.1, 0.2])
    assert study.parse_set("hinge_width=1") == ("hinge-width", [1])
    assert study.parse_set("sectors=[135,90,45,90],[90,90,90,90]") == \
        ("sectors", [[135, 90, 45, 90], [90, 90, 90, 90]])
    assert study.parse_set("solver=hybrid,newton") == ("solver", ["hybrid", "newton"])
    with pytest.raises(StudyError, match="NAME=V1"):
        study.parse_set("thickness")


def test_a_grid_is_every_combination_last_name_fastest():
    points = study.grid(GRID)
    assert len(points) == 6
    assert points[:2] == [{"thickness": 0.1, "hinge-width": 0.3},
                          {"thickness": 0.1, "hinge-width": 0.5}]


def test_points_are_checked_before_any_fold(vertex_file):
    with pytest.raises(StudyError, match="unknown name 'thicknes'"):
        study.sweep(vertex_file, grid={"thicknes": [0.1]}, workers=0, cache=None)
    with pytest.raises(StudyError, match=r"point 1 \(thickness=-1\): thickness must be"):
        study.sweep(vertex_file, points=[{"thickness": 0.1}, {"thickness": -1}],
                    workers=0, cache=None)
    with pytest.raises(StudyError, match="not a generator"):
        study.sweep("no-such-file.fold", grid=GRID, workers=0, cache=None)


def test_a_points_file_names_its_bad_line(tmp_path):
    bad = tmp_path / "points.csv"
    bad.write_text("thickness,hinge-width\n0.1,0.3\n0.2\n")
    with pytest.raises(StudyError, match="points.csv: line 3: 1 cells"):
        study.read_points(bad)


# ------------------------------------------------------------------ in this process
def test_rows_equal_direct_runs_in_process(vertex_file):
    frame = study.sweep(vertex_file, grid=GRID, workers=0, cache=None, progress=False)
    assert len(frame) == 6 and set(frame["worker"]) == {"local"}
    assert frame["converged"].all()
    assert_rows_equal_direct(frame, vertex_file)


def test_a_failing_point_is_a_row_with_its_error(vertex_file):
    frame = study.sweep(vertex_file, points=[{"thickness": 0.1, "hinge-width": 0.5},
                                             {"thickness": 0.1, "hinge-width": 500.0}],
                        workers=0, cache=None, progress=False)
    assert frame.loc[0, "error"] == "" and frame.loc[0, "converged"]
    assert "hinge widths are too large" in frame.loc[1, "error"]
    assert str(vertex_file) not in frame.loc[1, "error"] or "vertex.fold" in frame.loc[1, "error"]
    assert pd.isna(frame.loc[1, "converged"])


def test_fold_percents_continue_along_one_path(vertex_file):
    points = [{"thickness": 0.1, "fold-percent": p} for p in (100, 50)]
    frame = study.sweep(vertex_file, points=points, workers=0, cache=None, progress=False)
    assert list(frame["start"]) == ["fold-percent 50", "flat"]  # 50 first, then on to 100
    assert frame.loc[1, "iterations"] == direct(vertex_file, points[1])["iterations"]
    # the continued point reaches the direct run's equilibrium
    want = direct(vertex_file, points[0])["fold_angles"]
    assert frame.loc[0, "miss_max_deg"] == pytest.approx(
        direct(vertex_file, points[0])["miss_max_deg"], abs=1e-6)
    assert np.isfinite(want).any()


def test_a_metric_adds_its_columns(vertex_file):
    def crease_1(fold):
        return {"crease_1_deg": float(fold.result.fold_angles_deg[0])}

    frame = study.sweep(vertex_file, grid={"thickness": [0.1]}, metric=crease_1, workers=0,
                        cache=None, progress=False)
    assert frame.loc[0, "crease_1_deg"] == pytest.approx(70.0, abs=0.01)


class Trace:
    """A metric that watches each iteration and gets the point."""

    def __init__(self):
        self.seen = 0

    def watch(self, sim, moved):
        self.seen += 1

    def __call__(self, fold, point):
        seen, self.seen = self.seen, 0
        return {"watched": seen, "thickness_seen": point["thickness"]}


@pytest.mark.parametrize("workers", [0, 1])
def test_a_metric_can_watch_the_iterations_and_see_its_point(vertex_file, workers):
    frame = study.sweep(vertex_file, grid={"thickness": [0.1, 0.2]}, metric=Trace(),
                        workers=workers, cache=None, progress=False)
    assert list(frame["watched"]) == list(frame["iterations"])
    assert list(frame["thickness_seen"]) == [0.1, 0.2]


def test_a_rerun_takes_finished_points_from_the_cache(vertex_file, tmp_path):
    cache = tmp_path / "cache"
    first = study.sweep(vertex_file, grid=GRID, workers=0, cache=cache, progress=False)
    assert not first["cached"].any() and len(list(cache.glob("*.json"))) == 6
    victim = sorted(cache.glob("*.json"))[0]
    victim.unlink()
    second = study.sweep(vertex_file, grid=GRID, workers=0, cache=cache, progress=False)
    assert int((~second["cached"]).sum()) == 1
    pd.testing.assert_series_equal(first["miss_max_deg"], second["miss_max_deg"])


def test_a_changed_pattern_file_misses_the_cache(vertex_file, tmp_path):
    cache = tmp_path / "cache"
    study.sweep(vertex_file, grid={"thickness": [0.1]}, workers=0, cache=cache)
    vertex_file.write_text(vertex_file.read_text().replace("70", "60", 1))
    again = study.sweep(vertex_file, grid={"thickness": [0.1]}, workers=0, cache=cache)
    assert not again["cached"].any()


def test_a_generator_is_swept_by_its_parameters():
    frame = study.sweep("miura", grid={"n": [2], "m": [2, 3], "thickness": [0.1],
                                       "fold-percent": [30]}, workers=0, cache=None)
    # every interior crease of an n × m Miura is driven: (n − 1) m + (m − 1) n
    assert list(frame["driven"]) == [1 * 2 + 1 * 2, 1 * 3 + 2 * 2]
    assert frame["converged"].all()


# ------------------------------------------------------------------ on Dask
def test_a_local_cluster_study_runs_on_its_workers(vertex_file):
    from distributed import Client, LocalCluster

    with LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                      dashboard_address=":0", env={"NUMBA_NUM_THREADS": "1"}) as cluster, \
            Client(cluster) as client:
        workers = set(client.scheduler_info()["workers"])
        frame = study.sweep(vertex_file, grid=GRID, client=client, cache=None)
    assert set(frame["worker"]) <= workers
    assert_rows_equal_direct(frame, vertex_file)


class DaskProcesses:
    """``dask scheduler`` and ``dask worker`` processes on 127.0.0.1 (each its own
    process group, so a worker and its nanny can be killed together)."""

    def __init__(self, folder: Path, workers: int):
        self.file = folder / "scheduler.json"
        self.scheduler = self._start("scheduler", "--host", "127.0.0.1", "--port", "0",
                                     "--no-dashboard", "--scheduler-file", str(self.file))
        self.workers = [self._start("worker", "--scheduler-file", str(self.file),
                                    "--nthreads", "1", "--host", "127.0.0.1",
                                    "--no-dashboard") for _ in range(workers)]
        self.address = self._wait_for(workers)

    def _start(self, *args):
        env = {**os.environ, "NUMBA_NUM_THREADS": "1"}
        return subprocess.Popen([str(DASK), *args], stdout=subprocess.DEVNULL,
                                stderr=subprocess.DEVNULL, env=env, start_new_session=True)

    def _wait_for(self, workers: int) -> str:
        import json

        from distributed import Client

        deadline = time.monotonic() + 60
        while not self.file.exists():
            assert time.monotonic() < deadline, "the scheduler did not start"
            time.sleep(0.2)
        address = json.loads(self.file.read_text())["address"]
        with Client(address, timeout="30s") as client:
            client.wait_for_workers(workers, timeout=60)
            self.addresses = set(client.scheduler_info()["workers"])
        return address

    def kill_worker(self, i: int) -> None:
        os.killpg(self.workers[i].pid, signal.SIGKILL)

    def close(self) -> None:
        for p in self.workers + [self.scheduler]:
            try:
                os.killpg(p.pid, signal.SIGKILL)
            except ProcessLookupError:
                pass
            p.wait()


@pytest.fixture
def cluster(tmp_path):
    procs = DaskProcesses(tmp_path, workers=2)
    yield procs
    procs.close()


def foldcore_cli(*args, **kw):
    return subprocess.Popen([sys.executable, "-m", "foldcore", *args], stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True, **kw)


def test_sweep_on_a_scheduler_and_two_workers_started_by_hand(cluster, vertex_file, tmp_path):
    out = tmp_path / "study.csv"
    run = foldcore_cli("sweep", str(vertex_file), "--set", "thickness=0.1,0.2", "--set",
                       "hinge-width=0.3,0.5,0.7", "--scheduler", cluster.address, "-o",
                       str(out), "--no-cache")
    _, err = run.communicate(timeout=300)
    assert run.returncode == 0, err
    frame = pd.read_csv(out, keep_default_na=False)
    assert len(frame) == 6
    assert set(frame["worker"]) <= cluster.addresses
    assert_rows_equal_direct(frame, vertex_file)
    assert "6 points (6 folded on" in err


def slow_points(n: int) -> list[dict]:
    return [{"thickness": 0.05 + 0.01 * i, "hinge-width": 0.2} for i in range(n)]


def slow_metric(folder: Path) -> str:
    """A metric that takes 0.5 s, so a study of a few points can be caught midway."""
    path = folder / "slow.py"
    path.write_text("import time\n\ndef slow(fold):\n    time.sleep(0.5)\n"
                    "    return fold.result.iterations\n")
    return f"{path}:slow"


def wait_for(predicate, run, timeout: float, what: str) -> None:
    """Wait until ``predicate()`` while the process ``run`` lives."""
    deadline = time.monotonic() + timeout
    while not predicate():
        assert run.poll() is None, f"{what}: {run.communicate()[1]}"
        assert time.monotonic() < deadline, what
        time.sleep(0.05)


def test_a_worker_killed_mid_study_loses_no_point(cluster, vertex_file, tmp_path):
    points = tmp_path / "points.csv"
    pd.DataFrame(slow_points(12)).to_csv(points, index=False)
    cache, out = tmp_path / "cache", tmp_path / "study.csv"
    run = foldcore_cli("sweep", str(vertex_file), "--points", str(points), "--scheduler",
                       cluster.address, "-o", str(out), "--cache", str(cache),
                       "--from-flat", "--metric", slow_metric(tmp_path))
    wait_for(lambda: len(list(cache.glob("*.json"))) >= 2, run, 240, "no point finished")
    cluster.kill_worker(0)
    finished_before = len(list(cache.glob("*.json")))
    _, err = run.communicate(timeout=300)
    assert run.returncode == 0, err
    assert finished_before < 12  # the worker died with points still to fold
    frame = pd.read_csv(out, keep_default_na=False)
    assert len(frame) == 12 and (frame["error"] == "").all(), frame["error"].tolist()
    assert frame["converged"].all() and (frame["metric"] == frame["iterations"]).all()
    assert set(frame["worker"]) <= cluster.addresses


def test_an_interrupted_study_resumes_without_refolding(vertex_file, tmp_path):
    points = tmp_path / "points.csv"
    pd.DataFrame(slow_points(10)).to_csv(points, index=False)
    cache, out = tmp_path / "cache", tmp_path / "study.csv"
    args = ("sweep", str(vertex_file), "--points", str(points), "-o", str(out), "--cache",
            str(cache), "--workers", "0", "--from-flat", "--metric", slow_metric(tmp_path))
    run = foldcore_cli(*args)
    wait_for(lambda: len(list(cache.glob("*.json"))) >= 2, run, 240, "no point finished")
    run.send_signal(signal.SIGINT)
    _, err = run.communicate(timeout=60)
    assert run.returncode == 130, err
    assert "cached" in err and len(err.strip().splitlines()) == 1
    assert not out.exists()
    done = len(list(cache.glob("*.json")))
    assert 2 <= done < 10
    again = foldcore_cli(*args)
    _, err = again.communicate(timeout=300)
    assert again.returncode == 0, err
    frame = pd.read_csv(out)
    assert int(frame["cached"].sum()) == done and len(frame) == 10
    assert f"{10 - done} folded" in err


def test_a_generator_that_refuses_its_parameters_is_a_row():
    frame = study.sweep("miura", grid={"n": [2], "m": [2], "gamma": [50, 95],
                                       "thickness": [0.1]}, workers=0, cache=None)
    assert frame.loc[0, "error"] == "" and frame.loc[0, "converged"]
    assert "miura(" in frame.loc[1, "error"] and "gamma" in frame.loc[1, "error"]


def test_a_switch_is_set_as_its_flag_does(vertex_file):
    frame = study.sweep("miura", grid={"n": [2], "m": [2], "thickness": [0.1],
                                       "mv-passive": [False, True]}, workers=0, cache=None)
    assert list(frame["driven"]) == [4, 0]
    assert "mv-passive=true" in frame.loc[0, "warnings"]
    with pytest.raises(StudyError, match="mv-passive is true or false"):
        study.sweep("miura", grid={"thickness": [0.1], "mv-passive": ["yes"]}, workers=0)


def test_a_metric_column_may_not_replace_a_figure(vertex_file):
    frame = study.sweep(vertex_file, grid={"thickness": [0.1]}, workers=0, cache=None,
                        metric=lambda fold: {"iterations": -1})
    assert frame.loc[0, "iterations"] > 0
    assert "'iterations' is a column of the row" in frame.loc[0, "metric_error"]


def test_another_constant_in_the_metric_is_another_cache_key(vertex_file, tmp_path):
    cache = tmp_path / "cache"
    study.sweep(vertex_file, grid={"thickness": [0.1]}, workers=0, cache=cache,
                metric=lambda fold: {"under": float(fold.result.iterations < 5)})
    again = study.sweep(vertex_file, grid={"thickness": [0.1]}, workers=0, cache=cache,
                        metric=lambda fold: {"under": float(fold.result.iterations < 500)})
    assert not again["cached"].any() and again.loc[0, "under"] == 1.0


def test_keep_refolds_cached_points_without_their_result(vertex_file, tmp_path):
    cache, keep = tmp_path / "cache", tmp_path / "keep"
    study.sweep(vertex_file, grid={"thickness": [0.1]}, workers=0, cache=cache)
    kept = study.sweep(vertex_file, grid={"thickness": [0.1]}, workers=0, cache=cache,
                       keep=keep)
    assert not kept["cached"].any() and Path(kept.loc[0, "result_fold"]).is_file()
    again = study.sweep(vertex_file, grid={"thickness": [0.1]}, workers=0, cache=cache,
                        keep=keep)
    assert again["cached"].all() and Path(again.loc[0, "result_fold"]).is_file()
