"""Reading the UTF-8 text files the tool takes (captures, fault files, scenarios), with
one wording for what went wrong: the caller puts it in its own error with the file name."""
from __future__ import annotations

from pathlib import Path


class UnreadableText(Exception):
    """Why a text file could not be read: `cannot read: ...` or `byte N: not UTF-8 text`."""


def read_utf8(path: Path) -> str:
    try:
        return path.read_text(encoding="utf-8")
    except OSError as exc:
        raise UnreadableText(f"cannot read: {exc.strerror or exc}") from None
    except UnicodeDecodeError as exc:
        raise UnreadableText(f"byte {exc.start}: not UTF-8 text") from None
