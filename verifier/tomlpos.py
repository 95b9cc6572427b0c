"""Where a key of a TOML file stands: the line numbers error messages give.

``tomllib`` returns plain dicts without positions, so a loader that finds a bad value
knows its key path (``faults[1].kind``, ``robot.turnaround_ms``) but not its line. These
helpers find it again in the text, for every loader of TOML the toolkit has (verifier
scenarios, ``uitamr emulate --faults``), so all of them say ``file:line: key: message``.
"""
from __future__ import annotations

import re
import tomllib

_KEY_PART = re.compile(r"[^.\[\]]+|\[\d+\]")
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
    header = re.compile(r"^\s*\[\[\s*" + re.escape(table) + r"\s*\]\]")
    plain_header = re.compile(r"^\s*\[\s*" + re.escape(table) + r"\s*\]")
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
                and not re.match(r"^\s*\[\[?\s*" + re.escape(table) + r"\.", line):
            break  # past its table (and the table's sub-tables): point at the table's header
        if re.match(r"^\s*\"?" + re.escape(target) + r"\"?\s*=", line):
            return number + 1
    if start is None:
        # no header: the table may be written inline (faults = [{ kind = "x" }]); its line
        return line_of_key(lines, table) if rest or index else None
    return start + 1


def decode_error_position(error: tomllib.TOMLDecodeError) -> tuple[str, int | None]:
    """A TOML syntax error as (message with its column, line): tomllib writes the place as
    "(at line L, column C)" at the end of its message; callers put the line after the file
    name like every other error."""
    text = str(error)
    match = _DECODE_POSITION.search(text)
    if match is None:
        return text, None
    message = _DECODE_POSITION.sub("", text) + f" (column {match.group(2)})"
    return message, int(match.group(1))
