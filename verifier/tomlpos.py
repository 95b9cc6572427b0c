"""Where a key of a TOML file stands: the line numbers error messages give.

``tomllib`` returns plain dicts without positions, so a loader that finds a bad value
knows its key path (``faults[1].kind``, ``robot.turnaround_ms``) but not its line. These
helpers find it again in the text, for every loader of TOML the toolkit has (verifier
scenarios, ``uitamr emulate --faults``), so all of them say ``file:line: key: message``.

They read the document as TOML does (`_Walk`): table headers, sub-tables of a table or of
the last table of an array (``[robot.point_durations_s]``, ``[[inputs]]`` then
``[inputs.set]``), dotted keys, inline tables, arrays over several lines, strings of every
kind and comments. So every key is found on its own line and column, and a name that
stands elsewhere (in a comment, a string, another table) is never taken for it.
"""
from __future__ import annotations

import bisect
import functools
import re
import tomllib

from verifier.place import Place
from verifier.textfile import has_lone_cr, place_of_char, text_lines


_LONG_NUMBER = re.compile(r"(?<![\w.])[0-9][0-9_]{4300,}")
_DECODE_POSITION = re.compile(r"\s*\(at line (\d+), column (\d+)\)")
_DECODE_AT_END = re.compile(r"\s*\(at end of document\)")
_BARE_KEY = re.compile(r"[A-Za-z0-9_-]+")
_INDEX = re.compile(r"\[([0-9]+)\]")

#: Where a value is in the document: table keys and array indices, ("faults", 1, "kind").
KeyPath = tuple


def line_of_key(lines: list[str], key: str) -> int | None:
    """Best effort: the 1-based line that sets ``key`` (see `place_of_key`)."""
    place = place_of_key(lines, key)
    return place.line if place is not None else None


def place_of_key(lines: list[str], key: str, at_name: bool = False) -> Place | None:
    """Best effort: line and column of what sets ``key`` ("robot.turnaround_ms",
    "inputs[0].set.D100", "watch[2]", "robot.point_poses.3[2]"): the value after ``name =``
    (the name itself with `at_name`, for a key that should not be there), the n-th item of
    an array, the header of a table (``[robot.point_poses]``, ``[[faults]]``). A key the file
    does not hold is placed at the table or array it would be in; None when not even its
    first part is in the file."""
    places = _places("\n".join(lines))
    # a key of the document named "" (TOML allows an empty quoted key) is its own path
    path, missing = (("",), "") if key == "" and ("",) in places else _find(places, (), key)
    if not path:
        return None
    name, value = places[path]
    return name if at_name and not missing else value


def _find(places: dict[KeyPath, tuple[Place, Place]], path: KeyPath, key: str) -> tuple[KeyPath, str]:
    """The deepest path in `places` that `key` names from `path` on, and what is left of
    `key`. A key may hold dots (a label "fbRobot.i_uPoint" in an input's `set`): the table's
    keys that `key` starts with are tried, the longest first. Only those are looked up: the
    loader places every key it knows, and reading all of a long document's keys for each
    took time in the square of its length."""
    if not key:
        return path, ""
    index = _INDEX.match(key)
    if index is not None:
        item = path + (int(index.group(1)),)
        if key[index.end():] == "." and item + ("",) in places:  # "faults[0]." names its key ""
            return item + ("",), ""
        return _find(places, item, key[index.end():].removeprefix(".")) if item in places else (path, key)
    deepest = (path, key)
    ends = [i for i, ch in enumerate(key) if ch in ".["] + [len(key)]  # where a name of the table may end
    for end in reversed(ends):
        name, rest = key[:end], key[end:]
        if path + (name,) in places:
            if rest == "." and path + (name, "") in places:  # "robot." names the key "" of [robot]
                return path + (name, ""), ""
            found = _find(places, path + (name,), rest.removeprefix("."))
            if not found[1]:
                return found
            if len(found[0]) > len(deepest[0]):
                deepest = found
    return deepest


@functools.lru_cache(maxsize=16)
def _places(text: str) -> dict[KeyPath, tuple[Place, Place]]:
    walk = _Walk(text)
    try:
        walk.document()
    except (ValueError, RecursionError):
        # not TOML after all (every loader reads it with tomllib first), or arrays nested
        # deeper than the walk can follow (tomllib reads a little deeper): what was found
        pass
    return walk.places


class _Walk:
    """Reads a TOML document for the places of its keys and values, without their values:
    ``places[path] = (where its name is, where its value starts)``; a table that a header
    makes is at its header, a table that a dotted key or a header makes on the way to
    another one (``robot`` of ``[robot.point_poses]``) where it is first named."""

    def __init__(self, text: str):
        self.text = text
        self.pos = 0
        self.line_starts = [0] + [i + 1 for i, ch in enumerate(text) if ch == "\n"]
        self.places: dict[KeyPath, tuple[Place, Place]] = {}
        self.tables_in: dict[KeyPath, int] = {}  # arrays of tables ([[faults]]): tables so far

    def document(self) -> None:
        table: KeyPath = ()
        while True:
            self.blank(newlines=True)
            if self.pos >= len(self.text):
                return
            if self.text.startswith("[", self.pos):
                table = self.header()
            else:
                self.pair(table)

    def header(self) -> KeyPath:
        """``[a.b]`` or ``[[a.b]]``: the table it opens, within the last table of an array."""
        start = self.pos
        brackets = 2 if self.text.startswith("[[", start) else 1
        self.pos += brackets
        names = self.key()
        self.expect("]" * brackets)
        path: KeyPath = ()
        for i, (name, _) in enumerate(names):
            path += (name,)
            last = i == len(names) - 1
            if last and brackets == 2:
                self.note(path, start, start, made=False)
                self.tables_in[path] = self.tables_in.get(path, 0) + 1
            if path in self.tables_in:
                path += (self.tables_in[path] - 1,)
            self.note(path, start, start, made=last)
        return path

    def pair(self, table: KeyPath) -> None:
        """``key = value`` in `table`; the key may be dotted (``robot.pacing = ...``)."""
        names = self.key()
        path = table
        for name, at in names:
            path += (name,)
            self.note(path, at, at, made=False)
        self.expect("=")
        self.blank()
        self.note(path, names[-1][1], self.pos)
        self.value(path)

    def key(self) -> list[tuple[str, int]]:
        """A bare, quoted or dotted key: its parts and where each starts."""
        names = []
        while True:
            self.blank()
            at = self.pos
            if self.text[at:at + 1] in ("\"", "'"):
                self.string()
                names.append((tomllib.loads("k = " + self.text[at:self.pos])["k"], at))
            else:
                match = _BARE_KEY.match(self.text, at)
                if match is None:
                    raise ValueError(f"no key at {at}")
                names.append((match.group(), at))
                self.pos = match.end()
            self.blank()
            if not self.text.startswith(".", self.pos):
                return names
            self.pos += 1

    def value(self, path: KeyPath) -> None:
        ch = self.text[self.pos:self.pos + 1]
        if ch in ("\"", "'"):
            self.string()
        elif ch == "[":
            self.items(path, "]", self.item)
        elif ch == "{":
            self.items(path, "}", self.pair)
        else:  # a number, true or false, a date and time (which may hold a space)
            while self.pos < len(self.text) and self.text[self.pos] not in ",]}\n#":
                self.pos += 1

    def item(self, path: KeyPath, index: int) -> None:
        item = path + (index,)
        self.note(item, self.pos, self.pos)
        self.value(item)

    def items(self, path: KeyPath, closing: str, read) -> None:
        """The items of an array, or the keys of an inline table, up to `closing`."""
        self.pos += 1
        count = 0
        while True:
            self.blank(newlines=True)
            if self.text.startswith(closing, self.pos):
                self.pos += 1
                return
            if closing == "]":
                read(path, count)
            else:
                read(path)
            count += 1
            self.blank(newlines=True)
            if self.text.startswith(",", self.pos):
                self.pos += 1
            elif not self.text.startswith(closing, self.pos):
                raise ValueError(f"no ',' or {closing!r} at {self.pos}")

    def string(self) -> None:
        """Past a string of any of TOML's four kinds."""
        text, start = self.text, self.pos
        quote = text[start]
        delimiter = quote * 3 if text.startswith(quote * 3, start) else quote
        i = start + len(delimiter)
        while not text.startswith(delimiter, i):
            if i >= len(text) or (len(delimiter) == 1 and text[i] == "\n"):
                raise ValueError(f"a string that does not end, from {start}")
            i += 2 if quote == "\"" and text[i] == "\\" else 1
        i += len(delimiter)
        if len(delimiter) == 3:  # """a"""" ends with one or two quotes of its own
            for _ in range(2):
                i += text.startswith(quote, i)
        self.pos = i

    def blank(self, newlines: bool = False) -> None:
        """Past spaces, tabs and a comment; with `newlines` past line ends too."""
        text = self.text
        while self.pos < len(text):
            ch = text[self.pos]
            if ch in " \t" or (newlines and ch in "\r\n"):
                self.pos += 1
            elif ch == "#":
                end = text.find("\n", self.pos)
                self.pos = len(text) if end < 0 else end
            else:
                return

    def expect(self, what: str) -> None:
        self.blank()
        if not self.text.startswith(what, self.pos):
            raise ValueError(f"no {what!r} at {self.pos}")
        self.pos += len(what)

    def note(self, path: KeyPath, name_at: int, value_at: int, made: bool = True) -> None:
        """Where `path` is: a key or table it `made`, or one named on the way to another
        (kept only when it is not placed yet)."""
        if made or path not in self.places:
            self.places[path] = (self.place(name_at), self.place(value_at))

    def place(self, offset: int) -> Place:
        """`textfile.place_of_char`, by bisection of the line starts: asked for every key"""
        line = bisect.bisect_right(self.line_starts, offset)
        return Place(None, line, offset - self.line_starts[line - 1] + 1)


def decode_error_position(error: ValueError | RecursionError, source: str = "") -> tuple[str, Place | None]:
    """A TOML syntax error as (message, place): tomllib writes the place as
    "(at line L, column C)" at the end of its message; callers put it after the file
    name like every other error. `source` (the file's text) lets the message name a cause
    tomllib cannot: line ends that are lone carriage returns, which TOML does not allow.
    `error` may also be the plain ValueError tomllib lets through from int() for a
    whole number of more than 4300 digits (Python's limit): it is placed in `source`; or
    the RecursionError tomllib ends in on arrays or inline tables nested some 400 deep."""
    if isinstance(error, RecursionError):
        return _nested_too_deep(source)
    if not isinstance(error, tomllib.TOMLDecodeError):
        return _too_many_digits(source)
    text = str(error)
    if has_lone_cr(source):
        text += ("; the file's line ends are lone carriage returns (classic Mac OS), which TOML "
                 "does not allow: save it with LF or CRLF line ends")
    match = _DECODE_POSITION.search(text)
    if match is None:
        if source and _DECODE_AT_END.search(text):
            # a file that ends inside a string, a key, a table header: tomllib names no line
            # (Python < 3.14); the place is just past the last character, as tomllib counts
            place = Place(None, *place_of_char(source, len(source)))
            return _DECODE_AT_END.sub(" at the end of the file", text), place
        return text, None
    place = Place(None, int(match.group(1)), int(match.group(2)))
    if text.startswith("Cannot overwrite a value") and source:
        return _given_twice(source, place)
    return _DECODE_POSITION.sub("", text), place


_KEY_AT_START = re.compile(r"""^(\s*)((?:[A-Za-z0-9_-]+|"[^"]*"|'[^']*')(?:\s*\.\s*(?:[A-Za-z0-9_-]+|"[^"]*"|'[^']*'))*)\s*=""")


def _given_twice(source: str, place: Place) -> tuple[str, Place]:
    """tomllib's 'Cannot overwrite a value', said by the key: which key is given twice, and
    where first in the same table (`duration = ...` written twice: the second one is the
    mistake, placed at its key)."""
    lines = text_lines(source)  # numbered as tomllib numbers them (line feeds only)
    line = lines[place.line - 1] if place.line - 1 < len(lines) else ""
    key = _KEY_AT_START.match(line)
    if key is None:
        return "Cannot overwrite a value: a key is given twice", place
    name = key.group(2)
    at = Place(None, place.line, len(key.group(1)) + 1)
    for number in range(place.line - 1, 0, -1):
        earlier = lines[number - 1]
        if earlier.lstrip().startswith("["):
            break  # the table's header: the key is not given before in this table
        other = _KEY_AT_START.match(earlier)
        if other is not None and other.group(2) == name:
            return f"'{name}' is given twice (first on line {number}): keep one", at
    return f"'{name}' is given twice in its table: keep one", at


def _nested_too_deep(source: str) -> tuple[str, Place | None]:
    """Where the value nested too deep for tomllib begins: the value of the outermost
    `key = ...` on the way to the deepest place the walk found."""
    message = "arrays or inline tables nested hundreds deep: too deep to read, and no setting takes them"
    places = _places(source)
    deepest = max(places, key=len, default=())
    for depth in range(1, len(deepest) + 1):
        name, value = places[deepest[:depth]]
        if name != value:  # a key = value pair (a table header is placed at its name)
            return message, value
    return message, None


def _too_many_digits(source: str) -> tuple[str, Place | None]:
    match = _LONG_NUMBER.search(source)
    if match is None:
        return "a number too long to read", None
    place = Place(None, *place_of_char(source, match.start()))
    digits = sum(ch.isdigit() for ch in match.group())
    return f"a whole number of {digits} digits: too long to read (at most 4300), and no setting takes it", place


def shown(value, depth: int = 0) -> str:
    """A TOML value for messages: `true`/`false` and arrays as the file writes them, a
    date-time as one, a table as "a table"; text quoted as the other messages quote it.
    Arrays nested deeper than a message can show (tomllib reads 400 deep) end in `[...]`:
    their items were shown one frame deeper each, to a RecursionError."""
    import datetime

    if isinstance(value, list) and depth >= 30:  # past the 60 characters shown in any case
        return "[...]"
    if isinstance(value, bool):
        text = "true" if value else "false"
    elif isinstance(value, (datetime.datetime, datetime.date, datetime.time)):
        text = f"{value.isoformat()} (a date or time)"
    elif isinstance(value, dict):
        text = "a table"
    elif isinstance(value, list):
        text = "[" + ", ".join(shown(item, depth + 1) for item in value) + "]"
    else:
        text = repr(value)
    return text if len(text) <= 60 else text[:57] + "..."
