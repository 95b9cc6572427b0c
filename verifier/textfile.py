"""Reading the text files the tool takes (captures, fault files, scenarios; ST files go
through verifier.st.source, which shares the helpers below), with one wording for what
went wrong: the caller puts it in its own error with the file name. And the one way
characters a report cannot hold are shown in it (`escape_chars`), and file names in
line-based messages (`shown_name`)."""
from __future__ import annotations

import os
import re
import stat
from contextlib import contextmanager
from pathlib import Path
from typing import IO, Callable, Iterator

from verifier.place import Place

BOM = b"\xef\xbb\xbf"  # a UTF-8 byte order mark, as Windows editors write it: skipped
#: UTF-16's byte order marks (little-, big-endian): what Windows editors call "Unicode"
UTF16_BOMS = (b"\xff\xfe", b"\xfe\xff")

#: the error handler of every text the tool writes (reports, traces, the console): a file
#: or folder name that is not UTF-8 comes to Python with its bad bytes as lone surrogates
#: (b"\xfe" as "\udcfe"), which UTF-8 cannot encode; they are written as "\udcfe", as
#: Python's own stderr shows them (in JSON, the escape of the same character)
UNENCODABLE = "backslashreplace"


class UnreadableText(Exception):
    """Why a text file could not be read: `cannot read: ...` or `line L, column C (byte N):
    not UTF-8 text`; `place` (in the file its caller read: `Place.file` None) says where
    when the bytes are not text, `byte` which byte it is."""

    def __init__(self, message: str, place: Place | None = None, byte: int | None = None,
                 utf16: bytes | None = None):
        super().__init__(message)
        self.place, self.byte, self.utf16 = place, byte, utf16

    def after_place(self) -> str:
        """The words to put after the file's `file:line:col: ` place (bytes that are not
        text), or after `file: ` (a file that cannot be read at all)."""
        if self.place is None:
            return str(self)
        if self.utf16 is not None:
            return (f"the file is UTF-16 (it starts with {self.utf16[0]:02X} {self.utf16[1]:02X}, UTF-16's byte "
                    "order mark; an editor's \"Unicode\"), not UTF-8: save it as UTF-8")
        return f"not UTF-8 text (byte {self.byte}): save the file as UTF-8"


def read_utf8(path: Path) -> str:
    """The text of `path`. Only a regular file is read (a named pipe would block for ever);
    a leading UTF-8 byte order mark is dropped."""
    try:
        mode = path.stat().st_mode
        if stat.S_ISDIR(mode):
            raise UnreadableText("cannot read: it is a folder, not a file")
        if not stat.S_ISREG(mode):
            raise UnreadableText(f"cannot read: not a regular file ({file_kind(mode)})")
        data = path.read_bytes()
    except OSError as exc:
        raise UnreadableText(f"cannot read: {exc.strerror or exc}") from None
    if data.startswith(UTF16_BOMS):
        raise UnreadableText("line 1, column 1 (byte 0): UTF-16 text, not UTF-8", Place(None, 1, 1), 0,
                             utf16=data[:2])
    start = len(BOM) if data.startswith(BOM) else 0
    try:
        return data[start:].decode("utf-8")
    except UnicodeDecodeError as exc:
        bad = start + exc.start
        line, col = place_of_byte(data, bad)
        raise UnreadableText(f"line {line}, column {col} (byte {bad}): not UTF-8 text", Place(None, line, col),
                             bad) from None


def real_path(path: Path | str) -> Path:
    """`Path(path).resolve()` for paths users give, which never raises: Python 3.11's
    `resolve` raises RuntimeError on a symlink loop, which is left as it is here, for
    whatever reads the file to report ("Too many levels of symbolic links")."""
    return Path(os.path.realpath(path))


def is_folder(path: Path | str) -> bool:
    """`Path.is_dir()` for paths users give, False where the file system refuses the name
    (one too long, a symlink loop), which Python 3.11's `is_dir` raises: whatever reads the
    path then says what is wrong with it."""
    try:
        return Path(path).is_dir()
    except OSError:
        return False


def is_char_device(path: Path | str) -> bool:
    """`Path.is_char_device()` (a serial port: /dev/ttyUSB0) for paths users give, False
    where it raises, as `is_folder`."""
    try:
        return Path(path).is_char_device()
    except OSError:
        return False


def reached_path(path: Path | str, cwd: Path | str) -> Path:
    """`path` against the folder `cwd`, absolute but not resolved: the path the user reached
    the file by (through a symlinked `vendor/uitamr`, say), where `real_path` says where it
    really is. A `..` step is folded away (`ci/../vendor` is `vendor`) only where that
    names the same file: after a symlinked folder, `..` leads elsewhere."""
    given = Path(cwd) / path
    folded = Path(os.path.normpath(given))
    return folded if folded == given or real_path(folded) == real_path(given) else given


def shown_path(path: Path | str, cwd: Path | str) -> str:
    """A path a user gave (or one reached through it, like a scenario's sources) as reports
    show it: relative to the working folder `cwd` when it lies inside it as reached
    (`reached_path`: `vendor/uitamr/plc/core/UITAMR_Engine.st`, not where the symlink
    leads) or else where it really is (`real_path`); otherwise as given."""
    reached = reached_path(path, cwd)
    for candidate in (reached, real_path(reached)):
        if candidate.is_relative_to(cwd):
            return str(candidate.relative_to(cwd))
    return str(path)


def place_of_byte(data: bytes, offset: int) -> tuple[int, int]:
    """The line and column (1-based) at which byte `offset` of a file's `data` stands, the
    text before it read as UTF-8 (a leading byte order mark is not a column)."""
    start = len(BOM) if data.startswith(BOM) else 0
    before = data[start:offset].decode("utf-8", errors="replace")
    return place_of_char(before, len(before))


def place_of_char(text: str, offset: int) -> tuple[int, int]:
    """The line and column (1-based) at which character `offset` of `text` stands (lines
    end at line feeds, as tomllib and `text_lines` count them)."""
    return text.count("\n", 0, offset) + 1, offset - text.rfind("\n", 0, offset)


def lone_cr_as_line_feed(text: str) -> str:
    """`text` with each carriage return not followed by a line feed made a line feed: a
    file saved with classic Mac OS line ends (a lone CR) is then read line by line, where
    lark, tomllib-style positions and `text_lines` count lines at line feeds only. CRLF
    text comes back as it is."""
    return re.sub(r"\r(?!\n)", "\n", text) if has_lone_cr(text) else text


def has_lone_cr(text: str) -> bool:
    """Whether `text` has a carriage return not followed by a line feed (CRLF, what GX
    Works and Windows editors write, is not one)."""
    return text.count("\r") != text.count("\r\n")


def text_lines(text: str) -> list[str]:
    """The lines of `text` as this tool numbers them everywhere (lark, tomllib and
    `place_of_byte` count line feeds): split at "\n" only, a "\r" before it dropped.
    `str.splitlines` also breaks at form feeds, NEL and the Unicode line separators, which
    can stand inside comments and strings; the source line printed under a message, or
    the line of a key, would then be the wrong one. Like `splitlines`, a final line feed
    does not start one more (empty) line."""
    lines = [line[:-1] if line.endswith("\r") else line for line in text.split("\n")]
    if text == "" or text.endswith("\n"):
        lines.pop()
    return lines


def file_kind(mode: int) -> str:
    """What a path that is not a regular file is, from its `stat` mode, for messages."""
    if stat.S_ISCHR(mode):
        return "a character device"
    if stat.S_ISBLK(mode):
        return "a block device"
    if stat.S_ISFIFO(mode):
        return "a pipe"
    if stat.S_ISSOCK(mode):
        return "a socket"
    return "not a file"


def escape_chars(text: str, keep: Callable[[str], bool]) -> str:
    """`text` with each character `keep` refuses written as \\xNN or \\uNNNN (a control
    character in a scenario name would restyle a terminal or break an XML report)."""
    if all(keep(c) for c in text):
        return text
    return "".join(c if keep(c) else f"\\x{ord(c):02x}" if ord(c) < 0x100 else f"\\u{ord(c):04x}"
                   for c in text)


def shown_name(name: str) -> str:
    """A file name as line-based messages show it (`file:line:col: ...` on the console, in
    editors and CI logs, a verdict line): a character that is not printable (a line feed,
    a tab, ESC, a byte that is not UTF-8) as \\xNN or \\uNNNN, as the console report
    shows it, so that the name stays on its line and the reader of `file:line:col` finds
    it; names of ordinary characters (spaces, any script) come back as they are. JSON,
    JUnit and SARIF hold the name itself, escaped by their own rules."""
    return escape_chars(name, str.isprintable)


@contextmanager
def whole_file(path: Path | str, mode: str = "w", **options) -> Iterator[IO]:
    """`open(path, mode, **options)` for a file the tool writes (a report, an export) that
    is to be whole or not there at all: when writing fails (a full disk, a file size limit,
    Ctrl-C), the part written is removed and the OSError names the file. A path that is not
    a regular file (/dev/stdout, a pipe) is left as it is."""
    out = open(path, mode, **options)
    try:
        yield out
        out.close()  # the last of the text may fail only here
    except BaseException as exc:
        try:
            out.close()
        except OSError:
            pass
        try:
            real = real_path(path)
            if stat.S_ISREG(real.stat().st_mode):
                real.unlink()
        except OSError:
            pass
        if isinstance(exc, OSError) and exc.filename is None:
            exc.filename = str(path)
        raise
