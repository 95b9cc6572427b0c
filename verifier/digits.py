"""Numbers as people type them: with the digits 0-9 only.

Python's int(), float(), Decimal() and Fraction() read the digits of every script too
('١٢' in Arabic-Indic, full-width '１２' as a Japanese or Chinese input method types them),
and str.isdigit() and the `\\d` of a regular expression take them (and '²', which int()
refuses). Such a digit in an option, a capture or a scenario's text is almost always an input
method left in the wrong mode: every number the toolkit parses from text is checked here
first, and the error names the character and the digit to write instead of taking it.
"""
from __future__ import annotations

import unicodedata


def foreign_digit(text: str) -> int | None:
    """The index of the first character of `text` that is a digit but not one of 0-9."""
    if text.isascii():  # the usual case, at C speed (a capture line can be megabytes long)
        return None
    return next((i for i, ch in enumerate(text) if ch.isdigit() and not ch.isascii()), None)


def digit_problem(text: str) -> str | None:
    """What is wrong with a number written with a digit other than 0-9, or None:
    "'١' (U+0661 ARABIC-INDIC DIGIT ONE) is not one of the digits 0-9 (write 1)"."""
    index = foreign_digit(text)
    if index is None:
        return None
    return describe(text[index])


def describe(ch: str) -> str:
    """How a message names a digit other than 0-9, and the one to write instead."""
    name = unicodedata.name(ch, "")
    value = unicodedata.digit(ch, None)
    instead = f"write {value}" if value is not None else "write the number with 0-9"
    return f"{ch!r} (U+{ord(ch):04X}{' ' + name if name else ''}) is not one of the digits 0-9 ({instead})"
