"""Reading the UTF-8 text files the tool takes (captures, fault files, scenarios), with
one wording for what went wrong: the caller puts it in its own error with the file name."""
from __future__ import annotations

import stat
from pathlib import Path

BOM = b"\xef\xbb\xbf"  # a UTF-8 byte order mark, as Windows editors write it: skipped


class UnreadableText(Exception):
    """Why a text file could not be read: `cannot read: ...` or `line L, column C (byte N):
    not UTF-8 text`; `line` and `col` say where when the bytes are not text."""

    def __init__(self, message: str, line: int | None = None, col: int | None = None,
                 byte: int | None = None):
        super().__init__(message)
        self.line, self.col, self.byte = line, col, byte


def read_utf8(path: Path) -> str:
    """The text of `path`. Only a regular file is read (a named pipe would block for ever);
    a leading UTF-8 byte order mark is dropped."""
    try:
        mode = path.stat().st_mode
        if stat.S_ISDIR(mode):
            raise UnreadableText("cannot read: it is a folder, not a file")
        if not stat.S_ISREG(mode):
            raise UnreadableText("cannot read: not a regular file (a pipe, socket or device)")
        data = path.read_bytes()
    except OSError as exc:
        raise UnreadableText(f"cannot read: {exc.strerror or exc}") from None
    start = len(BOM) if data.startswith(BOM) else 0
    try:
        return data[start:].decode("utf-8")
    except UnicodeDecodeError as exc:
        before = data[start:start + exc.start].decode("utf-8")
        line = before.count("\n") + 1
        col = len(before) - (before.rfind("\n") + 1) + 1
        raise UnreadableText(f"line {line}, column {col} (byte {start + exc.start}): not UTF-8 text",
                             line, col, start + exc.start) from None
