"""SIGINT and SIGTERM in the ``foldcore`` command: one line, exit codes 130 / 143,
never a traceback, from the command's first statement to its exit.

:func:`starting` covers the imports before :func:`foldcore.cli.main` runs (nothing
has been written yet: a line and the exit code at once); :func:`handled` covers
main itself, turning both signals into exceptions raised where the process is,
so temporary files are removed on the way out (:mod:`foldcore.files`);
:func:`finished` ignores both once main has returned (the work is done and its
exit code stands; a signal while the interpreter shut down printed a thread's
traceback, or ended the process by the signal). Design notes:
``docs/architecture.md#signals``.
"""
from __future__ import annotations

import os
import signal
import sys
import threading
from contextlib import contextmanager

EXIT_SIGINT = 130  # 128 + SIGINT, as shells report it
EXIT_SIGTERM = 143  # 128 + SIGTERM
_EXIT = {signal.SIGINT: (EXIT_SIGINT, "interrupted (SIGINT)"),
         signal.SIGTERM: (EXIT_SIGTERM, "terminated (SIGTERM)")}


class Terminated(BaseException):
    """SIGTERM, raised where the process is, so temporary files are removed on the way
    out (a BaseException: nothing catches it by accident)."""


class Interrupt(KeyboardInterrupt):
    """SIGINT as the command raises it: a KeyboardInterrupt of its own class, as CPython
    ends the process by SIGINT after main returns (exit −2, not 130) once an interrupt
    of exactly KeyboardInterrupt has left code that an extension's import runs."""


def _starting(signum, frame):
    code, what = _EXIT[signum]
    os.write(2, f"foldcore: {what} while starting; nothing was written\n".encode())
    os._exit(code)


def starting() -> None:
    """Until :func:`handled` takes over: a signal prints one line and exits."""
    for number in _EXIT:
        signal.signal(number, _starting)


def finished() -> None:
    """After the command: both signals ignored, so its exit code stands."""
    for number in _EXIT:
        signal.signal(number, signal.SIG_IGN)


def run_command(command) -> int:
    """``command()`` (the command line, or a function that imports and runs it) with
    signals handled from before it starts (:func:`starting`) to after it ends
    (:func:`finished`); its exit code."""
    starting()
    code = command()
    finished()
    return code


_received: list = []  # the signals :func:`handled` turned into exceptions, in order


def _raise(signum, frame):
    _received.append(signum)
    raise Interrupt() if signum == signal.SIGINT else Terminated()


def caught(exc: BaseException) -> tuple[int, str] | None:
    """(exit code, words) of the signal that ``exc`` ends the command for: SIGINT for
    a KeyboardInterrupt, SIGTERM for :class:`Terminated`, and, for any other
    exception once a signal arrived, that signal (C code an exception passes
    through may replace it: numpy's import turns one into an ImportError); None
    for an error of the command's own."""
    if isinstance(exc, KeyboardInterrupt):
        return _EXIT[signal.SIGINT]
    if isinstance(exc, Terminated):
        return _EXIT[signal.SIGTERM]
    return _EXIT[_received[-1]] if _received else None


@contextmanager
def handled():
    """While the block runs (in the main thread; elsewhere signals cannot be handled):
    SIGINT raises :class:`Interrupt`, SIGTERM :class:`Terminated`.

    A handler's exception raised inside a callback from C is lost there (ctypes
    prints it as "Exception ignored" and goes on; llvmlite calls one while numba
    compiles a kernel): such a signal is sent again 10 ms later, until it lands in
    Python code, and its traceback is not printed. The previous handlers and
    ``sys.unraisablehook`` are put back after the block.
    """
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    previous = {number: signal.signal(number, _raise) for number in _EXIT}
    hook, resends = sys.unraisablehook, []
    _received.clear()

    def lost(unraisable):
        exc = unraisable.exc_value
        if not isinstance(exc, (Interrupt, Terminated)):
            return hook(unraisable)
        number = signal.SIGINT if isinstance(exc, Interrupt) else signal.SIGTERM
        resends.append(threading.Timer(0.01, os.kill, (os.getpid(), number)))
        resends[-1].daemon = True
        resends[-1].start()

    sys.unraisablehook = lost
    try:
        yield
    finally:
        for timer in resends:
            timer.cancel()
        _received.clear()
        sys.unraisablehook = hook
        for number, before in previous.items():
            signal.signal(number, before)
