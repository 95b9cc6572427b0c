"""The `uitamr` program's first code (pyproject's console script): `verifier.cli` with a
Ctrl-C that lands while it is still being imported told as every other Ctrl-C is.

`verifier.cli` catches Ctrl-C from the moment its click group runs; pressed in the tenth
of a second before (click and the package importing on a loaded PC), it ended in Python's
KeyboardInterrupt traceback. This module imports nothing heavy itself.
"""
from __future__ import annotations

import sys

#: 128 + SIGINT; verifier.cli takes it and `interrupted` from here (this module cannot import
#: the CLI's: that import is what a Ctrl-C may interrupt)
EXIT_INTERRUPTED = 130


def interrupted(command: str | None) -> str:
    """What a Ctrl-C before the command finished says (stderr), `command` the one typed."""
    return f"\nuitamr{' ' + command if command else ''}: interrupted (Ctrl-C) before it finished: no verdict"


def main() -> None:
    try:
        from verifier.cli import main as run
    except KeyboardInterrupt:
        typed = sys.argv[1] if len(sys.argv) > 1 and not sys.argv[1].startswith("-") else ""
        sys.stderr.write(interrupted(typed) + "\n")
        sys.exit(EXIT_INTERRUPTED)
    run()
