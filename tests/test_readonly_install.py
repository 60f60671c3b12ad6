"""A read-only install without a writable home still runs.

numba's ``cache=True`` raises ``no locator available`` at the decorator when
neither ``NUMBA_CACHE_DIR``, the in-tree ``__pycache__`` nor ``~/.cache/numba``
is writable. ``elements.cache.choose_cache_dir`` then falls back to another
folder, or to no cache, with one warning line.

The reproducer is real: a copy of the package sources with write permission
removed, imported in a child process that cannot write it. chmod does not stop
root, so as root the child runs as ``nobody`` (``setpriv``); as another user,
chmod alone is enough. ``HOME`` points at the read-only copy.
"""
from __future__ import annotations

import os
import shutil
import stat
import subprocess
import sys
import tempfile
from pathlib import Path

import pytest

from elements import cache as _cache

SRC = Path(__file__).resolve().parents[1] / "src"
IS_ROOT = hasattr(os, "geteuid") and os.geteuid() == 0
SETPRIV = shutil.which("setpriv")
pytestmark = pytest.mark.skipif(sys.platform == "win32" or (IS_ROOT and not SETPRIV),
                                reason="needs POSIX permissions (and setpriv when run as root)")

FOLD_HINGE = """
import foldcore
pattern = foldcore.patterns.single_hinge(panel_length=5, angle=90)
mesh = foldcore.thicken(pattern, thickness=1.0, hinge_width=2.0, subdivisions=4)
result = foldcore.Simulation(mesh, pattern).run(tolerance=1e-9)
print(result.converged, result.fold_angles_deg[0])
"""


@pytest.fixture
def install():
    """(read-only copy of src/elements and src/foldcore, writable temp folder), both
    reachable by the child's user; removed afterwards."""
    root = Path(tempfile.mkdtemp(prefix="foldcore-ro-"))
    os.chmod(root, 0o755)
    site = root / "site"
    for package in ("elements", "foldcore"):
        shutil.copytree(SRC / package, site / package,
                        ignore=shutil.ignore_patterns("__pycache__"))
    for path in [site, *site.rglob("*")]:
        mode = path.stat().st_mode
        path.chmod(mode & ~0o222 | (0o555 if path.is_dir() else 0o444))
    tmp = root / "tmp"
    tmp.mkdir()
    os.chmod(tmp, 0o1777)
    yield site, tmp
    for path in [site, *site.rglob("*")]:
        path.chmod(path.stat().st_mode | stat.S_IWUSR)
    shutil.rmtree(root)


def run_child(site, tmp, code):
    """Run ``code`` with the read-only copy first on the path, unable to write it."""
    env = {"PATH": os.environ.get("PATH", "/usr/bin:/bin"), "PYTHONPATH": str(site),
           "HOME": str(site), "TMPDIR": str(tmp)}
    prefix = [SETPRIV, "--reuid=nobody", "--regid=nogroup", "--clear-groups"] if IS_ROOT else []
    return subprocess.run([*prefix, sys.executable, "-c", code], capture_output=True, text=True,
                          env=env, cwd=str(tmp), timeout=600, check=False)


def test_the_copy_is_really_read_only_for_the_child(install):
    site, tmp = install
    proc = run_child(site, tmp, f"open({str(site / 'probe')!r}, 'w')")
    assert proc.returncode != 0 and "PermissionError" in proc.stderr


@pytest.mark.slow
def test_a_read_only_install_folds_a_hinge_caching_in_a_fallback_folder(install):
    """Slow: compiles every kernel the hinge needs from cold."""
    site, tmp = install
    proc = run_child(site, tmp, FOLD_HINGE)
    assert proc.returncode == 0, proc.stderr
    fallback = tmp / f"foldcore-numba-{65534 if IS_ROOT else os.getuid()}"
    (line,) = proc.stderr.splitlines()
    assert "KernelCacheWarning" in line and str(fallback) in line and "NUMBA_CACHE_DIR" in line
    converged, angle = proc.stdout.split()
    # the same hinge folds to 90° within 0.05° in tests/test_cli.py
    assert converged == "True" and abs(float(angle) - 90.0) < 0.05
    # numba names a cache folder after the source's folder: the rigid-body kernels'
    # is foldcore/strategies/rigid
    for package in ("elements", "rigid"):
        (folder,) = fallback.glob(f"{package}_*")
        assert list(folder.glob("*.nbi")), f"no kernel of {package} was cached"
    # the stale-kernel guard stamps the fallback folder too
    (elements_folder,) = fallback.glob("elements_*")
    assert (elements_folder / _cache.STAMP_NAME).exists()


def test_with_no_writable_folder_at_all_kernels_run_uncached(install):
    """The temporary folder is read-only too: caching of foldcore's kernels is turned
    off, one warning says so, and a kernel still compiles and runs."""
    site, tmp = install
    code = ("import tempfile; tempfile.tempdir = " + repr(str(site)) + "\n"
            "import foldcore.system, foldcore.strategies.rigid.normal\n"
            "from elements.rotation import _det\n"
            "print(_det(2.0, 0.0, 0.0, 0.0, 3.0, 0.0, 0.0, 0.0, 4.0))\n")
    proc = run_child(site, tmp, code)
    assert proc.returncode == 0, proc.stderr
    (line,) = proc.stderr.splitlines()   # one warning for both packages' folders
    assert "KernelCacheWarning" in line and "no fallback folder" in line
    assert "NUMBA_CACHE_DIR" in line
    assert float(proc.stdout) == 24.0
    assert not list(tmp.iterdir())


def test_a_writable_install_keeps_numbas_own_cache():
    import elements

    assert _cache.choose_cache_dir(Path(elements.__file__)) is None


def test_a_fallback_folder_others_can_write_is_refused(tmp_path):
    """numba's cache files are pickles: loading one planted by another user would run
    their code, so a group- or world-writable folder is not used."""
    shared = tmp_path / "shared"
    shared.mkdir()
    shared.chmod(0o777)
    assert not _cache._private_writable(shared)
    shared.chmod(0o700)
    assert _cache._private_writable(shared)


def test_fallback_folders_follow_xdg_then_home_then_temp(monkeypatch, tmp_path):
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "xdg"))
    monkeypatch.setenv("HOME", str(tmp_path / "home"))
    dirs = _cache.fallback_dirs()
    assert dirs[:2] == [tmp_path / "xdg" / "foldcore-numba",
                        tmp_path / "home" / ".cache" / "foldcore-numba"]
    assert dirs[2].parent == Path(tempfile.gettempdir())
