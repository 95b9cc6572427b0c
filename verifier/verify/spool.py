"""The hidden folder beside a report (`--trace`, `--html`) where runs write their frames'
trace lines as they go (`Keep.frames_to_file`, verifier.verify.stream), and its clean-up.

`uitamr verify` removes the folder when it ends, also on Ctrl-C, SIGTERM and a killed
worker. A command killed outright (SIGKILL, the OOM killer) cannot: its folder is named
after the host and the process, and the next command that makes one in the same folder
removes those of this host's processes that are gone (a folder shared between machines
holds others' too: only this host's processes can be asked whether they live).
"""
from __future__ import annotations

import os
import re
import shutil
import socket
import tempfile
from pathlib import Path

PREFIX = ".uitamr-trace-"  # the folder's, and each run's file in it


def make(folder: Path) -> str:
    """A new spool folder in `folder`, after removing the orphaned ones there (OSError
    when it cannot be made)."""
    _remove_orphans(folder)
    return tempfile.mkdtemp(prefix=f"{PREFIX}{owner()}-{os.getpid()}-", dir=folder)


def owner() -> str:
    """This host's name as a spool folder's name holds it."""
    return "".join(ch if ch.isalnum() else "_" for ch in socket.gethostname())[:40] or "host"


def _remove_orphans(folder: Path) -> None:
    """Remove the spool folders in `folder` of this host's processes that are gone."""
    mine = re.compile(re.escape(f"{PREFIX}{owner()}-") + r"(\d+)-")
    try:
        names = [entry.name for entry in os.scandir(folder) if entry.is_dir(follow_symlinks=False)]
    except OSError:
        return  # the report's own write says what is wrong with the folder
    for name in names:
        match = mine.match(name)
        if match and not _alive(int(match.group(1))):
            shutil.rmtree(folder / name, ignore_errors=True)


def _alive(pid: int) -> bool:
    if pid == os.getpid():
        return True
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except (PermissionError, OverflowError, ValueError):
        return True  # someone else's process (or a number no process has): leave it
    return True
