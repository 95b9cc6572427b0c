"""Arbitrary input never raises: every problem comes back as a diagnostic with a place."""
from __future__ import annotations

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from st_helpers import SEEDS, TOKENS
from verifier.st import ast, check, parse


def run_all(text: str, target: str = "gxworks2") -> list[ast.Diagnostic]:
    source = parse(text, "fuzz.st", target)
    diags = source.diagnostics + check([source], target)
    for d in diags:
        assert d.file == "fuzz.st"
        assert d.severity in ("error", "warning")
        assert d.line >= 1 and d.col >= 1, d
        assert d.message
    return diags


@settings(max_examples=400, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(st.text(max_size=300))
def test_arbitrary_text_gives_diagnostics_not_exceptions(text):
    run_all(text)


@settings(max_examples=300, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(st.sampled_from(SEEDS), st.data())
def test_mutated_valid_programs_give_diagnostics_not_exceptions(seed, data):
    text = seed
    for _ in range(data.draw(st.integers(1, 4))):
        pos = data.draw(st.integers(0, len(text)))
        action = data.draw(st.sampled_from(["delete", "insert", "duplicate", "swap"]))
        if action == "delete":
            length = data.draw(st.integers(1, 20))
            text = text[:pos] + text[pos + length:]
        elif action == "insert":
            text = text[:pos] + data.draw(st.sampled_from(TOKENS)) + text[pos:]
        elif action == "duplicate":
            length = data.draw(st.integers(1, 40))
            text = text[:pos] + text[pos:pos + length] + text[pos:]
        else:
            other = data.draw(st.integers(0, len(text)))
            a, b = sorted((pos, other))
            text = text[:a] + text[b:] + text[a:b]
    target = data.draw(st.sampled_from(["gxworks2", "gxworks3"]))
    run_all(text, target)


@settings(max_examples=150, deadline=None)
@given(st.lists(st.sampled_from(TOKENS + ["x", "1", "TRUE", " "]), max_size=60))
def test_token_soup_gives_diagnostics_not_exceptions(tokens):
    run_all("PROGRAM P\n" + " ".join(tokens) + "\nEND_PROGRAM\n")


def test_deeply_nested_expression_is_a_diagnostic():
    text = "PROGRAM P\nVAR x : INT; END_VAR\nx := " + "(" * 3000 + "1" + ")" * 3000 + ";\nEND_PROGRAM\n"
    run_all(text)


def test_bad_input_reports_a_syntax_error_with_position():
    diags = run_all("PROGRAM P\nVAR x : INT; END_VAR\nx := (1 + ;\nEND_PROGRAM\n")
    assert any(d.is_error and d.line == 3 for d in diags)


LONG = "9" * 5000  # more digits than Python reads (4300) or a float holds in T#...s


@pytest.mark.parametrize("decl, body, col", [
    ("", f"x := {LONG};", 6),
    ("", f"x := 16#{LONG};", 6),
    ("", f"x := 1{LONG}.5;", 6),
    ("", f"t := T#{LONG}s;", 6),             # was OverflowError: float infinity to integer
    ("", f"x := K{LONG};", 6),
    ("", f"x := H{LONG};", 6),
    ("", f"x := D{LONG};", 6),
    ("", f"D{LONG} := 1;", 1),
    ("", f"x := U0\\G{LONG};", 6),
    ("", f"b := x.{LONG};", 8),
    (f"s : STRING[{LONG}];", "", 5),
    (f"a : ARRAY[0..{LONG}] OF INT;", "", 5),
    (f"c : INT := {LONG};", "", 5),
    (f"w AT D{LONG} : INT;", "", 5),
])
def test_numbers_too_long_for_python_are_diagnostics(decl, body, col):
    # each was a ValueError (int() reads at most 4300 digits) or an OverflowError
    text = f"PROGRAM P\nVAR x : INT; b : BOOL; t : TIME; {decl} END_VAR\n{body}\nEND_PROGRAM\n"
    errors = [d for d in run_all(text) if d.is_error]
    assert any("no PLC type holds one this long" in d.message for d in errors), errors
    line = 3 if body else 2
    assert all(d.line == line for d in errors), errors
    if body:
        assert errors[0].col == col


def test_a_64_bit_binary_literal_is_not_too_long():
    bits = "_".join(["1111"] * 16)  # 79 characters
    diags = run_all(f"PROGRAM P\nVAR x : LWORD; END_VAR\nx := 2#{bits};\nEND_PROGRAM\n")
    assert not any("no PLC type holds" in d.message for d in diags)
