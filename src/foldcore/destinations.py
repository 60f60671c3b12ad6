"""Where a command's outputs go: checked before any work, written all or nothing.

The output contract (issue 18): a destination that cannot be written is found
before the run — not after a long fold, with a temporary file's name in the
message — and a run writes either every output it was asked for or none
(each file goes to a temporary name in its own folder and is renamed over
the destination only when every writer has succeeded;
:func:`foldcore.io.fold.atomic_path`). A signal that ends the process (the
CLI turns SIGINT and SIGTERM into exceptions) removes the temporary files on
its way out; SIGKILL cannot be caught and may leave a ``.NAME.PID.HEX.tmp``.
"""
from __future__ import annotations

import os
from contextlib import ExitStack, contextmanager

from .errors import FoldcoreError


class OutputError(FoldcoreError, ValueError):
    """An output path cannot be written: no such folder, a folder, an input file, or
    given twice."""


def check_destinations(outputs: dict, inputs=(), suffixes: dict | None = None) -> None:
    """Refuse output paths that cannot be written, before any work.

    Parameters
    ----------
    outputs : dict {option name: path or None}
        e.g. ``{"-o": "out.fold", "--report": None}``; None entries are skipped.
    inputs : iterable of paths
        Files the command reads: an output may not overwrite one.
    suffixes : dict {option name: tuple of suffixes}, optional
        The file types an option writes (e.g. ``{"--render": (".png",)}``): another
        suffix is refused rather than written in a format the name does not say.

    Raises
    ------
    OutputError
        Naming the option and the path as the user gave them.
    """
    seen = {}
    for option, path in outputs.items():
        if not path:
            continue
        target = os.path.realpath(os.fspath(path))
        folder = os.path.dirname(target)
        where = f"{option} {os.fspath(path)}"
        allowed = (suffixes or {}).get(option)
        if allowed and os.path.splitext(target)[1].lower() not in allowed:
            raise OutputError(f"{where}: writes {' or '.join(allowed)} only; "
                              f"name the file {os.path.splitext(os.fspath(path))[0]}{allowed[0]}")
        if os.path.isdir(target):
            raise OutputError(f"{where}: is a folder, not a file name")
        if not os.path.isdir(folder):
            raise OutputError(f"{where}: cannot write there (no such folder: {folder})")
        if not os.access(folder, os.W_OK):
            raise OutputError(f"{where}: cannot write there (folder not writable: {folder})")
        for source in inputs:
            if source and os.path.realpath(os.fspath(source)) == target:
                raise OutputError(f"{where}: is the input file {os.fspath(source)}; "
                                  "choose another output name")
        if target in seen:
            raise OutputError(f"{where}: also given to {seen[target]}")
        seen[target] = option


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
    from .io.fold import atomic_path

    with ExitStack() as stack:
        yield {key: stack.enter_context(atomic_path(path, os.path.splitext(os.fspath(path))[1]))
               for key, path in paths.items() if path}
