"""The reader: literals, devices, precedence, comments and keywords come out as GX Works
reads them, with exact positions."""
from __future__ import annotations

import pytest

from verifier.st import ast, parse


def body_of(statements: str, decls: str = "", target: str = "gxworks2"):
    text = f"PROGRAM P\nVAR\n{decls}\nEND_VAR\n{statements}\nEND_PROGRAM\n"
    source = parse(text, "t.st", target)
    assert source.diagnostics == [], source.diagnostics
    return source.pous[0].body


def expr_of(text: str) -> ast.Expr:
    (stmt,) = body_of(f"x := {text};")
    return stmt.value


@pytest.mark.parametrize("text, value, radix, prefix", [
    ("42", 42, 10, ""), ("1_000", 1000, 10, ""), ("16#01A0", 0x01A0, 16, ""),
    ("16#ff_ff", 0xFFFF, 16, ""), ("2#1010_0000", 0xA0, 2, ""), ("8#17", 15, 8, ""),
    ("K100", 100, 10, "K"), ("H1F", 0x1F, 16, "H"), ("h0ff", 0xFF, 16, "H"),
])
def test_integer_literals(text, value, radix, prefix):
    lit = expr_of(text)
    assert isinstance(lit, ast.IntLiteral)
    assert (lit.value, lit.radix, lit.prefix) == (value, radix, prefix)


@pytest.mark.parametrize("text, ms", [
    ("T#1s", 1000), ("T#1s500ms", 1500), ("TIME#2h", 7_200_000), ("t#1d2h3m4s5ms", 93_784_005),
    ("T#1.5s", 1500), ("T#-5ms", -5), ("T#100MS", 100), ("T#1m_30s", 90_000),
])
def test_time_literals_in_milliseconds(text, ms):
    lit = expr_of(text)
    assert isinstance(lit, ast.TimeLiteral) and lit.ms == ms


def test_real_bool_and_string_literals():
    assert expr_of("1.5E2") == ast.RealLiteral(150.0)
    assert expr_of("0.25") == ast.RealLiteral(0.25)
    assert expr_of("TRUE") == ast.BoolLiteral(True)
    assert expr_of("false") == ast.BoolLiteral(False)
    assert expr_of("'a$'b$$c$N$R$T$41'") == ast.StringLiteral("a'b$c\n\r\tA")
    assert expr_of('"wide"') == ast.StringLiteral("wide", wide=True)


def test_unknown_string_escape_is_reported():
    source = parse("PROGRAM P\ns := 'a$Qb';\nEND_PROGRAM", "t.st")
    assert any("unknown escape '$Q'" in d.message for d in source.diagnostics)


@pytest.mark.parametrize("text, expected", [
    ("D100", dict(kind="D", address="100", number=100)),
    ("X1F", dict(kind="X", address="1F", number=31)),
    ("SM400", dict(kind="SM", address="400", number=400)),
    ("D0.F", dict(kind="D", number=0, bit=15)),
    ("D1.3", dict(kind="D", number=1, bit=3)),
    ("K4M0", dict(kind="M", number=0, digits=4)),
    ("D0Z1", dict(kind="D", number=0, index=1)),
    ("U0\\G100", dict(kind="G", number=100, module="0")),
    ("U3E0\\G10", dict(kind="G", number=10, module="3E0")),
    ("zr100", dict(kind="ZR", number=100)),
])
def test_devices_are_resolved(text, expected):
    dev = expr_of(text)
    assert isinstance(dev, ast.Device), dev
    for field, value in expected.items():
        assert getattr(dev, field) == value
    assert dev.text == text


def test_device_key_is_canonical():
    assert expr_of("d100").key == "D100"
    assert expr_of("U0\\G100").key == "U0\\G100"
    assert expr_of("D0.F").key == "D0"


def test_bit_of_a_label_and_members():
    assert expr_of("wData.3") == ast.BitAccess(ast.Name("wData"), 3)
    assert expr_of("tmr.Q") == ast.Member(ast.Name("tmr"), "Q")
    assert expr_of("a[1, 2].b.5") == ast.BitAccess(
        ast.Member(ast.Index(ast.Name("a"), [ast.IntLiteral(1), ast.IntLiteral(2)]), "b"), 5)


def test_iec_precedence():
    # ** binds tighter than unary minus, which binds tighter than * / MOD
    e = expr_of("-a ** 2 * b MOD c + d")
    assert e == ast.BinaryOp("+", ast.BinaryOp("MOD", ast.BinaryOp(
        "*", ast.UnaryOp("-", ast.BinaryOp("**", ast.Name("a"), ast.IntLiteral(2))), ast.Name("b")),
        ast.Name("c")), ast.Name("d"))
    e = expr_of("a OR b XOR c AND d = e")
    assert e == ast.BinaryOp("OR", ast.Name("a"), ast.BinaryOp(
        "XOR", ast.Name("b"), ast.BinaryOp("AND", ast.Name("c"),
                                           ast.BinaryOp("=", ast.Name("d"), ast.Name("e")))))
    assert expr_of("a & b") == ast.BinaryOp("AND", ast.Name("a"), ast.Name("b"))
    assert expr_of("a < b = c") == ast.BinaryOp("=", ast.BinaryOp("<", ast.Name("a"), ast.Name("b")), ast.Name("c"))
    assert expr_of("a - b - c") == ast.BinaryOp("-", ast.BinaryOp("-", ast.Name("a"), ast.Name("b")), ast.Name("c"))
    assert expr_of("NOT a AND b") == ast.BinaryOp("AND", ast.UnaryOp("NOT", ast.Name("a")), ast.Name("b"))


def test_output_binding_wins_over_equals():
    (stmt,) = body_of("tmr(IN:=b,PT:=T#1s,Q=>q,ET=>t);")
    args = stmt.call.args
    assert [(a.name, a.output) for a in args] == [("IN", False), ("PT", False), ("Q", True), ("ET", True)]
    (stmt,) = body_of("b := a>=c;")
    assert stmt.value.op == ">="


def test_keywords_are_case_insensitive_and_names_keep_spelling():
    (stmt,) = body_of("if Tmr.q then X := 1; end_if;")
    assert isinstance(stmt, ast.If)
    assert stmt.branches[0].cond.base.name == "Tmr"


def test_keyword_prefix_is_still_a_name():
    (stmt,) = body_of("IFX := ENDING;")
    assert stmt.target == ast.Name("IFX") and stmt.value == ast.Name("ENDING")


def test_comments_are_ignored_where_gx_works_allows_them():
    body = body_of("(* one *) x := 1; (* two\nlines *) y := 2;")
    assert len(body) == 2
    body = body_of("x := 1; // line\n/* block */ y := 2;", target="gxworks3")
    assert len(body) == 2


def test_spans_are_exact():
    source = parse("PROGRAM P\nVAR x : INT; END_VAR\n  x := x + 10;\nEND_PROGRAM", "f.st")
    stmt = source.pous[0].body[0]
    assert (stmt.span.line, stmt.span.col, stmt.span.end_line, stmt.span.end_col) == (3, 3, 3, 15)
    assert (stmt.value.right.span.col, stmt.value.right.span.end_col) == (12, 14)
    assert stmt.span.file == "f.st"
    decl = source.pous[0].variables[0]
    assert (decl.span.line, decl.span.col) == (2, 5)


def test_declarations_are_resolved():
    source = parse("""
FUNCTION_BLOCK FB
VAR_INPUT i_b : BOOL := TRUE; END_VAR
VAR CONSTANT C_N : INT := 3; END_VAR
VAR_RETAIN r : DINT; END_VAR
VAR a : ARRAY[0..1, -2..2] OF WORD := [10(16#FF)]; s : STRING(8); bX AT M0 : BOOL; END_VAR
END_FUNCTION_BLOCK""", "f.st")
    assert source.diagnostics == []
    v = {d.name: d for d in source.pous[0].variables}
    assert v["i_b"].section == "VAR_INPUT" and v["i_b"].init == ast.BoolLiteral(True)
    assert v["C_N"].constant and v["C_N"].section == "VAR"
    assert v["r"].retain and v["r"].section == "VAR"
    assert v["a"].type == ast.ArrayType([ast.Subrange(0, 1), ast.Subrange(-2, 2)], ast.NamedType("WORD"))
    assert v["a"].init.items[0].repeat == 10
    assert v["s"].type == ast.StringType(8)
    assert v["bX"].at.key == "M0"


def test_structures_and_globals():
    source = parse("TYPE s1 : STRUCT a : INT; b : BOOL; END_STRUCT; END_TYPE\n"
                   "VAR_GLOBAL g : s1; END_VAR\n", "f.st")
    assert source.diagnostics == []
    assert source.types[0].name == "s1" and [f.name for f in source.types[0].fields] == ["a", "b"]
    assert source.globals[0].variables[0].section == "VAR_GLOBAL"


def test_statements():
    body = body_of("""
CASE i OF 1, 2..4: x := 1; -1: ; ELSE x := 0; END_CASE;
FOR i := 10 TO 0 BY -2 DO EXIT; END_FOR;
WHILE b DO b := FALSE; END_WHILE;
REPEAT i := i + 1; UNTIL i > 3 END_REPEAT;
RETURN;
""")
    case, loop, whl, rep, ret = body
    assert isinstance(case.clauses[0].labels[1], ast.CaseRange)
    assert case.clauses[1].labels == [ast.IntLiteral(-1)]
    assert isinstance(case.clauses[1].body[0], ast.Empty)
    assert loop.step == ast.UnaryOp("-", ast.IntLiteral(2))
    assert isinstance(loop.body[0], ast.Exit)
    assert isinstance(whl, ast.While) and isinstance(rep, ast.Repeat) and isinstance(ret, ast.Return)


def test_instruction_call_forms():
    body = body_of("MOV(TRUE, K100, D100); ok := RS2(b, s[0], 8, 7, 1, r[0]); G_OUTPUT(b, 16#0, c, s, d);")
    assert body[0].call.name == "MOV" and len(body[0].call.args) == 3
    assert isinstance(body[1].value, ast.Call) and body[1].value.name == "RS2"
    assert body[2].call.key == "G_OUTPUT"


def test_pou_end_may_be_left_out_of_the_last_pou_only():
    assert parse("FUNCTION F : INT\nF := 1;\n", "f.st").diagnostics == []
    diags = parse("PROGRAM A\nPROGRAM B\nEND_PROGRAM", "f.st").diagnostics
    assert [(d.line, d.col) for d in diags] == [(2, 1)]
    assert "END_PROGRAM" in diags[0].message


def _only_error(text: str):
    (diag,) = parse(text, "t.st").diagnostics
    return diag.line, diag.col, diag.message


@pytest.mark.parametrize("statement, col, after, found", [
    ("y := 1 +;", 9, "'+'", "';'"),
    ("y := ;", 6, "':='", "';'"),
    ("y := MAX(1,);", 12, "','", "')'"),
    ("y := (2 * );", 11, "'*'", "')'"),
])
def test_missing_operand_says_an_expression_is_expected(statement, col, after, found):
    line, c, message = _only_error(f"PROGRAM M\nVAR y : INT; END_VAR\n{statement}\nEND_PROGRAM\n")
    assert (line, c) == (3, col)
    assert message == f"expected an expression (a value, label or call) after {after}, not {found}"


def test_nested_comment_is_named_at_the_inner_opener():
    line, col, message = _only_error("PROGRAM M\nVAR y : INT; END_VAR\n(* outer (* inner *) still *)\n"
                                     "y := 1;\nEND_PROGRAM\n")
    assert (line, col) == (3, 10)
    assert message.startswith("nested comments are not supported: this '(*' is inside the comment opened at 3:1")


def test_nested_comment_over_lines():
    text = "PROGRAM M\n(* header\n   old: (* y := 2; *)\n   more text *)\nEND_PROGRAM\n"
    line, col, message = _only_error(text)
    assert (line, col) == (3, 9) and message.startswith("nested comments are not supported")


def test_an_opener_inside_a_closed_comment_is_just_text():
    assert parse("PROGRAM M\n(* a (* b *)\nEND_PROGRAM\n", "t.st").diagnostics == []
