"""The cyclic garbage collector held off while ST is read and checked.

Reading and checking a project builds its trees, symbols and types: tens of thousands of
objects that all stay alive until the command ends. The collector, run as usual, walks
them again at each of its passes (the old generation repeatedly as it grows: about a tenth
of `uitamr check`'s time on a 15,000-line project) and finds nothing to free. Held off for
the length of that work, it runs as usual afterwards; what the work left as cyclic
garbage (little: the trees have no reference cycles) waits until then.
"""
from __future__ import annotations

import gc
from contextlib import contextmanager
from typing import Iterator


@contextmanager
def collector_held() -> Iterator[None]:
    """Hold the cyclic garbage collector off inside the block (a no-op when the caller
    has turned it off already); reference counting frees memory as usual."""
    collecting = gc.isenabled()
    gc.disable()
    try:
        yield
    finally:
        if collecting:
            gc.enable()
