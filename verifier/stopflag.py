"""A stop request that a signal handler may raise (Ctrl-C, SIGTERM) and a loop polls.

`threading.Event.set` takes the lock of the Event's Condition. A signal handler runs in the
main thread between two bytecodes of whatever it interrupted, so a second Ctrl-C that came
while the first handler held that lock ran a handler that waited for it for ever (the first
cannot go on under it), and every further signal nested one more: `uitamr monitor`, sent
Ctrl-C again and again while it stopped, hung or died of RecursionError. A flag set by one
assignment takes no lock; `is_set` and `set` are all the loops and a `threading.Timer` need.
"""
from __future__ import annotations

import signal


class StopFlag:
    """Set once, by a signal handler or another thread; read by the loop that stops on it."""

    __slots__ = ("_set",)

    def __init__(self) -> None:
        self._set = False

    def set(self) -> None:
        self._set = True

    def is_set(self) -> bool:
        return self._set


#: set when `uitamr` runs as a program (cli.LazyGroup.__call__), never when a command is
#: invoked in-process (click's CliRunner, a Python caller keeps its own Ctrl-C)
AS_PROGRAM = StopFlag()


def put_back(previous: dict) -> None:
    """The handlers a stopping command replaced (`{signal: handler}`), once its reports or
    summary are written. In the `uitamr` program Ctrl-C is ignored from then on: the
    interpreter's own handler, put back, turned a further Ctrl-C of a burst into a
    KeyboardInterrupt while the command exited ("Exception ignored in atexit callback",
    "lost sys.stderr") or, once the interpreter had reset it to the default, ended the
    process by SIGINT (status 130), so the exit status that says the verdict (`monitor`'s
    0, 1, 3 or 4, `emulate`'s 0) was lost though nothing was left to stop. SIGTERM is put back as
    it was: it still ends a process that would not exit.

    Ctrl-C is blocked while its handler becomes SIG_IGN: one that came between
    signal.signal's look at the signals due and its change of the handler was due to a
    Python handler that was no longer there, and Python printed "Signal 2 ignored due to
    race condition" (1 run in 40 under a burst). Blocked, it waits; SIG_IGN then drops it."""
    for sig, handler in previous.items():
        if sig != signal.SIGINT or not AS_PROGRAM.is_set():
            signal.signal(sig, handler)
            continue
        signal.pthread_sigmask(signal.SIG_BLOCK, {signal.SIGINT})
        try:
            signal.signal(signal.SIGINT, signal.SIG_IGN)
        finally:
            signal.pthread_sigmask(signal.SIG_UNBLOCK, {signal.SIGINT})
