"""A stop request that a signal handler may raise (Ctrl-C, SIGTERM) and a loop polls.

`threading.Event.set` takes the lock of the Event's Condition. A signal handler runs in the
main thread between two bytecodes of whatever it interrupted, so a second Ctrl-C that came
while the first handler held that lock ran a handler that waited for it for ever (the first
cannot go on under it), and every further signal nested one more: `uitamr monitor`, sent
Ctrl-C again and again while it stopped, hung or died of RecursionError. A flag set by one
assignment takes no lock; `is_set` and `set` are all the loops and a `threading.Timer` need.
"""
from __future__ import annotations


class StopFlag:
    """Set once, by a signal handler or another thread; read by the loop that stops on it."""

    __slots__ = ("_set",)

    def __init__(self) -> None:
        self._set = False

    def set(self) -> None:
        self._set = True

    def is_set(self) -> bool:
        return self._set
