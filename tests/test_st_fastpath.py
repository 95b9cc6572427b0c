"""The fast reader (verifier/st/fastparse.py) answers exactly as the lark reference does.

For every corpus file (valid, invalid, broken), every PLC library file and generated
mutations of them: whenever the fast path answers, its tree is the reference tree field
by field — spans (line, col, end line, end col) and literal spellings included, which
plain `==` on the AST does not look at — the reference had no diagnostic, and the
semantic check says the same about both; and `parse` (fast path, else lark) gives the
reference's tree and diagnostics on every input.
"""
from __future__ import annotations

import dataclasses

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from st_helpers import CORPUS, INVALID, PLC_FILES, ROOT, SEEDS, TOKENS, VALID
from verifier.st import ast, check, fastparse, parse
from verifier.st.parser import get_parser, parse_reference

BROKEN = sorted((CORPUS / "broken").glob("*.st"))
ALL_FILES = VALID + INVALID + BROKEN + PLC_FILES
TARGETS = ("gxworks2", "gxworks3")
#: fields the semantic check fills in (None after parsing, not part of what is read)
ANNOTATIONS = {"type", "symbol", "resolved"}


def deep(x):
    """Every field of an AST (compare=False ones too: spans, literal texts), as nested
    tuples; the check's annotation fields left out."""
    if dataclasses.is_dataclass(x) and not isinstance(x, type):
        if isinstance(x, (ast.Expr,)) and x.type is not None:
            raise AssertionError(f"{type(x).__name__} annotated before the check")
        return (type(x).__name__,) + tuple(
            (f.name, deep(getattr(x, f.name))) for f in dataclasses.fields(x) if f.name not in ANNOTATIONS)
    if isinstance(x, (list, tuple)):
        return (type(x).__name__,) + tuple(deep(y) for y in x)
    return (type(x).__name__, x)


def first_difference(a, b, path="tree"):
    """Where two `deep` values first differ (for a readable failure)."""
    if type(a) is not type(b) or not isinstance(a, tuple):
        return None if a == b else f"{path}: {a!r} != {b!r}"
    if len(a) != len(b):
        return f"{path}: {len(a)} items != {len(b)} items ({a[:1]!r})"
    for i, (x, y) in enumerate(zip(a, b)):
        named = isinstance(x, tuple) and len(x) == 2 and isinstance(x[0], str)  # (field, value)
        where = first_difference(x, y, f"{path}.{x[0]}" if named else f"{path}[{i}]")
        if where:
            return where
    return None


def assert_same(text: str, filename: str = "t.st", target: str = "gxworks2") -> bool:
    """Check the fast path against the reference on `text`; True when it answered."""
    reference = parse_reference(text, filename, target)
    expected = deep(reference)
    try:
        fast = fastparse.parse_fast(text, filename, target, get_parser())
    except (fastparse.Bail, RecursionError):
        fast = None
    if fast is not None:
        assert reference.diagnostics == [], "the fast path answered where lark reports " + str(reference.diagnostics[0])
        difference = first_difference(deep(fast), expected)
        assert difference is None, f"fast path != reference at {difference}"
    public = parse(text, filename, target)
    assert public.diagnostics == reference.diagnostics
    difference = first_difference(deep(public), expected)
    assert difference is None, f"parse() != reference at {difference}"
    if fast is not None:  # last: the check annotates the trees
        assert check([fast], target) == check([reference], target)
    return fast is not None


@pytest.mark.parametrize("target", TARGETS)
@pytest.mark.parametrize("path", ALL_FILES, ids=lambda p: str(p.relative_to(ROOT)))
def test_every_file_reads_as_the_reference_reads_it(path, target):
    assert_same(path.read_text(encoding="utf-8"), str(path), target)


#: clean files the fast path leaves to lark: they use a keyword as a name where lark's
#: contextual lexer reads it as one (`MOD(a, b)`, a label called IF)
KEYWORD_AS_NAME = {"calls.st", "reserved_names.st"}


def test_the_fast_path_reads_every_clean_file():
    """The equivalence above is not vacuous: every file lark reads without a diagnostic
    is read by the fast path too (but for the known keyword-as-name files)."""
    clean = answered = 0
    for path in ALL_FILES:
        text = path.read_text(encoding="utf-8")
        for target in TARGETS:
            if parse_reference(text, str(path), target).diagnostics:
                continue
            clean += 1
            if assert_same(text, str(path), target):
                answered += 1
            else:
                assert path.name in KEYWORD_AS_NAME, f"fast path bailed on clean {path} ({target})"
    assert clean >= 100 and answered >= clean - 2 * len(KEYWORD_AS_NAME)


def test_a_wrong_fast_path_is_caught(monkeypatch):
    """The comparison can fail: a fast path that spells an operator or places a node one
    column off is reported."""
    text = (VALID[0].parent / "expressions.st").read_text(encoding="utf-8")
    assert assert_same(text, "e.st", "gxworks3")
    monkeypatch.setitem(fastparse._OP_TEXT, "PLUS", "-")
    with pytest.raises(AssertionError, match="fast path != reference"):
        assert_same(text, "e.st", "gxworks3")
    monkeypatch.undo()
    real = fastparse.make_span

    def off_by_one(file, line, col, end_line, end_col):
        return real(file, line, col, end_line, end_col + (line == end_line == 5))

    monkeypatch.setattr(fastparse, "make_span", off_by_one)
    with pytest.raises(AssertionError, match="end_col"):
        assert_same(text, "e.st", "gxworks3")


#: pieces that keep a program readable more often than not, and pieces that break it
BENIGN = [" ", "\n", "\t", "(* c *)", "/* c */", "// c\n", "\u3000", "\r\n"]
BREAKING = TOKENS + ["1", "1.5", "2#102", "'$Q'", "-", "+", "MOD", "x", "e5", "_", "END_FUNCTION_BLOCK"]


def mutate(data, text: str, pieces: list[str], steps: int) -> str:
    for _ in range(steps):
        pos = data.draw(st.integers(0, len(text)))
        action = data.draw(st.sampled_from(["delete", "insert", "duplicate", "swap", "case"]))
        if action == "delete":
            text = text[:pos] + text[pos + data.draw(st.integers(1, 20)):]
        elif action == "insert":
            text = text[:pos] + data.draw(st.sampled_from(pieces)) + text[pos:]
        elif action == "duplicate":
            length = data.draw(st.integers(1, 40))
            text = text[:pos] + text[pos:pos + length] + text[pos:]
        elif action == "swap":
            other = data.draw(st.integers(0, len(text)))
            a, b = sorted((pos, other))
            text = text[:a] + text[b:] + text[a:b]
        else:
            end = pos + data.draw(st.integers(1, 30))
            text = text[:pos] + text[pos:end].swapcase() + text[end:]
    return text


@settings(max_examples=300, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(st.sampled_from(SEEDS), st.data())
def test_mutated_programs_read_as_the_reference_reads_them(seed, data):
    text = mutate(data, seed, BREAKING, data.draw(st.integers(1, 4)))
    assert_same(text, "fuzz.st", data.draw(st.sampled_from(TARGETS)))


@settings(max_examples=300, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(st.sampled_from(SEEDS), st.data())
def test_lightly_mutated_programs_read_as_the_reference_reads_them(seed, data):
    """Mostly still valid (white space, comments, letter case, small cuts): the fast
    path answers for many of these, so its trees are compared, not only its bailing."""
    text = mutate(data, seed, BENIGN, data.draw(st.integers(1, 3)))
    assert_same(text, "fuzz.st", data.draw(st.sampled_from(TARGETS)))


@settings(max_examples=200, deadline=None)
@given(st.lists(st.sampled_from(BREAKING + ["x", "1", "TRUE", " ", "a := ", "b", "(", ")"]), max_size=60))
def test_token_soup_reads_as_the_reference_reads_it(tokens):
    assert_same("PROGRAM P\nVAR a, b, x : INT; END_VAR\n" + " ".join(tokens) + "\nEND_PROGRAM\n")


@pytest.mark.parametrize("opening", ["(*\r(*\r\n c *)\n", "(* x\ry *)\n", "(* x\r\ry *)\n"])
def test_a_lone_carriage_return_ends_a_line_on_both_paths(opening):
    """The reference reads a lone CR (a classic Mac OS line end) as a line end; the fast
    path, given the text as it came, counted a line fewer after one, so every span below
    was one line off (found by the mutation test above: '(*\r(*\r\n ...', 32 != 33). Both
    must answer, and alike."""
    text = opening + "PROGRAM P\nVAR\n    a : INT;\nEND_VAR\na := 1;\nEND_PROGRAM\n"
    for target in TARGETS:
        assert assert_same(text, "cr.st", target), "the fast path did not answer"


def test_deep_nesting_falls_back_to_the_reference():
    text = "PROGRAM P\nVAR x : INT; END_VAR\nx := " + "(" * 3000 + "1" + ")" * 3000 + ";\nEND_PROGRAM\n"
    assert_same(text)


def test_the_fast_path_follows_this_grammar():
    """fastparse.py mirrors st.lark rule by rule. After a grammar change, bring its
    parser in line (and this file's corpus with it), then set
    fastparse.GRAMMAR_SHA256 to the digest below."""
    parser = get_parser()
    assert fastparse.unavailable(parser) is None, (
        f"{fastparse.unavailable(parser)}; st.lark digest is {fastparse.grammar_digest(parser)}")


def test_another_grammar_turns_the_fast_path_off(monkeypatch):
    monkeypatch.setattr(fastparse, "GRAMMAR_SHA256", "0" * 64)
    monkeypatch.setattr(fastparse, "_tokenizer", None)
    monkeypatch.setattr(fastparse, "_unavailable", None)
    text = (VALID[0].parent / "statements.st").read_text(encoding="utf-8")
    with pytest.raises(fastparse.Bail):
        fastparse.parse_fast(text, "s.st", "gxworks2", get_parser())
    assert "not the grammar" in fastparse.unavailable(get_parser())
    assert deep(parse(text, "s.st")) == deep(parse_reference(text, "s.st"))


@pytest.mark.parametrize("target, opener", [("gxworks2", "(* "), ("gxworks3", "(* "), ("gxworks3", "/* ")])
def test_many_comments_never_closed_are_read_in_linear_time(target, opener):
    # the fast path's split tried each opener as a comment to the end of the text: 20,000
    # of them (100 kB) took 12 s, where the reference stops at the first
    import time

    text = "PROGRAM P\nVAR x : INT; END_VAR\nx := 1;\n" + opener * 20_000 + "\nEND_PROGRAM\n"
    started = time.perf_counter()
    diagnostics = parse(text, "open.st", target).diagnostics
    assert time.perf_counter() - started < 3
    assert [(d.line, d.col, d.message) for d in diagnostics] == [
        (4, 1, f"comment '{opener.strip()}' is never closed; add '{'*)' if opener[0] == '(' else '*/'}'")]


@pytest.mark.parametrize("text", [
    "PROGRAM P\nVAR s : STRING; END_VAR\ns := '(*';\nEND_PROGRAM\n",
    "PROGRAM P\nVAR x : INT; END_VAR\nx := 1; // (*\nEND_PROGRAM\n",
    "PROGRAM P\nVAR x : INT; END_VAR\nx := 1; (*)\nEND_PROGRAM\n",
    "PROGRAM P\nVAR x : INT; END_VAR\n(* (* *)\nx := 1;\nEND_PROGRAM\n",
])
def test_comment_openers_without_a_closer_read_as_the_reference_reads_them(text):
    for target in TARGETS:
        assert_same(text, target=target)


@pytest.mark.parametrize("quote", ["'", '"'])
def test_a_long_line_of_strings_never_closed_is_read_in_linear_time(quote):
    # each quote of a string not closed on its line was tried to the line's end: a line of
    # 40,000 characters took 8 s in the fast path's split, 0.1 s in the reference
    import time

    text = "PROGRAM P\nVAR x : INT; END_VAR\nx := " + f"{quote}$" * 20_000 + ";\nEND_PROGRAM\n"
    started = time.perf_counter()
    diagnostics = parse(text, "open.st", "gxworks3").diagnostics
    assert time.perf_counter() - started < 3
    assert [(d.line, d.col) for d in diagnostics] == [(3, 6)]
    assert diagnostics[0].message.startswith("string literal is not closed on this line")


def test_a_long_line_reads_as_the_reference_reads_it():
    text = ("PROGRAM P\nVAR s : STRING; x : INT; END_VAR\ns := 'it''s';\nx := " + " + ".join(["1"] * 400)
            + "; (* the robot's *)\nEND_PROGRAM\n")
    assert_same(text, target="gxworks3")
