"""Keep numba's on-disk kernel cache consistent with the sources it was built from.

numba's ``cache=True`` keys each compiled function on its *own* source file
(modification time and size). A kernel that calls a helper from another
module — every element type calls :func:`elements.rotation.fit_rotated` —
keeps running the helper it was compiled with after the helper's file
changes (docs/architecture.md#stale-kernels-after-a-helper-changes).

The guard: a stamp (SHA-256 of the package's ``*.py`` sources and the numba
version) is kept beside numba's cache files; when it differs at import, every
numba index/data file (``*.nbi``, ``*.nbc``) of the package is removed, so
each kernel compiles once more from the current sources, and the new stamp is
written. Cost at import: hashing ~30 kB (≈ 0.1 ms).

Scope: the package's in-tree ``__pycache__`` and, when ``NUMBA_CACHE_DIR`` is
set (by the user or by :func:`choose_cache_dir`'s fallback), the package's
folder there (numba's locations for a writable tree).
Not covered: a long-running process that imported the old modules and
compiles a new specialisation after another process stamped the new sources
(its stale kernel then sits under a matching stamp; restart such sessions
after editing kernels). Editing any file of the package (even a docstring)
recompiles every kernel once. A wheel install does not need it (reinstalling rewrites every
source, which numba sees), an editable checkout does. Kernels outside this
package (plugins) that call its helpers are not covered: clear their
``__pycache__`` after upgrading foldcore (docs/adding-an-element-type.md).
"""
from __future__ import annotations

import hashlib
import os
import tempfile
import warnings
from pathlib import Path

STAMP_NAME = "foldcore-kernel-sources.sha256"
NUMBA_SUFFIXES = (".nbi", ".nbc")
FALLBACK_NAME = "foldcore-numba"


def sources_digest(package_dir: Path, numba_version: str, extra_dirs=(), module=None) -> str:
    """SHA-256 (hex) over the numba version and each ``*.py`` file's name and bytes, in
    ``package_dir`` (only ``module``.py when given) and then each of ``extra_dirs``
    (folders of helpers it calls)."""
    digest = hashlib.sha256(numba_version.encode())
    for folder, pattern in ((package_dir, f"{module}.py" if module else "*.py"),
                            *((d, "*.py") for d in extra_dirs)):
        for path in sorted(Path(folder).glob(pattern)):
            digest.update(path.name.encode() + b"\0" + path.read_bytes() + b"\0")
    return digest.hexdigest()


def cache_dirs(package_dir: Path) -> list[Path]:
    """Where numba writes this package's cache: ``__pycache__`` beside the sources
    and, if ``NUMBA_CACHE_DIR`` is set, the package's folder there (named by
    numba's own locator)."""
    dirs = [package_dir / "__pycache__"]
    from numba.core import caching, config

    if config.CACHE_DIR:
        try:  # numba's private naming of the folder; if it changes, skip that location
            subpath = caching._CacheLocator.get_suitable_cache_subpath(str(package_dir / "x.py"))
        except Exception:  # noqa: BLE001 - never break `import elements` over a cache
            return dirs
        dirs.append(Path(config.CACHE_DIR) / subpath)
    return dirs


def drop_stale_kernels(package_dir: Path, numba_version: str, extra_dirs=(),
                       module=None) -> int:
    """Remove numba cache files built from other sources than the current ones.

    Parameters
    ----------
    package_dir : Path
        Directory holding the kernel modules.
    numba_version : str
        Part of the stamp (a new numba recompiles anyway; kept for clarity).
    extra_dirs : sequence of Path
        Folders of helpers the kernels call (a plugin passes the ``elements``
        folder, so a foldcore upgrade that changes ``rotation`` drops its
        kernels too).
    module : str, optional
        Guard one module of ``package_dir`` only (its source, its cache files,
        its own stamp), e.g. a module of foldcore whose kernels call
        ``elements.rotation``, so that editing the package's other files does
        not recompile them.

    Returns
    -------
    int
        Number of cache files removed (0 when the stamp matched or there was
        no cache yet). Best effort: unreadable or read-only locations are left
        alone (numba then recompiles into its user-wide cache, keyed per file).
    """
    stamp = sources_digest(package_dir, numba_version, extra_dirs, module)
    removed = 0
    for folder in cache_dirs(package_dir):
        marker = folder / (f"{module}-{STAMP_NAME}" if module else STAMP_NAME)
        try:
            if marker.read_text() == stamp:
                continue
        except OSError:
            pass
        try:
            folder.mkdir(parents=True, exist_ok=True)
            for path in folder.iterdir():
                if path.suffix in NUMBA_SUFFIXES and (module is None
                                                      or path.name.startswith(f"{module}.")):
                    path.unlink(missing_ok=True)
                    removed += 1
            partial = marker.with_suffix(f".{os.getpid()}.tmp")
            partial.write_text(stamp)
            os.replace(partial, marker)
        except OSError:
            continue
    return removed


def _numba_can_cache(py_file: Path) -> bool:
    """Whether one of numba's own cache locators accepts ``py_file`` (each one
    creates its folder and a temporary file there, as numba does per kernel)."""
    from numba.core import caching, config

    def probe():
        pass

    try:
        classes = caching.FunctionCache._impl_class._locator_classes
    except AttributeError:  # numba renamed its private list: keep numba's behaviour
        return True
    if config.CACHE_LOCATOR_CLASSES:  # the user chose numba's locators
        return True
    return any(cls.from_function(probe, str(py_file)) is not None for cls in classes)


def _private_writable(folder: Path) -> bool:
    """Whether ``folder`` can be created or used as this user's own cache: writable
    and, because numba's cache files are pickles that run code when loaded, owned
    by this user and not writable by group or others."""
    try:
        folder.mkdir(mode=0o700, parents=True, exist_ok=True)
        st = folder.stat()
        if hasattr(os, "getuid") and (st.st_uid != os.getuid() or st.st_mode & 0o022):
            return False
        tempfile.TemporaryFile(dir=folder).close()
    except OSError:
        return False
    return True


def fallback_dirs() -> list[Path]:
    """Cache folders tried, in order, when numba has no usable locator:
    ``$XDG_CACHE_HOME/foldcore-numba``, ``~/.cache/foldcore-numba`` and a
    per-user ``foldcore-numba-<user>`` under :func:`tempfile.gettempdir`."""
    dirs = []
    if os.environ.get("XDG_CACHE_HOME"):
        dirs.append(Path(os.environ["XDG_CACHE_HOME"]) / FALLBACK_NAME)
    home = os.path.expanduser("~")
    if home != "~":
        dirs.append(Path(home) / ".cache" / FALLBACK_NAME)
    user = os.getuid() if hasattr(os, "getuid") else os.environ.get("USERNAME", "user")
    try:
        dirs.append(Path(tempfile.gettempdir()) / f"{FALLBACK_NAME}-{user}")
    except OSError:  # no usable temporary folder at all
        pass
    return dirs


def _disable_caching_of(packages: tuple[str, ...]) -> None:
    """Make ``cache=True`` a no-op for functions of ``packages`` (numba would raise
    ``no locator available`` at their decorator); other packages keep numba's
    behaviour."""
    from numba.core.dispatcher import Dispatcher

    enable = Dispatcher.enable_caching

    def enable_caching(self):
        if self.py_func.__module__.split(".")[0] not in packages:
            enable(self)

    Dispatcher.enable_caching = enable_caching


_CHOSEN: dict[Path, str | None] = {}


def choose_cache_dir(py_file: Path) -> str | None:
    """Make sure the ``cache=True`` kernels of ``py_file``'s folder can be decorated.

    Call before the folder's first ``@njit(cache=True)``. When numba can cache
    there (``NUMBA_CACHE_DIR``, the in-tree ``__pycache__`` or its user-wide
    folder: a cheap check, one temporary file), nothing changes. Otherwise (a
    read-only install without a writable home) ``NUMBA_CACHE_DIR`` is set, in
    ``numba.config`` and in the environment (child processes follow), to the
    first usable :func:`fallback_dirs`; if there is none, caching of
    foldcore's kernels is turned off (they compile in every process). Either
    way one :class:`foldcore.errors.KernelCacheWarning` line says which.

    Parameters
    ----------
    py_file : Path
        A source file of the folder whose kernels are about to be decorated.

    Returns
    -------
    str or None
        The fallback folder chosen, ``""`` for no cache, None when numba's own
        locations work.
    """
    folder = Path(py_file).parent
    if folder not in _CHOSEN:
        if "" in _CHOSEN.values():  # caching of foldcore's kernels is already off
            _CHOSEN[folder] = ""
        elif _numba_can_cache(py_file):
            _CHOSEN[folder] = None
        else:
            _CHOSEN[folder] = next((str(d) for d in fallback_dirs() if _private_writable(d)), "")
            _apply(_CHOSEN[folder], folder)
    return _CHOSEN[folder]


def _apply(chosen: str, folder: Path) -> None:
    """Point numba at ``chosen`` (or turn caching off when it is empty); warn in one line."""
    from numba.core import config

    from foldcore.errors import KernelCacheWarning  # only on this rare path

    where = f"numba cannot write a kernel cache for {folder}"
    if chosen:
        config.CACHE_DIR = os.environ["NUMBA_CACHE_DIR"] = chosen
        message = f"{where}; caching kernels in {chosen} (set NUMBA_CACHE_DIR to choose)"
    else:
        _disable_caching_of(("elements", "foldcore"))
        message = (f"{where} and no fallback folder is writable; kernels will compile in "
                   "every process (set NUMBA_CACHE_DIR to a writable folder)")
    # line 0: no source line under the message, so the warning is one line of stderr
    warnings.warn_explicit(message, KernelCacheWarning, "foldcore", 0, module="foldcore")
