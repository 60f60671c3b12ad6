"""numba keys a cached kernel on its own source file only; elements.cache drops the
package's cache files whenever any of its sources changed (a helper edited in
_rotation.py must reach every kernel that calls it)."""
from __future__ import annotations

from elements import cache as _cache


def make_package(root):
    (root / "helper.py").write_text("def f():\n    return 1\n")
    (root / "kernel.py").write_text("from .helper import f\n")
    cache = root / "__pycache__"
    cache.mkdir()
    for name in ("kernel.batch-3.py311.nbi", "kernel.batch-3.py311.1.nbc", "kernel.cpython-311.pyc"):
        (cache / name).write_bytes(b"compiled")
    return cache


def test_first_import_clears_then_stamps_and_keeps_a_matching_cache(tmp_path):
    cache = make_package(tmp_path)
    assert _cache.drop_stale_kernels(tmp_path, "0.68.1") == 2
    assert sorted(p.name for p in cache.iterdir()) == [_cache.STAMP_NAME,
                                                      "kernel.cpython-311.pyc"]
    (cache / "kernel.batch-3.py311.nbi").write_bytes(b"recompiled")
    assert _cache.drop_stale_kernels(tmp_path, "0.68.1") == 0
    assert (cache / "kernel.batch-3.py311.nbi").exists()


def test_an_edited_helper_drops_the_kernels_that_may_have_inlined_it(tmp_path):
    cache = make_package(tmp_path)
    _cache.drop_stale_kernels(tmp_path, "0.68.1")
    (cache / "kernel.batch-3.py311.nbi").write_bytes(b"compiled with f() == 1")
    (tmp_path / "helper.py").write_text("def f():\n    return 2\n")
    assert _cache.drop_stale_kernels(tmp_path, "0.68.1") == 1
    assert not (cache / "kernel.batch-3.py311.nbi").exists()


def test_numba_cache_dir_location_is_covered(tmp_path, monkeypatch):
    from numba.core import config

    (tmp_path / "pkg").mkdir()
    make_package(tmp_path / "pkg")
    monkeypatch.setattr(config, "CACHE_DIR", str(tmp_path / "numba-cache"))
    folders = _cache.cache_dirs(tmp_path / "pkg")
    assert folders[0] == tmp_path / "pkg" / "__pycache__"
    assert folders[1].parent == tmp_path / "numba-cache" and folders[1].name.startswith("pkg_")
    _cache.drop_stale_kernels(tmp_path / "pkg", "0.68.1")
    assert (folders[1] / _cache.STAMP_NAME).exists()


def test_the_installed_package_is_stamped():
    from pathlib import Path

    import elements
    import numba

    package = Path(elements.__file__).parent
    marker = package / "__pycache__" / _cache.STAMP_NAME
    assert marker.read_text() == _cache.sources_digest(package, numba.__version__)


def test_a_plugin_tracks_the_helpers_it_calls_through_extra_dirs(tmp_path):
    plugin, helpers = tmp_path / "plugin", tmp_path / "helpers"
    plugin.mkdir(), helpers.mkdir()
    cache = make_package(plugin)
    (helpers / "rotation.py").write_text("R = 1\n")
    _cache.drop_stale_kernels(plugin, "0.68.1", extra_dirs=[helpers])
    (cache / "kernel.batch-3.py311.nbi").write_bytes(b"compiled against R = 1")
    assert _cache.drop_stale_kernels(plugin, "0.68.1", extra_dirs=[helpers]) == 0
    (helpers / "rotation.py").write_text("R = 2\n")
    assert _cache.drop_stale_kernels(plugin, "0.68.1", extra_dirs=[helpers]) == 1


def test_a_guarded_module_ignores_its_siblings_and_keeps_their_caches(tmp_path):
    package = tmp_path / "pkg"
    package.mkdir()
    (package / "solver.py").write_text("def f(): pass\n")
    (package / "other.py").write_text("x = 1\n")
    (package / "helper.py").write_text("H = 1\n")
    cache = package / "__pycache__"
    cache.mkdir()
    _cache.drop_stale_kernels(package, "0.68.1", module="solver")
    (cache / "solver.f-1.py311.nbi").write_bytes(b"")
    (cache / "other.g-1.py311.nbi").write_bytes(b"")
    (package / "other.py").write_text("x = 2\n")  # a sibling edited: nothing to drop
    assert _cache.drop_stale_kernels(package, "0.68.1", module="solver") == 0
    (package / "solver.py").write_text("def f(): return 1\n")
    assert _cache.drop_stale_kernels(package, "0.68.1", module="solver") == 1
    assert sorted(p.name for p in cache.glob("*.nbi")) == ["other.g-1.py311.nbi"]
