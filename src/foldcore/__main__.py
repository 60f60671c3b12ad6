"""``python -m foldcore …`` runs the command-line tool (same as ``foldcore …``).

:func:`run` handles SIGINT and SIGTERM from its first statement, before the
command line is imported (:mod:`foldcore.interrupts`). Before it — the
interpreter's start and ``import foldcore``, some 40 ms — Python's defaults
apply.
"""
import sys


def run() -> int:
    """The ``foldcore`` command: :func:`foldcore.cli.main` with signals handled from
    the start to the exit; the exit code."""
    from .interrupts import finished, starting

    starting()
    from .cli import main

    code = main()
    finished()
    return code


if __name__ == "__main__":
    sys.exit(run())
