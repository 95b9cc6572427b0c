"""Where a key of a TOML file stands: the line numbers error messages give.

``tomllib`` returns plain dicts without positions, so a loader that finds a bad value
knows its key path (``faults[1].kind``, ``robot.turnaround_ms``) but not its line. These
helpers find it again in the text, for every loader of TOML the toolkit has (verifier
scenarios, ``uitamr emulate --faults``), so all of them say ``file:line: key: message``.
"""
from __future__ import annotations

import re
import tomllib
from dataclasses import dataclass

from verifier.textfile import has_lone_cr


@dataclass(frozen=True)
class Place:
    """A line and column (both 1-based) in a TOML file; prints as `line:col`."""

    line: int
    col: int

    def __str__(self) -> str:
        return f"{self.line}:{self.col}"


_KEY_PART = re.compile(r"[^.\[\]]+|\[\d+\]")
_LONG_NUMBER = re.compile(r"(?<![\w.])[0-9][0-9_]{4300,}")
_DECODE_POSITION = re.compile(r"\s*\(at line (\d+), column (\d+)\)")


def line_of_key(lines: list[str], key: str) -> int | None:
    """Best effort: the 1-based line that sets ``key`` ("expect[1].within", "robot.x",
    "faults[0]"), or the header of its table, or the line of an inline table that holds it;
    None when it cannot be found."""
    parts = _KEY_PART.findall(key)
    if not parts:
        return None
    table, index, rest = parts[0], 0, parts[1:]
    if rest and rest[0].startswith("["):
        index = int(rest[0][1:-1])
        rest = rest[1:]
    header = re.compile(r"^\s*\[\[\s*" + _name(table) + r"\s*\]\]")
    plain_header = re.compile(r"^\s*\[\s*" + _name(table) + r"\s*\]")
    start: int | None = None  # the line of the table's header, when the key is in a table
    seen = -1
    for number, line in enumerate(lines):
        if header.match(line):
            seen += 1
            if seen == index:
                start = number
                break
        elif plain_header.match(line):
            start = number
            break
    target = rest[0] if rest else table
    if start is not None and not rest:
        return start + 1  # the table itself is wrong: point at its header
    for number in range(start or 0, len(lines)):
        line = lines[number]
        if start is None and number > 0 and re.match(r"^\s*\[", line):
            break  # a top-level key comes before every table
        if start is not None and number > start and re.match(r"^\s*\[", line) \
                and not re.match(r"^\s*\[\[?\s*" + _name(table) + r"\.", line):
            break  # past its table (and the table's sub-tables): point at the table's header
        if re.match(r"^\s*" + _name(target) + r"\s*[=.]", line):  # a dotted key too: robot.pacing = ...
            return number + 1
    if start is None:
        # no header: the table may be written inline (faults = [{ kind = "x" }]); its line
        return line_of_key(lines, table) if rest or index else None
    return start + 1


def _name(key: str) -> str:
    """A pattern for `key` as a TOML file may write it: bare, "basic" or 'literal' (as the
    docs write buffer memory: 'U0\\G164' = 8)."""
    name = re.escape(key)
    return f"(?:{name}|\"{name}\"|'{name}')"


def decode_error_position(error: ValueError, source: str = "") -> tuple[str, Place | None]:
    """A TOML syntax error as (message, place): tomllib writes the place as
    "(at line L, column C)" at the end of its message; callers put it after the file
    name like every other error. `source` (the file's text) lets the message name a cause
    tomllib cannot: line ends that are lone carriage returns, which TOML does not allow.
    `error` may also be the plain ValueError tomllib lets through from int() for a
    whole number of more than 4300 digits (Python's limit): it is placed in `source`."""
    if not isinstance(error, tomllib.TOMLDecodeError):
        return _too_many_digits(source)
    text = str(error)
    if has_lone_cr(source):
        text += ("; the file's line ends are lone carriage returns (classic Mac OS), which TOML "
                 "does not allow: save it with LF or CRLF line ends")
    match = _DECODE_POSITION.search(text)
    if match is None:
        return text, None
    return _DECODE_POSITION.sub("", text), Place(int(match.group(1)), int(match.group(2)))


def _too_many_digits(source: str) -> tuple[str, Place | None]:
    match = _LONG_NUMBER.search(source)
    if match is None:
        return "a number too long to read", None
    before = source[:match.start()]
    place = Place(before.count("\n") + 1, match.start() - (before.rfind("\n") + 1) + 1)
    digits = sum(ch.isdigit() for ch in match.group())
    return f"a whole number of {digits} digits: too long to read (at most 4300), and no setting takes it", place


def place_of_key(lines: list[str], key: str, at_name: bool = False) -> Place | None:
    """Best effort: line and column of what sets ``key``: the value after ``name =`` (the
    name itself with `at_name`, for a key that should not be there), the n-th item of an
    inline array for ``watch[2]``, the key inside an inline table, or the table's header;
    None when the line cannot be found."""
    line = line_of_key(lines, key)
    if line is None:
        return None
    text = lines[line - 1]
    parts = _KEY_PART.findall(key)
    index = None
    if parts and parts[-1].startswith("["):
        index = int(parts[-1][1:-1])
        parts = parts[:-1]
    name = parts[-1] if parts else ""
    match = re.search(r"(?:^|[{,.])\s*(" + _name(name) + r")\s*=\s*", text) if name else None
    if match is None:
        return Place(line, len(text) - len(text.lstrip()) + 1)
    if at_name:
        return Place(line, match.start(1) + 1)
    col = match.end()
    if index is not None and col < len(text) and text[col] == "[":
        item = _array_item(lines, line - 1, col, index)
        if item is not None:
            line, col = item
    return Place(line, col + 1)


def _array_item(lines: list[str], row: int, start: int, index: int) -> tuple[int, int] | None:
    """(line, offset) of the index-th item of the array opening at lines[row][start] ('['),
    which may go on over the following lines (with comments after its items)."""
    depth, count, quote = 0, 0, ""
    expecting = True
    i = start
    while row < len(lines):
        text = lines[row]
        while i < len(text):
            ch = text[i]
            if quote:
                if ch == "\\" and quote == '"':
                    i += 1
                elif ch == quote:
                    quote = ""
            elif ch == "#":
                break  # a comment: the rest of the line
            elif ch in "[{\"'" or (not ch.isspace() and ch not in "]},"):
                if depth == 1 and expecting:
                    if count == index:
                        return row + 1, i
                    count, expecting = count + 1, False
                if ch in "[{":
                    depth += 1
                elif ch in "\"'":
                    quote = ch
            elif ch in "]}":
                depth -= 1
                if depth == 0:
                    return None
            elif ch == "," and depth == 1:
                expecting = True
            i += 1
        if quote or depth == 0:
            return None  # a string that does not end on its line (a multi-line one): give up
        row, i = row + 1, 0
    return None


def shown(value) -> str:
    """A TOML value for messages: `true`/`false` and arrays as the file writes them, a
    date-time as one, a table as "a table"; text quoted as the other messages quote it."""
    import datetime

    if isinstance(value, bool):
        text = "true" if value else "false"
    elif isinstance(value, (datetime.datetime, datetime.date, datetime.time)):
        text = f"{value.isoformat()} (a date or time)"
    elif isinstance(value, dict):
        text = "a table"
    elif isinstance(value, list):
        text = "[" + ", ".join(shown(item) for item in value) + "]"
    else:
        text = repr(value)
    return text if len(text) <= 60 else text[:57] + "..."
