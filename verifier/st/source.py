"""Read a structured-text file from disk: the one reader used by `uitamr check`,
`uitamr export` and `verifier.load` (docs/st-dialect.md section 2, "Files").

Encoding policy: UTF-8 (a byte-order mark is allowed and dropped), else Shift-JIS
(Windows code page 932, what GX Works writes on Japanese Windows). Nothing else is
guessed: a file that is neither gives an error naming the first byte that is not UTF-8,
so two tools never read the same bytes as different text.
"""
from __future__ import annotations

import stat
from pathlib import Path

from verifier.st.ast import Diagnostic
from verifier.textfile import BOM, UTF16_BOMS, file_kind, place_of_byte

ENCODINGS = ("utf-8-sig", "cp932")
#: Python's cp932 decodes these single bytes to control or private-use characters that
#: no editor writes; a file holding them is not Shift-JIS text.
_NOT_SHIFT_JIS = frozenset("\x80\uf8f0\uf8f1\uf8f2\uf8f3")


def read_source(path: str | Path) -> tuple[str, list[Diagnostic]]:
    """The text of an ST file and the problems met reading it. On a problem the text is
    "" and the diagnostics hold one error naming the file (and line, column, byte
    offset when the bytes are not text)."""
    p = Path(path)
    name = str(path)
    try:
        mode = p.stat().st_mode
    except FileNotFoundError:
        return "", [_error(name, 0, 0, "cannot read: no such file or directory")]
    except OSError as e:
        return "", [_error(name, 0, 0, f"cannot read: {e.strerror or e}")]
    if stat.S_ISDIR(mode):
        return "", [_error(name, 0, 0, "is a folder; give .st files (or the folder to check/export/load)")]
    if not stat.S_ISREG(mode):
        return "", [_error(name, 0, 0, f"is not a regular file ({file_kind(mode)}); give a .st file")]
    try:
        data = p.read_bytes()
    except OSError as e:
        return "", [_error(name, 0, 0, f"cannot read: {e.strerror or e}")]
    return decode_source(data, name)


def decode_source(data: bytes, name: str = "<bytes>") -> tuple[str, list[Diagnostic]]:
    """Decode the bytes of an ST file by the policy above."""
    try:
        return data.decode("utf-8-sig"), []
    except UnicodeDecodeError as utf8_error:
        # "utf-8-sig" counts from after a byte order mark; the offset, line and column
        # are the file's
        bad = utf8_error.start + (len(BOM) if data.startswith(BOM) else 0)
    try:
        text = data.decode("cp932")
    except UnicodeDecodeError:
        text = None
    if text is not None and not _NOT_SHIFT_JIS.intersection(text):
        return text, []
    if data.startswith(UTF16_BOMS):
        # what Windows editors call "Unicode": named, not read (the policy above)
        order = "little" if data.startswith(b"\xff\xfe") else "big"
        return "", [_error(name, 1, 1, f"the file is UTF-16 ({order}-endian: it starts with the bytes "
                                       f"{data[0]:02X} {data[1]:02X}, UTF-16's byte order mark), not UTF-8 or "
                                       "Shift-JIS text; save it as UTF-8 (an editor's \"Unicode\" is UTF-16)")]
    line, col = place_of_byte(data, bad)
    return "", [_error(name, line, col,
                       f"byte 0x{data[bad]:02X} at offset {bad} is neither UTF-8 nor Shift-JIS text; "
                       "save the file as UTF-8")]


def _error(name: str, line: int, col: int, message: str) -> Diagnostic:
    return Diagnostic(name, line, col, "error", message)
