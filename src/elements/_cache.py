"""Keep numba's on-disk kernel cache consistent with the sources it was built from.

numba's ``cache=True`` keys each compiled function on its *own* source file
(modification time and size). A kernel that calls a helper from another
module — every element type calls :func:`elements._rotation.fit_rotated` —
keeps running the helper it was compiled with after the helper's file
changes. Measured here: after the scaled-Newton polar factor replaced the
per-element SVD in ``_rotation.py``, ``rigid_panel``'s cached batch still ran
the SVD, 3.1 µs per panel instead of 0.39 µs (Miura 40 × 40, one thread).

The guard: a stamp (SHA-256 of the package's ``*.py`` sources and the numba
version) is kept beside numba's cache files; when it differs at import, every
numba index/data file (``*.nbi``, ``*.nbc``) of the package is removed, so
each kernel compiles once more from the current sources, and the new stamp is
written. Cost at import: hashing ~30 kB (≈ 0.1 ms).

Scope: the package's in-tree ``__pycache__`` and, when ``NUMBA_CACHE_DIR`` is
set, the package's folder there (numba's locations for a writable tree).
Not covered: a long-running process that imported the old modules and
compiles a new specialisation after another process stamped the new sources
(its stale kernel then sits under a matching stamp; restart such sessions
after editing kernels). Editing any file of the package (even a docstring)
recompiles every kernel once. A wheel install does not need it (reinstalling rewrites every
source, which numba sees), an editable checkout does. Kernels outside this
package (plugins) that call its helpers are not covered: clear their
``__pycache__`` after upgrading foldcore (docs/elements.md).
"""
from __future__ import annotations

import hashlib
import os
from pathlib import Path

STAMP_NAME = "foldcore-kernel-sources.sha256"
NUMBA_SUFFIXES = (".nbi", ".nbc")


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
        folder, so a foldcore upgrade that changes ``_rotation`` drops its
        kernels too).
    module : str, optional
        Guard one module of ``package_dir`` only (its source, its cache files,
        its own stamp), e.g. a module of foldcore whose kernels call
        ``elements._rotation``, so that editing the package's other files does
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
