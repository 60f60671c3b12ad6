"""Where a command's outputs go: checked before any work, written all or nothing.

A destination that cannot be written is found before the run, not after a
long fold, and the message names the option and the path as the user gave
them. The files themselves are written by :mod:`foldcore.files`: each to a
temporary name in its own folder, renamed over the destination only when
every writer has succeeded (:func:`foldcore.files.all_or_nothing`), the temporary files
removed on any error or signal.
"""
from __future__ import annotations

import os

from .files import OutputError


def check_destinations(outputs: dict, inputs=(), suffixes: dict | None = None) -> None:
    """Refuse output paths that cannot be written, before any work.

    Parameters
    ----------
    outputs : dict {option name: path or None}
        e.g. ``{"-o": "out.fold", "--report": None}``; None entries are skipped, an
        empty name is refused, and so is a name longer than its folder takes
        (``NAME_MAX``, ``PATH_MAX``: found now rather than after the run).
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
        if path is None:
            continue
        if not os.fspath(path):
            raise OutputError(f'{option} "": the file name is empty; name the file to write')
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
        _check_length(target, folder, where)
        for source in inputs:
            if source and os.path.realpath(os.fspath(source)) == target:
                raise OutputError(f"{where}: is the input file {os.fspath(source)}; "
                                  "choose another output name")
        if target in seen:
            raise OutputError(f"{where}: also given to {seen[target]}")
        seen[target] = option


def _check_length(target: str, folder: str, where: str) -> None:
    """OutputError naming ``where`` when ``target``'s file name (bytes) is longer than
    its ``folder`` takes, or the whole path longer than the system's limit."""
    for what, text, name, default in (("file name", os.path.basename(target), "PC_NAME_MAX",
                                       255),
                                      ("path", target, "PC_PATH_MAX", 4096)):
        try:
            limit = os.pathconf(folder, name)
        except (OSError, ValueError, AttributeError):  # not known here: the usual
            limit = default
        size = len(os.fsencode(text))
        if limit is not None and limit > 0 and size > limit:
            raise OutputError(f"{where}: the {what} is {size} bytes, longer than the {limit} "
                              "this system takes")
