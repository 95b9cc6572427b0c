"""Inline the bodies of called function blocks into their callers' generated code.

A scan of a typical program is mostly FB calls (the library's engine calls a dozen FBs
each scan); a Python method call per FB call is a large share of the scan time.  After
all bodies are generated, a call line `_oN._body()` whose instance type is a user FB is
replaced by that FB's own generated lines, with `self.` turned into `_oN.` and its
temporaries renamed so they cannot meet the caller's.  The `_body` methods stay for calls
from Python.  ST spans travel with the lines, so errors still name the FB's own source.

Not inlined: bodies containing RETURN (a `return` would leave the caller), bodies over
`MAX_LINES`, calls deeper than `MAX_DEPTH`, and recursive instances.
"""
from __future__ import annotations

import re
from dataclasses import dataclass, field

MAX_LINES = 400
MAX_DEPTH = 4
_CALL = re.compile(r"^(\s*)(_o\d+)\._body\(\)$")
_SELF = re.compile(r"(?<![\w.])self\.")
_TEMP = re.compile(r"(?<![\w.])(_(?:t|o|i|n|e|s|c|q|r|en|cell)\d+)\b")


@dataclass
class Body:
    """Generated lines of one FB/PROGRAM body at indentation `depth` (4 spaces each)."""

    lines: list[str]
    spans: list
    depth: int
    calls: dict[str, str] = field(default_factory=dict)  # temp "_oN" -> FB key

    @property
    def inlinable(self) -> bool:
        return len(self.lines) <= MAX_LINES and not any(ln.strip() == "return" for ln in self.lines)


class Inliner:
    def __init__(self, bodies: dict[str, Body]):
        self.bodies = bodies
        self.counter = 0
        self._done: dict[str, tuple[list[str], list]] = {}

    def expanded(self, key: str, depth: int = 0, stack: tuple = ()) -> tuple[list[str], list]:
        """Lines and spans of `key`'s body with its FB calls inlined."""
        if depth == 0 and key in self._done:
            return self._done[key]
        body = self.bodies[key]
        lines, spans = [], []
        for line, span in zip(body.lines, body.spans):
            m = _CALL.match(line)
            callee = body.calls.get(m.group(2)) if m else None
            if (callee is None or callee in stack or depth >= MAX_DEPTH
                    or not self.bodies[callee].inlinable):
                lines.append(line)
                spans.append(span)
                continue
            indent, receiver = m.group(1), m.group(2)
            sub_lines, sub_spans = self.expanded(callee, depth + 1, stack + (key,))
            sub = self.bodies[callee]
            self.counter += 1
            suffix = f"_{self.counter}"
            strip = "    " * sub.depth
            for sl, ss in zip(sub_lines, sub_spans):
                text = sl[len(strip):] if sl.startswith(strip) else sl.lstrip()
                text = _TEMP.sub(r"\g<1>" + suffix, text)
                text = _SELF.sub(receiver + ".", text)
                lines.append(indent + text)
                spans.append(ss)
        if depth == 0:
            self._done[key] = (lines, spans)
        return lines, spans
