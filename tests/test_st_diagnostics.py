"""Syntax errors point at the real mistake (issue 11).

`tests/corpus/broken/` holds one typing mistake per file, written the way people get ST
wrong (a block or VAR section left open, a missing ';', THEN, DO or OF, an unbalanced
parenthesis, a misspelt keyword), each with the one diagnostic it must get: its line,
column and message. Every message that names an open construct must name the keyword
that closes that construct, and the place it gives must hold that construct's keyword.
"""
from __future__ import annotations

import re
from pathlib import Path

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from st_helpers import CORPUS, PLC_FILES, VALID, diagnose, expectations
from verifier.st import parse
from verifier.st.diagnose import BRACKET_TEXT, CLOSER, OPENER_OF

BROKEN = sorted((CORPUS / "broken").glob("*.st"))

#: "IF opened at 6:1 is not closed: expected END_IF before END_FUNCTION_BLOCK"
_OPENED = re.compile(r"(?P<what>'[(\[]'|[A-Z_]+)(?: (?P<name>\w+))? opened at (?P<line>\d+):(?P<col>\d+)"
                     r"(?: is not closed: expected (?P<closer>\S+) before (?P<before>.+)$)?")
_NO_MATCH = re.compile(r"^(?P<closer>\S+) has no matching (?P<opener>[^\s:]+)")
_KEYWORD_NAMED = re.compile(r"\bEND_[A-Z_]+\b")


def test_corpus_is_large_enough():
    assert len(BROKEN) >= 60


def test_the_dialect_page_counts_the_broken_corpus_as_it_is():
    """docs/st-dialect.md §9 says how many typing mistakes the corpus holds: the number
    stays the corpus's own as files are added (it read 79 after three more were)."""
    page = (Path(__file__).parent.parent / "docs" / "st-dialect.md").read_text(encoding="utf-8")
    claim = re.search(r"`tests/corpus/broken/` holds (\d+) files", page)
    assert claim and int(claim.group(1)) == len(BROKEN), claim


@pytest.mark.parametrize("path", BROKEN, ids=lambda p: p.name)
def test_broken_file_gets_its_one_diagnostic(path):
    expected = expectations(path.read_text(encoding="utf-8"))
    assert len(expected) == 1, f"{path.name}: one mistake, one (* expect ... *) line"
    (line, col, severity, part), = expected
    _, diags = diagnose(path)
    assert [(d.line, d.col, d.severity) for d in diags] == [(line, col, severity)], \
        "\n".join(str(d) for d in diags)
    assert part in diags[0].message


@pytest.mark.parametrize("literal, message", [
    ("TOD#12:30:00", "'TOD#12:30:00': TOD literals are not supported; GX Works has no date or time-of-day types"),
    ("DT#2024-01-01-12:00:00", "'DT#2024-01-01-12:00:00': DT literals are not supported; GX Works has no date"),
    ("D#2024-01-01", "'D#2024-01-01': D literals are not supported; GX Works has no date"),
    ("LTIME#5s", "'LTIME#5s': LTIME literals are not supported (docs/st-dialect.md §6 has no LTIME type): "
                 "write a TIME literal, T#5s"),
    ("LT#1m30s", "'LT#1m30s': LT literals are not supported (docs/st-dialect.md §6 has no LTIME type): "
                 "write a TIME literal, T#1m30s"),
])
def test_a_date_or_long_time_literal_is_named_whole_and_for_what_it_is(tmp_path, literal, message):
    """58cb9e5 names the literal whole at its first character; a time of day was cut at its
    first ':' ('TOD#12'), and LTIME#5s was said to be a date or time-of-day type."""
    path = tmp_path / "p.st"
    path.write_text(f"PROGRAM P\nVAR\n    t : TIME;\nEND_VAR\nt := {literal};\nEND_PROGRAM\n", encoding="utf-8")
    _, diags = diagnose(path)
    assert [(d.line, d.col, d.severity) for d in diags] == [(5, 6, "error")], "\n".join(map(str, diags))
    assert message in diags[0].message, diags[0].message


def _opener_text(what: str) -> str:
    return what.strip("'")


_WORDS = re.compile(r"\(\*[\s\S]*?\*\)|//[^\n]*|/\*[\s\S]*?\*/|'[^'\n]*'|\"[^\"\n]*\"|[A-Za-z_]\w*")
_OPENS = {"IF": "END_IF", "CASE": "END_CASE", "FOR": "END_FOR", "WHILE": "END_WHILE", "REPEAT": "END_REPEAT",
          "FUNCTION_BLOCK": "END_FUNCTION_BLOCK", "FUNCTION": "END_FUNCTION", "PROGRAM": "END_PROGRAM",
          "TYPE": "END_TYPE", "STRUCT": "END_STRUCT"}


def closers_open_at(text: str, line: int, col: int) -> set[str]:
    """The END_ keywords of every construct open before line:col, counted independently
    of the code under test (keywords outside comments and strings)."""
    offset = sum(len(x) for x in text.splitlines(keepends=True)[:line - 1]) + col - 1
    stack: list[str] = []
    for m in _WORDS.finditer(text, 0, max(offset, 0)):
        w = m.group().upper()
        if w in _OPENS:
            stack.append(_OPENS[w])
        elif w.startswith("VAR"):
            stack.append("END_VAR")
        elif w.startswith("END_") and w in stack:
            del stack[len(stack) - 1 - stack[::-1].index(w):]
    return set(stack)


def check_message_fits(text: str, line: int, col: int, message: str) -> None:
    """The open construct a message names is really there, and the keyword it asks for
    is the one that closes it; any other END_ keyword it names is the token that arrived
    at the reported place or the one that closes a construct it names."""
    lines = text.splitlines()
    allowed: set[str] = set() if _OPENED.search(message) else closers_open_at(text, line, col)
    opened = _OPENED.search(message)
    if opened is not None:
        what = opened["what"]
        kind = next((k for k, v in BRACKET_TEXT.items() if v == what), what)
        assert kind in CLOSER, message
        o_line, o_col = int(opened["line"]), int(opened["col"])
        assert lines[o_line - 1][o_col - 1:].upper().startswith(_opener_text(what)), \
            f"{message!r}: {what} is not at {o_line}:{o_col}"
        allowed.add(CLOSER[kind])
        if opened["closer"] is not None:
            closer = opened["closer"]
            wanted = BRACKET_TEXT.get(CLOSER[kind], CLOSER[kind])
            assert closer == wanted, f"{message!r}: {what} is closed by {wanted}, not {closer}"
    stray = _NO_MATCH.search(message)
    if stray is not None:
        closer = next((k for k, v in BRACKET_TEXT.items() if v == stray["closer"]), stray["closer"])
        opener = OPENER_OF[closer]
        assert stray["opener"] == BRACKET_TEXT.get(opener, opener), message
        allowed.add(closer)
    if 1 <= line <= len(lines):
        arrived = re.match(r"\w*", lines[line - 1][col - 1:]).group().upper()
        allowed.add(arrived)
    for place in re.finditer(r"before (\S+) at (\d+):(\d+)", message):
        b_line, b_col = int(place[2]), int(place[3])
        allowed.add(re.match(r"\w*", lines[b_line - 1][b_col - 1:]).group().upper())
    named = set(_KEYWORD_NAMED.findall(message))
    assert named <= allowed, f"{message!r} names {sorted(named - allowed)}, which close nothing open there"


@pytest.mark.parametrize("path", BROKEN + sorted((CORPUS / "invalid").glob("*.st")), ids=lambda p: p.name)
def test_no_message_names_a_keyword_that_does_not_fit(path):
    text = path.read_text(encoding="utf-8")
    _, diags = diagnose(path)
    for d in diags:
        check_message_fits(text, d.line, d.col, d.message)


def test_the_example_of_the_issue():
    text = ("FUNCTION_BLOCK FB_Motor\n"
            "VAR_INPUT i_bRun : BOOL; END_VAR\n"
            "VAR_OUTPUT o_bOn : BOOL; END_VAR\n"
            "VAR iCount : INT; END_VAR\n"
            "iCount := iCount + 1;\n"
            "IF i_bRun THEN\n"
            "    o_bOn := TRUE;\n"
            "ELSE\n"
            "    o_bOn := FALSE;\n"
            "END_FUNCTION_BLOCK\n")
    diags = parse(text, "FB_Motor.st").diagnostics
    assert [str(d) for d in diags] == [
        "FB_Motor.st:10:1: error: IF opened at 6:1 is not closed: expected END_IF before END_FUNCTION_BLOCK"]


# ------------------------------------------------------------------ mutated valid files
_SOURCES = [p for p in VALID + PLC_FILES if p.stat().st_size < 20_000]
_TOKEN = re.compile(r"\(\*[\s\S]*?\*\)|'[^'\n]*'|\w+|:=|<>|<=|>=|\.\.|\S")


def _mutate(text: str, choice: int, where: int) -> str:
    """Delete one token, or one line, or one keyword that closes something."""
    tokens = [m for m in _TOKEN.finditer(text) if not m.group().startswith("(*")]
    if choice == 0:  # a token
        m = tokens[where % len(tokens)]
        return text[:m.start()] + text[m.end():]
    if choice == 1:  # a line
        lines = text.splitlines(keepends=True)
        i = where % len(lines)
        return "".join(lines[:i] + lines[i + 1:])
    closers = [m for m in tokens if m.group().upper() in OPENER_OF or m.group() in (";", ")", "THEN", "DO")]
    if not closers:
        return text
    m = closers[where % len(closers)]
    return text[:m.start()] + text[m.end():]


@settings(max_examples=150, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(st.sampled_from(_SOURCES), st.integers(0, 2), st.integers(0, 10_000))
def test_mutated_programs_get_well_placed_diagnostics(path: Path, choice: int, where: int):
    text = _mutate(path.read_text(encoding="utf-8"), choice, where)
    source = parse(text, "mutant.st", "gxworks3")
    lines = text.splitlines()
    for d in source.diagnostics:
        assert 1 <= d.line <= len(lines) + 1 and d.col >= 1, str(d)
        assert d.message and "Traceback" not in d.message
        check_message_fits(text, d.line, d.col, d.message)
