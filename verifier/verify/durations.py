"""Durations as people write them in scenario files and on the command line.

"60s", "250ms", "1.5 s", "2min", "500us" → integer microseconds (the virtual clock's unit).
A bare number is rejected: a scenario that says `within = 5` is ambiguous.
"""
from __future__ import annotations

import re
from fractions import Fraction

from verifier.digits import digit_problem

_UNITS_US = {
    "us": 1,
    "µs": 1,
    "ms": 1_000,
    "s": 1_000_000,
    "min": 60_000_000,
    "h": 3_600_000_000,
}

_PATTERN = re.compile(r"^\s*([0-9]+(?:\.[0-9]+)?|\.[0-9]+)\s*(us|µs|ms|s|min|h)\s*$")


def parse_duration_us(text: object) -> int:
    """Return `text` ("250ms", "1.5s") in whole microseconds; ValueError on anything else."""
    if not isinstance(text, str):
        from verifier.tomlpos import shown

        if isinstance(text, (int, float)) and not isinstance(text, bool):
            raise ValueError(f"expected a duration such as \"250ms\" or \"60s\", got the bare number {shown(text)}: "
                             f"write it in quotes with its unit, e.g. \"{text}s\" or \"{text}ms\"")
        raise ValueError(f"expected a duration such as \"250ms\" or \"60s\", got {shown(text)}")
    if problem := digit_problem(text):
        raise ValueError(f"{text!r}: {problem}")
    match = _PATTERN.match(text)
    if not match:
        raise ValueError(
            f"{text!r} is not a duration: write a number and a unit (us, ms, s, min, h), "
            "e.g. \"250ms\" or \"60s\"" + _meant(text)
        )
    # Fraction() reads no number of more than 4300 digits: no duration needs 20 either side
    whole, _, fraction = match.group(1).partition(".")
    whole, fraction = whole.lstrip("0"), fraction.rstrip("0")
    if len(whole) > 20:
        raise ValueError(f"a duration of {len(whole)} digits is longer than any run: check the number, "
                         "e.g. \"250ms\" or \"60s\"")
    if len(fraction) > 20:
        raise ValueError(f"{text!r} is finer than the virtual clock's microsecond")
    value = Fraction(f"{whole or 0}.{fraction or 0}") * _UNITS_US[match.group(2)]
    if value.denominator != 1:
        raise ValueError(f"{text!r} is finer than the virtual clock's microsecond")
    return int(value)


#: units people write that are spelt otherwise here
_OTHER_UNITS = {
    "sec": "s", "secs": "s", "second": "s", "seconds": "s",
    "msec": "ms", "msecs": "ms", "millisecond": "ms", "milliseconds": "ms",
    "usec": "us", "microsecond": "us", "microseconds": "us",
    "m": "min", "mins": "min", "minute": "min", "minutes": "min",
    "hr": "h", "hrs": "h", "hour": "h", "hours": "h",
}
_OTHER = re.compile(r"^\s*(-?)\s*([0-9]+(?:\.[0-9]+)?|\.[0-9]+)\s*([A-Za-zµ]*)\s*$")


def _meant(text: str) -> str:
    """'; did you mean "5s"?' for "5sec", '; ... from power-on or a window's start: it cannot
    be negative' for "-1s"; '' when nothing better can be said."""
    match = _OTHER.match(text)
    if not match:
        st_time = re.match(r"^\s*(?:T|TIME)#(.*)$", text, re.IGNORECASE)
        if st_time:  # T#500ms: ST's TIME literal, where a scenario writes "500ms"
            meant = _meant(st_time.group(1))
            return (f"; T# belongs to ST and to conditions, not to a scenario's durations{meant}"
                    if meant.startswith("; did you mean") else "; T# belongs to ST and to conditions, "
                    "not to a scenario's durations")
        return ""
    sign, number, unit = match.groups()
    unit = _OTHER_UNITS.get(unit.lower(), unit.lower() if unit.lower() in _UNITS_US else None)
    if unit is None:
        return ""
    if sign:
        return "; a duration counts forward (from power-on, or from the window's start): it cannot be negative"
    return f"; did you mean \"{number}{unit}\"?"


def format_seconds(t_us: int) -> str:
    """Virtual time for people: seconds with millisecond precision ("12.345 s")."""
    return f"{t_us / 1_000_000:.3f} s"


def format_duration(us: int) -> str:
    """A duration the way people write it in scenario files: "24h", "90s", "250ms"."""
    for unit in ("h", "min", "s", "ms"):
        if us % _UNITS_US[unit] == 0:
            return f"{us // _UNITS_US[unit]}{unit}"
    return f"{us}us"
