"""Turn lark's lexer/parser exceptions into messages that say what to write.

A missing `;` is reported where it belongs (right after the previous token), not at the
next line's first word; other errors name the unexpected text and what GX Works
expects there.
"""
from __future__ import annotations

import re

from lark import Lark, Token
from lark.exceptions import UnexpectedCharacters, UnexpectedEOF, UnexpectedInput, UnexpectedToken
from lark.lexer import PatternStr

from verifier.st import diagnose
from verifier.textfile import place_of_char

#: how terminals that are not plain strings are named in messages
_TERMINAL_WORDS = {
    "IDENT": "a name",
    "INT": "a number",
    "BASED_INT": "a number",
    "REAL": "a number",
    "TIME_LIT": "a time literal",
    "STRING_LIT": "a string",
    "WSTRING_LIT": "a string",
    "BUFFER_DEVICE": "a device",
    "VAR_KEYWORD": "VAR",
    "$END": "end of file",
}
_VAR_OPENERS = ("VAR", "VAR_INPUT", "VAR_OUTPUT", "VAR_IN_OUT", "VAR_TEMP", "VAR_GLOBAL",
                "VAR_EXTERNAL", "VAR_CONSTANT", "VAR_RETAIN", "VAR_GLOBAL_CONSTANT",
                "VAR_GLOBAL_RETAIN", "VAR_OUTPUT_RETAIN", "VAR_PUBLIC", "VAR_PUBLIC_RETAIN",
                "STRUCT")


def _terminal_text(parser: Lark, name: str) -> str:
    if name in _TERMINAL_WORDS:
        return _TERMINAL_WORDS[name]
    try:
        term = parser.get_terminal(name)
    except KeyError:
        return name
    if isinstance(term.pattern, PatternStr):
        return f"'{term.pattern.value.upper()}'"
    return name.lower()


def _expected_list(parser: Lark, names) -> str:
    words = sorted({_terminal_text(parser, n) for n in names})
    if len(words) > 8:
        words = words[:8] + ["..."]
    return ", ".join(words)


def _previous_token(parser: Lark, text: str, pos: int):
    """The last significant token ending at or before `pos` (None if none), and whether
    it sits inside a VAR...END_VAR / STRUCT block."""
    last = None
    depth = 0
    try:
        for tok in parser.lex(text[:pos]):
            if tok.end_pos is not None and tok.end_pos > pos:
                break
            kind = tok.type
            if kind in _VAR_OPENERS:
                depth += 1
            elif kind in ("END_VAR", "END_STRUCT"):
                depth = max(0, depth - 1)
            last = tok
    except UnexpectedInput:
        pass
    return last, depth > 0


def _token_text(tok) -> str:
    if tok.type == "$END":
        return "end of file"
    return diagnose.word(tok)


def _token_name(tok) -> str:
    return "the end of the file" if tok.type == "$END" else diagnose.word(tok)


def _semicolon_fixes(exc: UnexpectedToken) -> bool:
    """True when inserting ';' before the unexpected token lets the parse go on."""
    ip = getattr(exc, "interactive_parser", None)
    if ip is None:
        return True
    try:
        trial = ip.copy()
        trial.feed_token(Token("SEMI", ";"))
        return exc.token.type in trial.accepts()
    except Exception:  # noqa: BLE001 - a failed trial only means "not a missing ';'"
        return False


_BLOCK_COMMENT_RE = re.compile(r"\(\*[\s\S]*?\*\)")


def _error_pos(exc: UnexpectedInput, text: str) -> int:
    if isinstance(exc, UnexpectedCharacters):
        return exc.pos_in_stream
    tok = getattr(exc, "token", None)
    if tok is not None and tok.type != "$END" and tok.start_pos is not None:
        return tok.start_pos
    return len(text)


def _nested_comment(text: str, pos: int) -> tuple[int, int, str] | None:
    """When the error sits in the tail of a comment that held another '(*' (the first
    '*)' closed it early), point at that inner '(*'."""
    for m in _BLOCK_COMMENT_RE.finditer(text, 0, pos + 2):
        if m.end() > pos:
            break
        inner = text.find("(*", m.start() + 2, m.end() - 2)
        if inner == -1:
            continue
        tail_end = text.find("*)", m.end())
        if tail_end != -1 and pos <= tail_end + 1:
            line, col = place_of_char(text, inner)
            outer_line, outer_col = place_of_char(text, m.start())
            return (line, col, f"nested comments are not supported: this '(*' is inside the comment opened at "
                               f"{outer_line}:{outer_col}, which the first '*)' closes; remove the inner '(*' "
                               "and '*)'")
    return None


#: what a TIME literal needs, for the ST checker and for scenario conditions alike
TIME_LITERAL_HINT = "give every number its unit, d, h, m, s or ms (T#2s, T#1m30s, T#500ms)"
#: a word with '#' after a name: a time literal (T#2s) or a typed one (INT#5) as written
_HASH_WORD = re.compile(r"(?<![A-Za-z0-9_#.])([A-Za-z_][A-Za-z0-9_]*)#[-+0-9A-Za-z_.#]*")
#: the time literal st.lark reads (TIME_LIT), the whole word, case aside: for the ST checker
#: and scenario conditions alike ('#' escaped, so that a verbose pattern takes it too)
TIME_LITERAL = r"(?:TIME|T)\#-?(?:[0-9][0-9_]*(?:\.[0-9]+)?(?:ms|d|h|m|s)_?)+"
_TIME_WORD = re.compile(TIME_LITERAL, re.IGNORECASE)
#: a TIME literal with blanks between its parts (T#1h 30m, T#5 s, T#1h at a line's end and
#: 30m on the next): read as T#1h and a word '30m', which was "a name must not start with a
#: digit" (and, across lines, "'30m' is a duration without T#")
_SPACED_TIME = re.compile(r"(?<![A-Za-z0-9_#.])(?:TIME|T)#\s*-?(?:\s*[0-9][0-9_]*(?:\.[0-9]+)?\s*"
                          r"(?:ms|d|h|m|s)(?![A-Za-z])_?)+", re.IGNORECASE)


def spaced_time_literal(text: str, pos: int = -1) -> tuple[int, str] | None:
    """The first TIME literal of `text` written with a space, tab or line break inside
    (`T#1h 30m`) and reaching past `pos` (any, for -1), as (its offset, the message naming it
    and the blank it holds, with the spelling that reads: T#1h30m); None when there is none.
    For the ST checker and scenario conditions alike."""
    for m in _SPACED_TIME.finditer(text):
        word = m.group()
        if pos >= 0 and m.end() <= pos or not any(c.isspace() for c in word):
            continue
        if pos >= 0 and m.start() > pos:
            return None
        fixed = re.sub(r"\s+", "", word)
        if _TIME_WORD.fullmatch(fixed):
            blank = ("a line break" if "\n" in word or "\r" in word  # lines end at line feeds (lone CRs read so)
                     else "a space" if " " in word else "a tab" if "\t" in word else "a blank")
            return m.start(), f"{word!r}: a TIME literal cannot hold {blank}: write {fixed}"
    return None


#: units people write that TIME literals spell otherwise
_TIME_UNITS = {"msec": "ms", "msecs": "ms", "sec": "s", "secs": "s", "second": "s", "seconds": "s",
               "min": "m", "mins": "m", "minute": "m", "minutes": "m", "hr": "h", "hrs": "h",
               "hour": "h", "hours": "h", "day": "d", "days": "d"}
_TIME_PART = re.compile(r"([0-9][0-9_]*(?:\.[0-9]+)?)\s*([A-Za-z]+)")
#: IEC elementary types a typed literal (INT#5) may be prefixed with
_NUMBER_TYPES = {"BOOL", "INT", "DINT", "UINT", "UDINT", "SINT", "USINT", "LINT", "ULINT", "BYTE",
                 "WORD", "DWORD", "LWORD", "REAL", "LREAL"}
_DATE_TYPES = {"D", "DATE", "TOD", "TIME_OF_DAY", "DT", "DATE_AND_TIME"}
#: the rest of a date or time-of-day literal after what _HASH_WORD reads (TOD#12 :30:00)
_DATE_REST = re.compile(r"[-0-9:._]*")
_LONG_TIME_TYPES = {"LTIME", "LT"}


#: a number with a unit and no T# (500ms, 1.5s, 1m30s, 2sec), the whole word
#: (blanks between a number and its unit too: `2 s`, `1 h 30 m`)
_BARE_TIME = re.compile(r"[0-9][0-9_]*(?:\.[0-9]+)?[ \t]*[A-Za-z]+(?:[ \t]*[0-9][0-9_]*(?:\.[0-9]+)?[ \t]*[A-Za-z]+)*")


def bare_time(text: str, pos: int) -> tuple[int, str] | None:
    """A duration written without its T# (`500ms`, `1.5s`, `2sec`) that `pos` falls in:
    (its first character's offset, the message saying which TIME literal to write), or None.
    For the ST checker and scenario conditions alike: people write a scenario's durations
    ("500ms") and forget that ST and conditions spell them T#500ms."""
    start = pos
    while start > 0 and text[start - 1] in " \t":  # the unit of `2 s`
        start -= 1
    while start > 0 and (text[start - 1].isdigit() or text[start - 1] in "._"):
        start -= 1
    if start > 0 and (text[start - 1].isalnum() or text[start - 1] in "_#"):
        return None  # part of a name (D100), a radix or T# literal
    m = _BARE_TIME.match(text, start)
    if m is None or m.end() <= pos:
        return None
    word = m.group()
    literal = "T#" + re.sub(r"[ \t]+", "", _TIME_PART.sub(
        lambda p: p.group(1) + _TIME_UNITS.get(p.group(2).lower(), p.group(2)), word))
    if not _TIME_WORD.fullmatch(literal):
        return None
    return start, f"'{word}' is a duration without T#: a TIME literal is written {literal}"


def _hash_literal(text: str, pos: int) -> tuple[int, int, str] | None:
    """A TIME literal with a unit GX Works does not know or none (`T#2sec`, `T#2`: lark read
    `T#2s` and stumbled on `ec`, or found no literal and blamed the '#') and a typed literal
    (`INT#5`, unsupported): the whole word, at its first character, with what to write."""
    start = max(text.rfind("\n", 0, pos), text.rfind("\r", 0, pos)) + 1
    for m in _HASH_WORD.finditer(text, start):
        if m.start() > pos:
            break
        if pos >= m.end():
            continue
        word, prefix = m.group(), m.group(1).upper()
        line, col = place_of_char(text, m.start())
        if prefix in ("T", "TIME"):
            if _TIME_WORD.fullmatch(word):
                return None
            body = word[len(prefix) + 1:]
            fixed = _TIME_PART.sub(lambda p: p.group(1) + _TIME_UNITS.get(p.group(2).lower(), p.group(2)), body)
            hint = (f"; did you mean {prefix}#{fixed}?"
                    if fixed != body and _TIME_WORD.fullmatch(f"{prefix}#{fixed}") else "")
            return line, col, f"'{word}' is not a TIME literal: {TIME_LITERAL_HINT}{hint}"
        if prefix in _NUMBER_TYPES:
            value = word[len(prefix) + 1:]
            if prefix == "BOOL":
                value = {"0": "FALSE", "1": "TRUE"}.get(value, value)
            return (line, col, f"typed literals such as '{word}' are not supported (docs/st-dialect.md §3): "
                               f"write the value alone, {value}" if value else
                               f"typed literals such as '{word}' are not supported (docs/st-dialect.md §3): "
                               "write the value alone")
        if prefix in _DATE_TYPES:
            word += _DATE_REST.match(text, m.end()).group()
            return (line, col, f"'{word}': {prefix} literals are not supported; GX Works has no date or "
                               "time-of-day types (docs/st-dialect.md §6)")
        if prefix in _LONG_TIME_TYPES:  # the checker: "unknown type 'LTIME'"
            time = "T#" + word.split("#", 1)[1]
            instead = f", {time}" if _TIME_WORD.fullmatch(time) else ""
            return (line, col, f"'{word}': {prefix} literals are not supported (docs/st-dialect.md §6 has no LTIME "
                               f"type): write a TIME literal{instead}")
        return None
    return None


def describe_syntax_error(exc: UnexpectedInput, text: str, parser: Lark) -> tuple[int, int, str]:
    """(line, column, message) for a lark exception raised while reading `text`."""
    nested = _nested_comment(text, _error_pos(exc, text))
    if nested is not None:
        return nested
    spaced = spaced_time_literal(text, _error_pos(exc, text))
    if spaced is not None:
        return *place_of_char(text, spaced[0]), spaced[1]
    literal = _hash_literal(text, _error_pos(exc, text))
    if literal is not None:
        return literal
    bare = bare_time(text, _error_pos(exc, text))
    if bare is not None:
        line, col = place_of_char(text, bare[0])
        return line, col, bare[1]
    if isinstance(exc, (UnexpectedToken, UnexpectedEOF)):
        exc = diagnose.earlier_keyword_error(parser, text, _error_pos(exc, text)) or exc
    if isinstance(exc, UnexpectedCharacters):
        rest = text[exc.pos_in_stream: exc.pos_in_stream + 2]
        if rest == "(*" or rest == "/*":
            closer = "*)" if rest == "(*" else "*/"
            return exc.line, exc.column, f"comment '{rest}' is never closed; add '{closer}'"
        if exc.char in "'\"":
            return exc.line, exc.column, "string literal is not closed on this line; add the closing quote"
        if exc.char == "#":
            return exc.line, exc.column, "'#' must follow a radix (2#, 8#, 16#) or T#/TIME#"
        char = exc.char
        shown = repr(char) if not char.isprintable() else f"'{char}'"
        if not char.isascii() and char.isprintable():
            return (exc.line, exc.column,
                    f"unexpected character {shown}: names are ASCII letters, digits and '_' "
                    "(docs/st-dialect.md §4); other characters belong in comments and strings")
        return exc.line, exc.column, f"unexpected character {shown}; GX Works ST does not use it here"

    error_pos = _error_pos(exc, text)
    if text[error_pos:error_pos + 2] in ("(*", "/*"):
        closer = "*)" if text[error_pos] == "(" else "*/"
        line, col = place_of_char(text, error_pos)
        return line, col, f"comment '{text[error_pos:error_pos + 2]}' is never closed; add '{closer}'"
    accepted = (_accepted(exc) if isinstance(exc, UnexpectedToken) else set()) or set(exc.expected or ())
    explained = diagnose.explain(parser, text, error_pos, accepted)
    if explained is not None:
        return explained

    if isinstance(exc, UnexpectedEOF):
        expected = _expected_list(parser, exc.expected)
        line, col = place_of_char(text, len(text))
        return line, col, f"unexpected end of file; expected {expected}"

    assert isinstance(exc, UnexpectedToken)
    tok = exc.token
    expected = set(exc.expected)
    if tok.type == "$END":
        pos = len(text)
        line, col = place_of_char(text, pos)
    else:
        line, col, pos = tok.line, tok.column, tok.start_pos
    if tok.type in ("LPAR", "SLASH") and text[pos:pos + 2] in ("(*", "/*"):
        closer = "*)" if text[pos] == "(" else "*/"
        return line, col, f"comment '{text[pos:pos + 2]}' is never closed; add '{closer}'"
    if "SEMI" in expected and tok.type != "SEMI" and _semicolon_fixes(exc):
        # Reported where the mistake becomes certain (the token that cannot continue the
        # statement), naming the place the ';' goes.
        prev, in_decl = _previous_token(parser, text, pos)
        what = "declaration" if in_decl else "statement"
        if prev is not None:
            return (line, col, f"expected ';' at {prev.end_line}:{prev.end_column} to end the {what} "
                               f"before {_token_name(tok)}")
        return line, col, f"expected ';' to end the {what} before {_token_name(tok)}"
    if tok.type == "$END":
        closers = sorted(n for n in expected if n.startswith("END_"))
        if "SEMI" in expected and not closers:
            return line, col, "unexpected end of file; expected ';' after statement, then the END_ of the block"
        if closers:
            return line, col, f"unexpected end of file; expected {_expected_list(parser, closers)} to close the block"
        return line, col, f"unexpected end of file; expected {_expected_list(parser, expected)}"
    if tok.type == "INT" and re.match(r"[0-9]+[A-Za-z_]", text[pos:pos + 40]):
        word = re.match(r"[0-9A-Za-z_]+", text[pos:pos + 40]).group()
        return line, col, f"'{word}': a name must not start with a digit; rename it"
    accepted = _accepted(exc) or expected
    if {"IDENT", "INT", "LPAR"} <= accepted and "SEMI" not in accepted:
        prev, _ = _previous_token(parser, text, pos)
        after = f" after {_token_text(prev)}" if prev is not None else ""
        return line, col, f"expected an expression (a value, label or call){after}, not {_token_text(tok)}"
    if tok.type == "EQ" and "ASSIGN" in expected:
        return line, col, "'=' compares; write ':=' to assign"
    if tok.type == "ASSIGN" and "EQ" in expected:
        return line, col, "':=' assigns; write '=' to compare"
    keywords = sorted(n for n in accepted if _is_keyword(parser, n))
    if keywords and len(keywords) < len(accepted):
        return (line, col, f"unexpected {_token_text(tok)}; expected {_expected_list(parser, keywords)} "
                           "(or an operator continuing the expression before it)")
    return line, col, f"unexpected {_token_text(tok)}; expected {_expected_list(parser, accepted)}"


def _accepted(exc: UnexpectedToken) -> set[str]:
    """Terminals the parser really accepts at the error (lark's `expected` may include
    lookaheads of merged LALR states)."""
    ip = getattr(exc, "interactive_parser", None)
    if ip is None:
        return set()
    try:
        return set(ip.accepts()) - {"$END"} or set()
    except Exception:  # noqa: BLE001 - fall back to lark's expected set
        return set()


def _is_keyword(parser: Lark, name: str) -> bool:
    try:
        term = parser.get_terminal(name)
    except KeyError:
        return False
    return isinstance(term.pattern, PatternStr) and term.pattern.value.replace("_", "").isalpha() \
        and name not in ("AND", "OR", "XOR", "MOD", "NOT")
