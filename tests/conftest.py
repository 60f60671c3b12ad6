"""Test-suite settings shared by every file.

Hypothesis draws the same examples on every run here (``derandomize``), so CI
is red only when the code changes; ``FOLDCORE_HYPOTHESIS=random`` explores
with fresh randomness (how the stress tests found the unanchored first
factorisation). Profiles set per test (``@settings``) inherit this default.
"""
import os

import pytest
from hypothesis import settings

settings.register_profile("foldcore", derandomize=True)
settings.register_profile("foldcore-random", derandomize=False)
settings.load_profile("foldcore-random" if os.environ.get("FOLDCORE_HYPOTHESIS") == "random"
                      else "foldcore")


@pytest.fixture(scope="session")
def runs():
    """Every built-in scene at reduced budgets (``quick=True``), run once per session
    (tests/test_scenes.py, tests/test_scene_box.py)."""
    from foldcore import scenes

    return {name: scenes.run(name, quick=True) for name in scenes.NAMES}


@pytest.fixture
def hinge_file(tmp_path):
    """A FOLD file of one 90° valley hinge (panels 5 × 2 mm, W = 2 mm, H = 1 mm)."""
    from foldcore import patterns
    from foldcore.io import write_fold

    pattern = patterns.single_hinge(panel_length=5.0, depth=2.0, angle=90.0, width=2.0)
    path = tmp_path / "hinge.fold"
    write_fold(path, pattern, thickness=1.0)
    return path
