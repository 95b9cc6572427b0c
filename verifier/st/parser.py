"""Read GX Works structured text into `verifier.st.ast` with lark's LALR parser.

The grammar is data (`st.lark`); `AstBuilder` is handed to the Lark constructor, so
lark calls it while parsing (no parse tree is built) — the fast path lark offers.
`parse()` never raises for bad input: lexical and syntax errors come back as
`Diagnostic`s naming file, line and column, with what to write instead.
"""
from __future__ import annotations

import re
from pathlib import Path

from lark import Lark, Token
from lark.exceptions import LarkError, UnexpectedCharacters, UnexpectedEOF, UnexpectedToken

from verifier.st import ast
from verifier.st.devices import H_CONST_RE, K_CONST_RE, parse_device
from verifier.st.errors import describe_syntax_error
from verifier.textfile import lone_cr_as_line_feed, text_lines

GRAMMAR_PATH = Path(__file__).with_name("st.lark")


class _ParseContext:
    """Per-parse state the builder and lexer callbacks write to (one parse at a time)."""

    def __init__(self) -> None:
        self.file = "<string>"
        self.target = "gxworks2"
        self.diagnostics: list[ast.Diagnostic] = []
        self.open_pous: list[ast.Pou] = []
        self.text = ""

    def reset(self, file: str, target: str, text: str = "") -> None:
        self.file = file
        self.target = target
        self.text = text  # split into lines only when a message needs a word of it
        self.diagnostics = []
        self.open_pous = []

    def word_at(self, line: int, col: int) -> str:
        """The keyword or name that starts at line:col of the text being parsed."""
        lines = text_lines(self.text)
        if not 1 <= line <= len(lines):
            return ""
        return re.match(r"[A-Za-z_0-9]*", lines[line - 1][col - 1:]).group().upper()

    def error(self, line: int, col: int, message: str, severity: str = "error") -> None:
        self.diagnostics.append(ast.Diagnostic(self.file, line, col, severity, message))


_ctx = _ParseContext()


def _tok_span(tok: Token) -> ast.Span:
    return ast.Span(_ctx.file, tok.line, tok.column, tok.end_line, tok.end_column)


def _start(item) -> tuple[int, int]:
    if isinstance(item, Token):
        return item.line, item.column
    if isinstance(item, list):
        return _start(item[0])
    return item.span.line, item.span.col


def _end(item) -> tuple[int, int]:
    if isinstance(item, Token):
        return item.end_line, item.end_column
    if isinstance(item, list):
        return _end(item[-1])
    return item.span.end_line, item.span.end_col


def _span(first, last) -> ast.Span:
    line, col = _start(first)
    end_line, end_col = _end(last)
    return ast.Span(_ctx.file, line, col, end_line, end_col)


_ESCAPES = {"$": "$", "'": "'", '"': '"', "L": "\n", "N": "\n", "P": "\f", "R": "\r", "T": "\t"}
_ESCAPE_RE = re.compile(r"\$([0-9A-Fa-f]{2}|.)")
_TIME_PART_RE = re.compile(r"([0-9][0-9_]*(?:\.[0-9]+)?)(ms|d|h|m|s)_?", re.IGNORECASE)
_TIME_UNIT_MS = {"D": 86_400_000, "H": 3_600_000, "M": 60_000, "S": 1000, "MS": 1}


def decode_escapes(body: str, unknown) -> str:
    """The text of a string literal's body with its `$` escapes decoded; `unknown(code)`
    gives what an unknown escape stands for (or raises)."""
    if "$" not in body:
        return body

    def escape(m: re.Match) -> str:
        code = m.group(1)
        if len(code) == 2:
            return chr(int(code, 16))
        mapped = _ESCAPES.get(code.upper())
        return unknown(code) if mapped is None else mapped

    return _ESCAPE_RE.sub(escape, body)


def _decode_string(tok: Token) -> str:
    def unknown(code: str) -> str:
        _ctx.error(tok.line, tok.column, f"unknown escape '${code}' in string; write '$$' for a dollar sign")
        return code

    return decode_escapes(tok.value[1:-1], unknown)


def _time_ms(tok: Token) -> int:
    return time_literal_ms(tok.value)


def time_literal_ms(value: str) -> int:
    """The value in ms of a TIME literal as st.lark reads it (`T#1m30s`, `TIME#-5ms`), as
    a TIME label holds it: for the ST readers and for scenario conditions alike."""
    text = value.split("#", 1)[1]
    negative = text.startswith("-")
    total = 0.0
    for number, unit in _TIME_PART_RE.findall(text):
        total += float(number.replace("_", "")) * _TIME_UNIT_MS[unit.upper()]
    ms = round(total)
    return -ms if negative else ms


def _classify_ident(tok: Token) -> ast.Expr:
    """An identifier in an expression is a label, a device (D100, K4M0 ...) or a MELSEC
    constant (K100, H1F) — decided by spelling, as GX Works forbids device-like labels."""
    text = tok.value
    span = _tok_span(tok)
    m = K_CONST_RE.fullmatch(text)
    if m:
        return ast.IntLiteral(int(m["value"]), 10, "K", text, span=span)
    m = H_CONST_RE.fullmatch(text)
    if m:
        return ast.IntLiteral(int(m["value"], 16), 16, "H", text, span=span)
    fields = parse_device(text)
    if fields is not None:
        return ast.Device(text=text, span=span, **fields)
    return ast.Name(text, span=span)


def _section(keyword: str, qualifiers: list[str]) -> tuple[str, bool, bool]:
    constant = "CONSTANT" in qualifiers
    retain = "RETAIN" in qualifiers or "PERSISTENT" in qualifiers
    for suffix, flag in (("_CONSTANT", "c"), ("_RETAIN", "r")):
        if keyword.endswith(suffix):
            keyword = keyword[: -len(suffix)]
            if flag == "c":
                constant = True
            else:
                retain = True
    return keyword, constant, retain


class AstBuilder:
    """lark callbacks, one per grammar rule/alias, building `ast` nodes from children
    (keep_all_tokens: every token of the rule is there, so spans are exact)."""

    # ------------------------------------------------------------- file
    def start(self, c):
        source = ast.SourceFile(_ctx.file, target=_ctx.target)
        for pou in _ctx.open_pous:
            if pou is not c[-1]:
                after = c[next(i for i, x in enumerate(c) if x is pou) + 1]
                first = after[0] if isinstance(after, list) else after
                before = _ctx.word_at(first.span.line, first.span.col)
                _ctx.error(first.span.line, first.span.col,
                           f"{pou.kind} {pou.name} opened at {pou.span.line}:{pou.span.col} is not closed: "
                           f"expected END_{pou.kind} before {before or 'the next declaration'}")
        for item in c:
            if isinstance(item, ast.Pou):
                source.pous.append(item)
            elif isinstance(item, ast.VarBlock):
                source.globals.append(item)
            else:  # list of StructDecl from a TYPE block
                source.types.extend(item)
        return source

    def pou(self, c):
        kind = c[0].value.upper()
        name = c[1].value
        closed = isinstance(c[-1], Token) and c[-1].type.startswith("END_")
        stop = -1 if closed else len(c)
        if kind == "FUNCTION":
            return_type, rest = c[3], c[4:stop]
        else:
            return_type, rest = None, c[2:stop]
        blocks = [x for x in rest if isinstance(x, ast.VarBlock)]
        body = rest[-1]
        last = c[-1]
        if not closed:
            last = body if body else (blocks[-1] if blocks else c[1])
        pou = ast.Pou(kind, name, return_type, blocks, body, span=_span(c[0], last))
        if not closed:
            _ctx.open_pous.append(pou)
        return pou

    # ------------------------------------------------------------- types
    def type_decl(self, c):
        return [x for x in c[1:-1]]

    def struct_decl(self, c):
        fields = [v for x in c[3:] if isinstance(x, list) for v in x]
        last = c[-1] if c[-1] is not None else c[-2]
        return ast.StructDecl(c[0].value, fields, span=_span(c[0], last))

    def semi_opt(self, c):
        return c[0] if c else None

    # ------------------------------------------------------------- declarations
    def var_keyword(self, c):
        return c[0]

    def var_qualifier(self, c):
        return c[0]

    def var_block(self, c):
        keyword = c[0].value.upper()
        qualifiers = [t.value.upper() for t in c[1:-1] if isinstance(t, Token)]
        section, constant, retain = _section(keyword, qualifiers)
        variables = []
        for item in c[1:-1]:
            if isinstance(item, list):
                for v in item:
                    v.section, v.constant, v.retain = section, constant, retain
                    variables.append(v)
        return ast.VarBlock(keyword, qualifiers, variables, span=_span(c[0], c[-1]))

    def var_decl(self, c):
        names = c[0]
        i = 1
        at = None
        if not (isinstance(c[i], Token) and c[i].type == "COLON"):
            at = c[i]
            i += 1
        type_ref = c[i + 1]
        init = c[i + 2] if len(c) > i + 3 else None
        end = c[-1]
        return [ast.VarDecl(t.value, type_ref, init, at=at, span=_span(t, end)) for t in names]

    def name_list(self, c):
        return [t for t in c if t.type == "IDENT"]

    def at_clause(self, c):
        tok = c[1]
        fields = parse_device(tok.value)
        if fields is None:
            _ctx.error(tok.line, tok.column, f"'{tok.value}' after AT is not a MELSEC device; write a device such as D100 or M0")
            return None
        return ast.Device(text=tok.value, span=_tok_span(tok), **fields)

    def init_clause(self, c):
        return c[1]

    def named_type(self, c):
        return ast.NamedType(c[0].value, span=_tok_span(c[0]))

    def string_type(self, c):
        length = int(c[2].value.replace("_", "")) if len(c) > 1 else None
        return ast.StringType(length, c[0].type == "WSTRING_KW", span=_span(c[0], c[-1]))

    def array_type(self, c):
        dims = [x for x in c[2:-3] if isinstance(x, ast.Subrange)]
        return ast.ArrayType(dims, c[-1], span=_span(c[0], c[-1]))

    def subrange(self, c):
        return ast.Subrange(c[0].value, c[2].value, span=_span(c[0], c[2]))

    def signed_int(self, c):
        tok = c[-1]
        if tok.type == "BASED_INT":
            lit = self.based_lit([tok])
        else:
            lit = self.int_lit([tok])
        if len(c) == 2:
            lit.value = -lit.value
            lit.text = "-" + lit.text
            lit.span = _span(c[0], tok)
        return lit

    def array_init(self, c):
        return ast.ArrayInit([x for x in c[1:-1] if isinstance(x, ast.ArrayInitItem)], span=_span(c[0], c[-1]))

    def array_item(self, c):
        if len(c) == 1:
            return ast.ArrayInitItem(c[0], None, span=c[0].span)
        count = int(c[0].value.replace("_", ""))
        value = c[2] if len(c) == 4 else None
        return ast.ArrayInitItem(value, count, span=_span(c[0], c[-1]))

    def struct_init(self, c):
        return ast.StructInit([x for x in c[1:-1] if isinstance(x, tuple)], span=_span(c[0], c[-1]))

    def field_init(self, c):
        return (c[0].value, c[2])

    # ------------------------------------------------------------- statements
    def stmt_list(self, c):
        return c

    def assignment(self, c):
        return ast.Assign(c[0], c[2], span=_span(c[0], c[3]))

    def call_statement(self, c):
        return ast.CallStmt(c[0], span=_span(c[0], c[1]))

    def if_statement(self, c):
        branches = [ast.IfBranch(c[1], c[3], span=_span(c[0], c[2]))]
        else_body = None
        for item in c[4:-2]:
            if isinstance(item, ast.IfBranch):
                branches.append(item)
            else:
                else_body = item[1]
        return ast.If(branches, else_body, span=_span(c[0], c[-1]))

    def elsif_part(self, c):
        return ast.IfBranch(c[1], c[3], span=_span(c[0], c[2]))

    def else_part(self, c):
        return ("else", c[1])

    def case_statement(self, c):
        clauses = []
        else_body = None
        for item in c[3:-2]:
            if isinstance(item, ast.CaseClause):
                clauses.append(item)
            else:
                else_body = item[1]
        return ast.Case(c[1], clauses, else_body, span=_span(c[0], c[-1]))

    def case_clause(self, c):
        labels = [x for x in c[:-2] if not isinstance(x, Token)]
        return ast.CaseClause(labels, c[-1], span=_span(c[0], c[-2]))

    def case_label(self, c):
        if len(c) == 1:
            return c[0]
        return ast.CaseRange(c[0], c[2], span=_span(c[0], c[2]))

    def for_statement(self, c):
        step = None
        i = 6
        if isinstance(c[6], tuple):
            step = c[6][1]
            i = 7
        return ast.For(c[1], c[3], c[5], step, c[i + 1], span=_span(c[0], c[-1]))

    def by_part(self, c):
        return ("by", c[1])

    def while_statement(self, c):
        return ast.While(c[1], c[3], span=_span(c[0], c[-1]))

    def repeat_statement(self, c):
        return ast.Repeat(c[1], c[3], span=_span(c[0], c[-1]))

    def exit_statement(self, c):
        return ast.Exit(span=_span(c[0], c[1]))

    def return_statement(self, c):
        return ast.Return(span=_span(c[0], c[1]))

    def empty_statement(self, c):
        return ast.Empty(span=_tok_span(c[0]))

    # ------------------------------------------------------------- expressions
    def binary(self, c):
        left, op, right = c
        text = op.value.upper()
        if text == "&":
            text = "AND"
        return ast.BinaryOp(text, left, right, span=_span(left, right))

    def unary(self, c):
        op, operand = c
        if op.type == "PLUS":
            return operand
        return ast.UnaryOp(op.value.upper(), operand, span=_span(op, operand))

    def paren(self, c):
        return c[1]

    def call(self, c):
        args = c[2] if len(c) == 4 else []
        return ast.Call(c[0], args, span=_span(c[0], c[-1]))

    def arg_list(self, c):
        return [x for x in c if isinstance(x, ast.Arg)]

    def arg_positional(self, c):
        return ast.Arg(c[0], span=c[0].span)

    def arg_input(self, c):
        return ast.Arg(c[2], c[0].value, span=_span(c[0], c[2]))

    def arg_output(self, c):
        return ast.Arg(c[2], c[0].value, True, span=_span(c[0], c[2]))

    def name(self, c):
        return _classify_ident(c[0])

    def buffer_device(self, c):
        tok = c[0]
        return ast.Device(text=tok.value, span=_tok_span(tok), **parse_device(tok.value))

    def index(self, c):
        indices = [x for x in c[2:-1] if not isinstance(x, Token)]
        return ast.Index(c[0], indices, span=_span(c[0], c[-1]))

    def member(self, c):
        base, tok = c[0], c[2]
        if isinstance(base, ast.Device) and re.fullmatch(r"[0-9A-Fa-f]", tok.value):
            return self._device_bit(base, tok)
        return ast.Member(base, tok.value, span=_span(base, tok))

    def bit_access(self, c):
        base, tok = c[0], c[2]
        if isinstance(base, ast.Device):
            return self._device_bit(base, tok)
        return ast.BitAccess(base, int(tok.value.replace("_", "")), span=_span(base, tok))

    def _device_bit(self, base: ast.Device, tok: Token) -> ast.Device:
        try:
            bit = int(tok.value, 16)
        except ValueError:
            bit = 16
        if bit > 15 or base.bit is not None or base.digits is not None or base.is_bit:
            _ctx.error(tok.line, tok.column,
                       f"'{base.text}.{tok.value}' is not a bit of a word device; write a word device and a bit 0-F, e.g. D0.F")
        base.bit = bit
        base.text = f"{base.text}.{tok.value}"
        base.span = _span(base, tok)
        return base

    # ------------------------------------------------------------- literals
    def int_lit(self, c):
        tok = c[0]
        return ast.IntLiteral(int(tok.value.replace("_", "")), 10, "", tok.value, span=_tok_span(tok))

    def based_lit(self, c):
        tok = c[0]
        radix, digits = tok.value.split("#", 1)
        radix = int(radix)
        try:
            value = int(digits.replace("_", ""), radix)
        except ValueError:
            _ctx.error(tok.line, tok.column, f"'{tok.value}' has a digit that is not valid in base {radix}")
            value = 0
        return ast.IntLiteral(value, radix, "", tok.value, span=_tok_span(tok))

    def real_lit(self, c):
        tok = c[0]
        return ast.RealLiteral(float(tok.value.replace("_", "")), tok.value, span=_tok_span(tok))

    def time_lit(self, c):
        tok = c[0]
        return ast.TimeLiteral(_time_ms(tok), tok.value, span=_tok_span(tok))

    def true_lit(self, c):
        return ast.BoolLiteral(True, span=_tok_span(c[0]))

    def false_lit(self, c):
        return ast.BoolLiteral(False, span=_tok_span(c[0]))

    def string_lit(self, c):
        return ast.StringLiteral(_decode_string(c[0]), False, span=_tok_span(c[0]))

    def wstring_lit(self, c):
        return ast.StringLiteral(_decode_string(c[0]), True, span=_tok_span(c[0]))


def _comment_style(tok: Token) -> Token:
    """GX Works2 reads only (* *) comments (ASSUMPTION, see docs/st-dialect.md)."""
    if _ctx.target == "gxworks2":
        style = "//" if tok.type == "LINE_COMMENT" else "/* */"
        _ctx.error(tok.line, tok.column,
                   f"GX Works2 does not accept {style} comments; write (* ... *) instead")
    return tok


#: No ST number needs more characters: LINT/ULINT have 20 digits, a 64-bit 2#... literal 64
#: (plus its underscores). Longer ones are reported and read as 0: Python reads no whole
#: number of more than 4300 digits, and prints none in a message; T#<400 digits>s is
#: no float.
MAX_NUMBER_CHARS = 100
_LONG_DIGITS = re.compile(r"[0-9][0-9_]{%d,}" % MAX_NUMBER_CHARS)
_NUMBER_TOKENS = ("INT", "BASED_INT", "REAL", "TIME_LIT")


def number_too_long(kind: str, text: str) -> bool:
    """Whether token `text` of terminal `kind` is, or holds, a number longer than
    MAX_NUMBER_CHARS: a literal, a device or buffer-memory number (D999...), a K or H
    constant."""
    if len(text) <= MAX_NUMBER_CHARS:
        return False
    if kind in _NUMBER_TOKENS:
        return True
    return _LONG_DIGITS.search(text) is not None or (kind == "IDENT" and H_CONST_RE.fullmatch(text) is not None)


def _long_number(tok: Token) -> Token:
    """A number too long for any PLC type: reported at its token, then read as 0."""
    if not number_too_long(tok.type, tok.value):
        return tok
    _ctx.error(tok.line, tok.column, f"a number of {len(tok.value)} characters: no PLC type holds one this "
                                     f"long (LINT has 20 digits); check this literal or device")
    if tok.type == "BASED_INT":
        zero = tok.value.split("#", 1)[0] + "#0"
    elif tok.type in _NUMBER_TOKENS:
        zero = {"INT": "0", "REAL": "0.0", "TIME_LIT": "T#0s"}[tok.type]
    elif H_CONST_RE.fullmatch(tok.value):
        zero = tok.value[0] + "0"
    else:
        zero = _LONG_DIGITS.sub("0", tok.value)
    return tok.update(value=zero)


_parser: Lark | None = None


def get_parser() -> Lark:
    """The LALR parser with the AST builder inlined (built once, grammar analysis cached)."""
    global _parser
    if _parser is None:
        _parser = Lark(
            GRAMMAR_PATH.read_text(encoding="utf-8"),
            parser="lalr",
            lexer="contextual",
            transformer=AstBuilder(),
            keep_all_tokens=True,
            propagate_positions=False,
            maybe_placeholders=False,
            cache=True,
            # IDENT last: lark 1.x chains a callback on IDENT after its keyword check with a
            # condition that reads the loop variable late (the last key), so only the last key
            # may have one
            lexer_callbacks={"LINE_COMMENT": _comment_style, "C_COMMENT": _comment_style,
                             **{kind: _long_number for kind in _NUMBER_TOKENS + ("BUFFER_DEVICE", "IDENT")}},
        )
    return _parser


def parse(text: str, filename: str = "<string>", target: str = "gxworks2") -> ast.SourceFile:
    """Parse ST `text`; never raises for bad input (errors are in `.diagnostics`).

    Text that reads without a diagnostic goes through the fast path
    (`verifier.st.fastparse`: same tokens, same tree, same spans); anything else is read
    by `parse_reference`, the lark parser over the grammar, which words the diagnostics.
    A lone carriage return (a classic Mac OS line end) ends a line, as in every editor."""
    from verifier.st import fastparse

    parser = get_parser()  # both read a lone carriage return as a line end
    try:
        return fastparse.parse_fast(text, filename, target, parser)
    except (fastparse.Bail, RecursionError):
        return parse_reference(text, filename, target)


def parse_reference(text: str, filename: str = "<string>", target: str = "gxworks2") -> ast.SourceFile:
    """`parse` with lark's LALR parser only (the reference the fast path must equal)."""
    text = lone_cr_as_line_feed(text)  # the lexers count lines at line feeds only
    parser = get_parser()
    _ctx.reset(filename, target, text)
    try:
        source = parser.parse(text)
    except (UnexpectedCharacters, UnexpectedToken, UnexpectedEOF) as exc:
        source = ast.SourceFile(filename, target=target)
        line, col, message = describe_syntax_error(exc, text, parser)
        _ctx.error(line, col, message)
    except LarkError as exc:  # any other lark failure is still the input's fault
        source = ast.SourceFile(filename, target=target)
        _ctx.error(1, 1, f"cannot read this file: {exc}")
    except RecursionError:
        source = ast.SourceFile(filename, target=target)
        _ctx.error(1, 1, "expression nested too deeply; split it into intermediate labels")
    source.diagnostics = sorted(_ctx.diagnostics, key=lambda d: (d.line, d.col))
    source.text = text
    return source
