"""The developer pages' examples run as printed: a strategy and an element type are
added by a new file only (docs/adding-a-strategy.md, docs/adding-an-element-type.md)."""
from __future__ import annotations

import re
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def python_blocks(page: str) -> list[str]:
    return re.findall(r"```python\n(.*?)```", (ROOT / "docs" / page).read_text(), re.S)


def run(tmp_path, files: dict, main: str) -> list[str]:
    """Write ``files`` (name → code) to a fresh folder and run ``main`` there in a new
    process (a registry starts empty); its printed lines."""
    for name, code in files.items():
        (tmp_path / name).write_text(code)
    (tmp_path / "main.py").write_text(main)
    proc = subprocess.run([sys.executable, "main.py"], cwd=tmp_path, capture_output=True,
                          text=True, timeout=600, check=False)
    assert proc.returncode == 0, proc.stderr
    return proc.stdout.splitlines()


def test_a_new_strategy_is_one_new_file(tmp_path):
    """The page's module, saved as my_strategies.py, registers ``relaxed``; the usage
    block folds the hinge with it and with ``paper`` to the same angle, and the
    over-relaxed map takes fewer iterations (ω = 1.8 on a map contracting slowly)."""
    module, usage, convergence = python_blocks("adding-a-strategy.md")
    lines = run(tmp_path, {"my_strategies.py": module}, usage)
    rows = {line.split()[0]: line.split()[1:] for line in lines}
    assert rows["paper"][0] == rows["relaxed"][0] == "converged"
    assert float(rows["paper"][2]) == float(rows["relaxed"][2]) == 60.0
    assert int(rows["relaxed"][1]) < int(rows["paper"][1])
    lines = run(tmp_path, {}, convergence)
    rows = {line.split()[0]: line.split()[1:] for line in lines}
    assert rows["EnergyBelow"][0] == rows["ConvergenceTest"][0] == "converged"
    assert int(rows["EnergyBelow"][1]) <= int(rows["ConvergenceTest"][1])


def test_a_new_element_type_is_one_new_file(tmp_path):
    """The page's module is examples/plugin_bar/bar.py as it is, and its usage block
    folds a hinge propped by a bar of that type short of its target."""
    module, usage = python_blocks("adding-an-element-type.md")[:2]
    assert module == (ROOT / "examples" / "plugin_bar" / "bar.py").read_text()
    lines = run(tmp_path, {"bar.py": module}, usage)
    reason, _, angle = lines[-1].split()
    # a 30 mm strut between edges 2 × 19 mm from the hinge: cos(φ/2) ≈ 30 / 38 (+ the
    # hinge's own chord, − H sin(φ/2)), φ ≈ 80°, far short of the 90° target
    assert reason == "converged" and 75.0 < float(angle) < 85.0
