"""Test-suite settings shared by every file.

Hypothesis draws the same examples on every run here (``derandomize``), so CI
is red only when the code changes; ``FOLDCORE_HYPOTHESIS=random`` explores
with fresh randomness (how the stress tests found the unanchored first
factorisation). Profiles set per test (``@settings``) inherit this default.
"""
import os

from hypothesis import settings

settings.register_profile("foldcore", derandomize=True)
settings.register_profile("foldcore-random", derandomize=False)
settings.load_profile("foldcore-random" if os.environ.get("FOLDCORE_HYPOTHESIS") == "random"
                      else "foldcore")
