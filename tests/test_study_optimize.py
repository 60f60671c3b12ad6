"""foldcore.study.optimize and ``foldcore optimize``: Optuna's trials folded as study
points, on the example of the module's docstring (a thick 3 × 3 Miura, 0.2 mm
sheet, at 60 %, whose hinge width is searched in 0.2…2 mm).

All but one run in this process (``workers=0``, about 0.05 s a fold); one runs
on a LocalCluster of two workers.
"""
from __future__ import annotations

import math
import sys

import numpy as np
import pytest

pytest.importorskip("optuna")
pytest.importorskip("distributed")

from foldcore import study  # noqa: E402
from foldcore.cli import main  # noqa: E402

MIURA = {"n": 3, "m": 3, "thickness": 0.2, "fold-percent": 60}
WIDTHS = (0.2, 2.0)
#: The fine sweep's spacing over WIDTHS, mm.
SPACING = 0.05


@pytest.fixture(scope="module")
def fine_sweep():
    """The example's figures every SPACING mm of hinge width (37 folds)."""
    widths = np.round(np.arange(WIDTHS[0], WIDTHS[1] + SPACING / 2, SPACING), 6)
    return study.sweep("miura", grid={**{k: [v] for k, v in MIURA.items()},
                                      "hinge-width": list(widths)},
                       workers=0, cache=None, progress=False)


def sweep_minimum(frame, column: str) -> tuple[float, float]:
    """(least value on the grid, tolerance): the true minimum is within one grid step
    of the grid's least point, so within the larger change over the steps to its
    neighbours (the local slope × the spacing)."""
    values = frame[column].to_numpy(dtype=float)
    k = int(np.argmin(values))
    steps = [abs(values[j] - values[k]) for j in (k - 1, k + 1) if 0 <= j < len(values)]
    return float(values[k]), max(steps)


@pytest.mark.parametrize("column", ["largest_strain", "miss_max_deg"])
def test_the_optimum_is_the_fine_sweeps_minimum_within_one_grid_step(fine_sweep, column):
    """largest_strain falls as the hinge widens (its minimum at 2 mm, the bound);
    miss_max_deg is least near 0.26–0.30 mm, where the panels stop overlapping at
    the creases. 24 seeded trials find both within the sweep's resolution."""
    found = study.optimize("miura", {"hinge-width": WIDTHS}, column, fixed=MIURA, trials=24,
                           seed=0, workers=0, cache=None)
    history = found.history
    assert len(history) == 24 and list(history["trial"]) == list(range(24))
    assert history["feasible"].all() and (history["error"] == "").all()
    assert found.value == history["objective"].min() == history.at[found.trial, column]
    assert found.best == {"hinge-width": history.at[found.trial, "hinge-width"], **MIURA}
    least, tolerance = sweep_minimum(fine_sweep, column)
    assert least - tolerance <= found.value <= least + tolerance, (found.value, least,
                                                                  tolerance)


def test_a_trials_row_is_the_sweep_row_of_its_point():
    found = study.optimize("miura", {"hinge-width": WIDTHS}, "largest_strain", fixed=MIURA,
                           trials=2, workers=0, cache=None)
    swept = study.sweep("miura", points=[found.best], workers=0, cache=None, progress=False)
    timing = {"wall_s", "run_s", "setup_s"}
    same = [c for c in study.FIGURES if c not in timing] + list(found.best)
    row = found.history.loc[found.history["trial"] == found.trial, same]
    assert row.reset_index(drop=True).equals(swept[same])


def test_a_strain_limit_picks_the_narrowest_hinge_that_keeps_to_it():
    """Minimising miss_max_deg under largest_strain ≤ 0.6: wider hinges strain less
    but miss more, so the best is just past where the strain falls to 0.6."""
    found = study.optimize("miura", {"hinge-width": WIDTHS}, "miss_max_deg", fixed=MIURA,
                           constraints={"largest_strain": 0.6}, trials=24, workers=0,
                           cache=None)
    history = found.history
    assert (history["feasible"] == (history["largest_strain"] <= 0.6)).all()
    assert not history["feasible"].all() and history["feasible"].any()
    feasible = history[history["feasible"]]
    assert found.value == feasible["miss_max_deg"].min()
    assert found.value > history.loc[~history["feasible"], "miss_max_deg"].min()
    assert 1.05 < found.best["hinge-width"] < 1.3
    narrower = history[history["hinge-width"] < found.best["hinge-width"]]
    assert (narrower["largest_strain"] > 0.6).all()


def test_the_same_seed_gives_the_same_trials_and_a_rerun_replays_them(tmp_path,
                                                                      monkeypatch):
    def run(seed, trials=6, **kw):
        return study.optimize("miura", {"hinge-width": WIDTHS, "gamma": (45.0, 75.0)},
                              "largest_strain", fixed={**MIURA, "n": 2, "m": 2},
                              trials=trials, seed=seed, **{"workers": 0, **kw})

    first, again = run(0, cache=None), run(0, cache=None)
    columns = ["hinge-width", "gamma", "objective"]
    assert first.history[columns].equals(again.history[columns])
    assert not first.history["hinge-width"].equals(run(1, cache=None).history["hinge-width"])

    folded = run(0, cache=tmp_path)
    assert not folded.history["cached"].any()

    def no_cluster(*args, **kwargs):
        raise AssertionError("a replay started a cluster")

    with monkeypatch.context() as patched:  # all cached: no cluster is started
        patched.setattr("foldcore.study.execute.session", no_cluster)
        replayed = run(0, cache=tmp_path, workers=2, batch=1)
    assert replayed.history["cached"].all()
    assert replayed.history[columns].equals(folded.history[columns])
    longer = run(0, trials=8, cache=tmp_path)
    assert list(longer.history["cached"]) == [True] * 6 + [False] * 2
    assert longer.history[columns].head(6).equals(folded.history[columns])


def test_a_failed_fold_is_a_row_with_its_error_and_the_study_goes_on():
    """Hinges wider than about 17 mm do not fit the 20 mm Miura edges: those trials
    fail (told FAILED), the others are the history's feasible rows."""
    found = study.optimize("miura", {"hinge-width": (1.0, 30.0)}, "largest_strain",
                           fixed={**MIURA, "n": 2, "m": 2}, trials=8, workers=0, cache=None)
    history = found.history
    failed = history[history["error"] != ""]
    assert len(failed) and len(failed) < len(history)
    assert failed["error"].str.contains("too short for the hinge widths").all()
    assert failed["objective"].isna().all() and not failed["feasible"].any()
    assert found.trial not in set(failed["trial"])


def test_unconverged_folds_are_infeasible():
    found = study.optimize("miura", {"hinge-width": WIDTHS}, "largest_strain",
                           fixed={**MIURA, "max-iterations": 2}, trials=3, workers=0,
                           cache=None)
    assert not found.history["converged"].any() and not found.history["feasible"].any()
    assert found.best is None and math.isnan(found.value)
    assert found.line() == "no feasible trial among 3"


def test_on_a_local_cluster_the_trials_run_on_its_workers():
    from distributed import Client, LocalCluster

    with LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                      dashboard_address=":0") as cluster, Client(cluster) as client:
        addresses = set(client.scheduler_info(n_workers=-1)["workers"])
        found = study.optimize("miura", {"hinge-width": WIDTHS}, "largest_strain",
                               fixed=MIURA, trials=6, client=client, cache=None)
    assert set(found.history["worker"]) == addresses  # batches of 2, one trial each
    assert (found.history["error"] == "").all() and found.best is not None


def test_the_embedded_cluster_of_two_workers_folds_batches_of_two():
    found = study.optimize("miura", {"hinge-width": WIDTHS}, "largest_strain",
                           fixed={**MIURA, "n": 2, "m": 2}, trials=4, workers=2, cache=None)
    assert found.history["worker"].str.startswith("tcp://").all()
    assert found.history["worker"].nunique() == 2 and found.best is not None


# ------------------------------------------------------------------ command line
FIXED = ["--set", "n=2", "--set", "m=2", "--set", "thickness=0.2", "--set", "fold-percent=60"]


def test_the_command_writes_the_history_and_says_the_best_point(tmp_path, capsys):
    import pandas as pd

    out = tmp_path / "history.csv"
    code = main(["optimize", "miura", "--vary", "hinge-width=0.2:2", *FIXED, "--minimize",
                 "largest_strain", "--trials", "5", "--workers", "0", "--no-cache", "-o",
                 str(out)])
    (line,) = capsys.readouterr().err.splitlines()
    assert code == 0
    assert line.startswith("foldcore: optimize: least largest_strain ")
    assert "hinge-width=" in line
    history = pd.read_csv(out)
    assert list(history["trial"]) == list(range(5)) and history["objective"].notna().all()


METRIC = "def columns(fold):\n    return {'flatness': 1.0}\n"


@pytest.mark.parametrize("args, says", [
    (["--vary", "hinge-widht=0.2:2", "--minimize", "largest_strain"], "unknown name"),
    (["--vary", "hinge-width=2:0.2", "--minimize", "largest_strain"], "not below HIGH"),
    (["--vary", "hinge-width=0.2", "--minimize", "largest_strain"], "one value"),
    (["--vary", "hinge-width=-1:2", "--minimize", "largest_strain"], "hinge-width"),
    (["--vary", "max-iterations=10.5:100", "--minimize", "largest_strain"], "integers"),
    (["--vary", "gamma=30:95", "--minimize", "largest_strain"], "gamma"),
    (["--vary", "thickness=0.1:0.3", "--minimize", "largest_strain"], "both varied and fixed"),
    (["--vary", "hinge-width=0.2:2", "--minimize", "strain"], "not a column"),
    (["--vary", "hinge-width=0.2:2", "--minimize", "reason"], "not a column"),
    (["--vary", "hinge-width=0.2:2", "--minimize", "largest_strain", "--at-most", "x=y"],
     "--at-most"),
    (["--vary", "hinge-width=0.2:2"], "--minimize"),
    (["--vary", "hinge-width=0.2:2", "--minimize", "a", "--maximize", "b"], "not allowed"),
    (["--vary", "hinge-width=0.2:2", "--minimize", "flatnes", "--metric", "{metric}"],
     "no such column"),
])
def test_bad_input_exits_2_with_one_line_and_no_output(args, says, tmp_path, capsys):
    metric = tmp_path / "metric.py"
    metric.write_text(METRIC)
    out = tmp_path / "history.csv"
    args = [a.replace("{metric}", f"{metric}:columns") for a in args]
    code = main(["optimize", "miura", *args, *FIXED, "--trials", "2", "--workers", "0",
                 "--no-cache", "-o", str(out)])
    (line,) = capsys.readouterr().err.splitlines()
    assert code == 2 and says in line and line.startswith("foldcore: "), line
    assert not out.exists()


def test_python_m_foldcore_optimize_refuses_in_one_line(tmp_path):
    import subprocess

    proc = subprocess.run([sys.executable, "-m", "foldcore", "optimize", "miura", "--vary",
                           "hinge-width=2:2", "--minimize", "largest_strain", "-o",
                           str(tmp_path / "h.csv")], capture_output=True, text=True,
                          timeout=300)
    assert proc.returncode == 2 and len(proc.stderr.splitlines()) == 1, proc.stderr
