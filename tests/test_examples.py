"""Every script in examples/ runs from a fresh interpreter and writes its outputs."""
from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

EXAMPLES_DIR = Path(__file__).parent.parent / "examples"
EXAMPLES = sorted(EXAMPLES_DIR.glob("*.py"))


@pytest.mark.parametrize("script", EXAMPLES, ids=lambda p: p.stem)
def test_example_runs(script, tmp_path):
    proc = subprocess.run([sys.executable, str(script), str(tmp_path)], capture_output=True,
                          text=True, timeout=600)
    assert proc.returncode == 0, proc.stderr
    written = {p.suffix for p in tmp_path.iterdir()}
    assert {".fold", ".json", ".png"} <= written


def test_plugin_element_type_props_a_hinge(tmp_path):
    """examples/plugin_bar: a bar (a type defined outside foldcore) holds a hinge
    actuated to 90° near the 60° at which the bar is at rest. The bar's weight is
    100× the hinge's, so it yields ~1/100 of the 30° disagreement (lever factors of
    order 1): within 1° of 60°, and on the 90° side."""
    sys.path.insert(0, str(EXAMPLES_DIR / "plugin_bar"))
    import prop

    import elements

    angle = prop.main(str(tmp_path))
    assert 60.0 < angle < 61.0
    assert elements.registered()["bar"] == "bar"
    assert (tmp_path / "prop.fold").exists() and (tmp_path / "prop.json").exists()
