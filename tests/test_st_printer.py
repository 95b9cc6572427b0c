"""parse -> print -> parse gives the same tree (corpus, plc/, and generated expressions)."""
from __future__ import annotations

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from st_helpers import PLC_FILES, VALID, target_of
from verifier.st import ast, format_source, parse
from verifier.st.printer import expr_text


def same_tree(a: ast.SourceFile, b: ast.SourceFile) -> bool:
    return (a.pous, a.types, a.globals) == (b.pous, b.types, b.globals)


@pytest.mark.parametrize("path", VALID + PLC_FILES, ids=lambda p: p.name)
def test_round_trip_of_real_files(path):
    target = target_of(path)
    first = parse(path.read_text(encoding="utf-8"), str(path), target)
    assert first.ok, first.diagnostics
    printed = format_source(first)
    second = parse(printed, "printed.st", target)
    assert second.ok, (second.diagnostics, printed)
    assert same_tree(first, second)
    assert format_source(second) == printed  # printing is stable


NAMES = st.sampled_from(["a", "b", "wData", "iCount", "tmr"])
LEAVES = st.one_of(
    NAMES.map(ast.Name),
    st.integers(0, 70000).map(ast.IntLiteral),
    st.integers(0, 0xFFFF).map(lambda v: ast.IntLiteral(v, 16, "", f"16#{v:X}")),
    st.integers(0, 999).map(lambda v: ast.IntLiteral(v, 10, "K", f"K{v}")),
    st.booleans().map(ast.BoolLiteral),
    st.floats(0, 1e6, allow_nan=False).map(lambda f: ast.RealLiteral(float(repr(f)), repr(f))),
    st.integers(0, 10**7).map(lambda ms: ast.TimeLiteral(ms, f"T#{ms}ms")),
    st.text(st.characters(codec="latin-1", exclude_characters="\x00"), max_size=8).map(ast.StringLiteral),
    st.sampled_from(["D100", "M0", "X1F", "D0.F", "K4M0", "U0\\G100", "SM400"]).map(
        lambda t: parse(f"PROGRAM P x := {t}; END_PROGRAM", "d.st").pous[0].body[0].value),
)
BINARY_OPS = ["**", "*", "/", "MOD", "+", "-", "<", ">", "<=", ">=", "=", "<>", "AND", "XOR", "OR"]


def _extend(children):
    return st.one_of(
        st.tuples(st.sampled_from(BINARY_OPS), children, children).map(lambda t: ast.BinaryOp(*t)),
        st.tuples(st.sampled_from(["NOT", "-"]), children).map(lambda t: ast.UnaryOp(*t)),
        st.tuples(NAMES, st.lists(children, max_size=3)).map(
            lambda t: ast.Call(ast.Name(t[0].upper() + "_F"), [ast.Arg(v) for v in t[1]])),
        st.tuples(NAMES, st.lists(children, min_size=1, max_size=2)).map(
            lambda t: ast.Index(ast.Name(t[0]), t[1])),
        st.tuples(children, st.integers(0, 15)).map(
            lambda t: ast.BitAccess(t[0], t[1]) if isinstance(t[0], (ast.Name, ast.Index)) else t[0]),
    )


EXPRESSIONS = st.recursive(LEAVES, _extend, max_leaves=12)


@settings(max_examples=300, deadline=None)
@given(EXPRESSIONS)
def test_generated_expressions_round_trip(expr):
    text = f"PROGRAM P\nx := {expr_text(expr)};\nEND_PROGRAM\n"
    source = parse(text, "gen.st")
    assert source.ok, (source.diagnostics, text)
    assert source.pous[0].body[0].value == expr, text
