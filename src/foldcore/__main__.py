"""``python -m foldcore …`` runs the command-line tool (same as ``foldcore …``).

:func:`run` handles SIGINT and SIGTERM from its first statement, before the
command line is imported (:mod:`foldcore.interrupts`). Before it — the
interpreter's start and ``import foldcore``, some 40 ms — Python's defaults
apply.
"""
import sys


def run() -> int:
    """The ``foldcore`` command: :func:`foldcore.cli.main` with signals handled from
    the start to the exit (its import included); the exit code."""
    from .interrupts import run_command

    def command() -> int:
        from .cli import main
        return main()

    return run_command(command)


if __name__ == "__main__":
    sys.exit(run())
