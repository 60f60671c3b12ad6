"""Every output file foldcore writes goes through here: complete or not at all.

A writer is handed a temporary path (or an open file) in the destination's own
folder; only when it returns without an exception is the temporary file
fsynced (open files) and renamed over the destination, so a reader never sees
a half-written file and an error leaves the old file as it was. Any exception
removes the temporary file, including ``KeyboardInterrupt`` and the exception
the command line raises for SIGTERM (:class:`foldcore.interrupts.Terminated`), so
Ctrl-C or a kill leaves nothing behind; SIGKILL cannot be caught and may leave a
``.NAME.PID.HEX.tmp`` file. :func:`all_or_nothing` extends this to several
files: none is renamed until every writer has succeeded.

Every file foldcore reads is first checked here too (:func:`check_input`): a
named pipe, a device or a folder is refused before it is opened, where a
read would block forever or never end.

Design notes: ``docs/architecture.md#output-files-one-module-writes-them-all``.
"""
from __future__ import annotations

import errno
import os
import secrets
import stat
from contextlib import ExitStack, contextmanager, suppress

from .errors import FoldcoreError

#: Longest destination suffix kept on a temporary name (longer ones are dropped, so the
#: temporary name stays within NAME_MAX).
MAX_SUFFIX = 16


class OutputError(FoldcoreError, ValueError):
    """An output path cannot be written: no such folder, a folder, an input file, or
    given twice."""


class ExportError(FoldcoreError, ValueError):
    """A fabrication file cannot be made (bad geometry, missing package, no output)."""


class InputError(FoldcoreError, ValueError):
    """An input path is not a regular file that can be read."""


#: What a path that is not a regular file is, by its ``stat`` mode.
_KINDS = ((stat.S_ISDIR, "a folder"), (stat.S_ISFIFO, "a named pipe (FIFO)"),
          (stat.S_ISCHR, "a character device"), (stat.S_ISBLK, "a block device"),
          (stat.S_ISSOCK, "a socket"))


def check_input(path, error: type = InputError) -> os.stat_result:
    """The ``stat`` of an input path that is a regular file (symbolic links followed);
    ``error`` (a :class:`~foldcore.errors.FoldcoreError`) naming ``path`` otherwise:
    missing or unreadable, or a folder, a named pipe (whose read blocks until a
    writer comes), a device or a socket, refused before it is opened."""
    source = os.fspath(path)
    try:
        info = os.stat(source)
    except OSError as exc:
        raise error(f"{source}: cannot read the file ({exc.strerror or exc})") from None
    except ValueError as exc:  # e.g. a NUL byte in the path
        raise error(f"{source}: cannot read the file (invalid path: {exc})") from None
    if not stat.S_ISREG(info.st_mode):
        kind = next((name for test, name in _KINDS if test(info.st_mode)), "not a file")
        raise error(f"{source}: cannot read the file: it is {kind}, not a regular file")
    return info


def check_folder(path, error: type = OutputError) -> None:
    """Refuse an output path whose folder does not exist.

    Parameters
    ----------
    path : str or os.PathLike
    error : type
        The exception raised (a :class:`~foldcore.errors.FoldcoreError`), naming
        ``path`` and its folder.
    """
    target = os.fspath(path)
    folder, name = os.path.split(os.path.abspath(target))
    if not name or not os.path.isdir(folder):
        raise error(f"{target}: cannot write there (no such folder: {folder})")


@contextmanager
def atomic_path(path, suffix: str | None = None):
    """A temporary path (same folder) that is renamed to ``path`` if the block succeeds.

    For writers that take a file name (pyvista, imageio). The temporary name
    starts with a prefix of the target's name (so it fits NAME_MAX) and ends
    in ``.tmp`` + ``suffix`` (default: ``path``'s own suffix), so writers that
    choose a format from the name still do. On any exception the temporary
    file is removed and ``path`` is left as it was; an OSError about the
    temporary file is re-raised naming ``path``.

    Parameters
    ----------
    path : str or os.PathLike
        The destination.
    suffix : str, optional
        End of the temporary name, e.g. ``".png"``.

    Yields
    ------
    str
        The temporary path to write.
    """
    target = os.fspath(path)
    folder, name = os.path.split(os.path.abspath(target))
    if suffix is None:
        suffix = os.path.splitext(name)[1]
    suffix = suffix if len(suffix) <= MAX_SUFFIX else ""
    tmp = os.path.join(folder, f".{name[:50]}.{os.getpid()}.{secrets.token_hex(4)}.tmp{suffix}")
    try:
        yield tmp
        if not os.path.exists(tmp):
            raise OSError(errno.ENOENT, "the writer produced no file", target)
        os.replace(tmp, target)
    except OSError as exc:
        with suppress(OSError):
            os.unlink(tmp)
        if exc.filename != tmp:
            raise
        raise OSError(exc.errno, exc.strerror, target) from None  # the user's name, not ours
    except BaseException:
        with suppress(OSError):
            os.unlink(tmp)
        raise


@contextmanager
def atomic_write(path, binary: bool = False):
    """An open file (text UTF-8 with ``\\n`` line ends, or bytes) that appears at ``path``
    only when complete: written to a temporary file, fsynced, renamed over ``path``
    (:func:`atomic_path`).

    Parameters
    ----------
    path : str or os.PathLike
    binary : bool
        Open for bytes instead of text.
    """
    with atomic_path(path) as tmp:
        mode = {"mode": "xb"} if binary else {"mode": "x", "encoding": "utf-8", "newline": "\n"}
        with open(tmp, **mode) as fh:
            yield fh
            fh.flush()
            os.fsync(fh.fileno())


def write_bytes(path, data: bytes) -> None:
    """Write ``data`` to ``path`` atomically (:func:`atomic_write`)."""
    with atomic_write(path, binary=True) as fh:
        fh.write(data)


def write_text(path, text: str) -> None:
    """Write ``text`` (UTF-8) to ``path`` atomically (:func:`atomic_write`)."""
    with atomic_write(path) as fh:
        fh.write(text)


@contextmanager
def all_or_nothing(paths: dict):
    """Temporary paths for every destination, renamed over them only if the block
    succeeds; on any exception (a signal's included) every temporary is removed
    and no destination is touched.

    Parameters
    ----------
    paths : dict {key: path or None}

    Yields
    ------
    dict {key: temporary path}, for the keys whose path is not None (each ends
    with its destination's suffix, for writers that choose a format by name).
    """
    with ExitStack() as stack:
        yield {key: stack.enter_context(atomic_path(path))
               for key, path in paths.items() if path}
