"""The success path of the ST reader: a tokenizer and a recursive-descent parser that
build exactly the AST the lark path builds (verifier/st/parser.py), several times faster.

The lark LALR parser over `st.lark` stays the reference: this module only answers for
text it reads completely and without any diagnostic. Anything else — a syntax error, a
character no terminal matches, a construct that makes the lark builder report something
(a // comment for GX Works2, an unknown `$` escape, `AT` with a non-device, a bad digit
in `2#...`, a bad device bit, a POU left open before another one), a keyword written
where the grammar wants a name, a non-ASCII identifier, nesting too deep for recursion —
raises `Bail`, and `parse()` reads the text again with lark, which gives the diagnostics.

Why the results are the same (tests/test_st_fastpath.py checks it on every corpus file
and on generated mutations of them):

* Tokens. The tokenizer is built from the terminals of lark's root lexer (the grammar
  is the data): the same regular expressions, tried in the same order (lark's order:
  priority, then width), ignored terminals (white space, comments) skipped the same
  way, and an identifier spelling a keyword turned into that keyword as lark's
  root lexer does. Lark's contextual lexer uses, in each parser state, a subset of
  these terminals in the same order; when the token found here is one the state
  accepts (it always is when the parse below succeeds, since the whole token
  sequence is then a sentence of the grammar), the state's lexer finds the same
  token. So on success both parsers see the same tokens.
* Trees. The grammar is LALR(1) and unambiguous (its only conflicts, a VAR keyword
  after the VAR sections of a POU whose body is empty, are resolved by lark as shift:
  the section belongs to the POU; the VAR section loop here is greedy too), so a
  sentence has one parse tree; the functions below follow the grammar's rules one by
  one and build each node as `AstBuilder` builds it from the same tokens, spans
  included (line/column of the first and one past the last character).
"""
from __future__ import annotations

import gc
import hashlib
import re
from itertools import accumulate, repeat
from operator import add, sub

from verifier.st import ast
from verifier.st.devices import H_CONST_RE, K_CONST_RE, parse_device
from verifier.textfile import lone_cr_as_line_feed
from verifier.st.parser import MAX_NUMBER_CHARS, _section, decode_escapes, number_too_long, time_literal_ms


class Bail(Exception):
    """The fast path does not answer for this text: read it with lark."""


# ----------------------------------------------------------------------------- spans
_Span = ast.Span


class _SpanSlots:
    """The slots of `ast.Span` without its frozen `__setattr__`: filled with plain
    attribute stores, then made a Span by class assignment (which Python allows only
    between classes of the same layout). A quarter of the fast path's time went into
    the frozen dataclass's `object.__setattr__` calls."""

    __slots__ = ("file", "line", "col", "end_line", "end_col")


def _span_by_class_assignment(file: str, line: int, col: int, end_line: int, end_col: int) -> ast.Span:
    s = _SpanSlots()
    s.file = file
    s.line = line
    s.col = col
    s.end_line = end_line
    s.end_col = end_col
    s.__class__ = _Span
    return s


def _span_by_constructor(file: str, line: int, col: int, end_line: int, end_col: int) -> ast.Span:
    return _Span(file, line, col, end_line, end_col)


def _same_span(make) -> bool:
    try:
        made = make("f", 1, 2, 3, 4)
    except TypeError:  # ast.Span's layout changed
        return False
    return type(made) is _Span and made == _Span("f", 1, 2, 3, 4) and repr(made) == repr(_Span("f", 1, 2, 3, 4))


#: `ast.Span(file, line, col, end_line, end_col)`, the same object, made faster
make_span = _span_by_class_assignment if _same_span(_span_by_class_assignment) else _span_by_constructor


# ----------------------------------------------------------------------------- tokens
_PUNCT_KINDS = ("ASSIGN_OUT", "ASSIGN", "DOTDOT", "GE", "LE", "NE", "POW", "AMP", "COLON",
                "COMMA", "DOT", "EQ", "GT", "LPAR", "LSQB", "LT", "MINUS", "PLUS", "RPAR",
                "RSQB", "SEMI", "SLASH", "STAR")
_ERR = "<error>"
_END = "$END"


def _noncapturing(rx: str) -> str:
    """`rx` with its capturing groups made non-capturing (escapes and classes kept)."""
    out = []
    i = 0
    in_class = False
    while i < len(rx):
        ch = rx[i]
        if ch == "\\":
            out.append(rx[i:i + 2])
            i += 2
            continue
        if in_class:
            if ch == "]":
                in_class = False
        elif ch == "[":
            in_class = True
            out.append(ch)
            i += 1
            if i < len(rx) and rx[i] == "^":
                out.append("^")
                i += 1
            if i < len(rx) and rx[i] == "]":  # a ']' first in a class is literal
                out.append("]")
                i += 1
            continue
        elif ch == "(" and not rx.startswith("(?", i):
            out.append("(?:")
            i += 1
            continue
        out.append(ch)
        i += 1
    result = "".join(out)
    assert re.compile(result).groups == 0, (rx, result)
    return result


#: longer lines that hold a quote go to the reference parser (see `Tokenizer.tokenize`);
#: those of the PLC library and the corpus are at most 200 characters
LONG_LINE = 500


class Tokenizer:
    """lark's root lexer for `st.lark`, run as C loops: `re.split` on one regular
    expression — (ignored text)(token) — cuts the text into what lark skips (white space,
    comments) and tokens; positions come from running sums of their lengths and newline
    counts; kinds from a table of the token texts already seen."""

    def __init__(self, lark_parser) -> None:
        root = lark_parser.parser.lexer.root_lexer
        scanner = root.scanner  # builds the scanner: keywords folded into IDENT
        assert not root.g_regex_flags
        terminals = scanner.terminals  # lark's order (priority, width, length, name)
        ignored = [t for t in terminals if t.name in root.ignore_types]
        tokens = [t for t in terminals if t.name not in root.ignore_types]
        by_name = {t.name: t for t in terminals}
        skip_rx = "|".join(_noncapturing(t.pattern.to_regexp()) for t in ignored)
        token_rx = "|".join(_noncapturing(t.pattern.to_regexp()) for t in tokens)
        white_rx = _noncapturing(by_name["WS"].pattern.to_regexp())
        assert re.fullmatch(r"\[[^\]]*\]\+", white_rx), white_rx  # one class, repeated
        # Lark tries its terminals in this order at every position and takes the first
        # that matches; ignored ones (comments: highest priority; white space: starts no
        # token) are always tried first, so (ignored text)(token) reads the same tokens.
        # The skip loop is possessive (lark never gives an ignored token back). `\Z` takes
        # the ignored text at the end of the text and stands for lark's end marker.
        # A match never starts just after white space, so where the sequential reading
        # stops (a character no terminal reads) the text between two matches is not
        # empty: the tokenizer bails there.
        self.split = re.compile(
            f"(?<!{white_rx[:-1]})((?:{skip_rx})*+)({token_rx}|\\Z)").split
        self.comment_style = re.compile(
            "|".join(f"(?P<{t.name}>{t.pattern.to_regexp()})" for t in ignored)).finditer
        ident = root.callback["IDENT"]
        ident = getattr(ident, "callback1", ident)  # lark's CallChain: the keyword check, then _long_number
        unless = ident.scanner  # the keywords an IDENT is turned into
        self.keywords = {t.pattern.value.upper(): t.name for t in unless.terminals}
        assert all(k.isascii() for k in self.keywords)
        names = {t.name for t in tokens}
        assert set(_PUNCT_KINDS) <= names, set(_PUNCT_KINDS) - names
        self.punct = {t.pattern.value: t.name for t in tokens if t.name in _PUNCT_KINDS}
        assert len(self.punct) == len(_PUNCT_KINDS)
        self.punct[""] = _END
        self.kinds: dict[str, str] = dict(self.punct)  # token text -> kind, as seen

    def classify(self, tok: str) -> str:
        """The terminal a token's text was read as (the regex alternatives are told apart
        by their first characters and what they may contain)."""
        first = tok[0]
        if first.isascii() and (first.isalpha() or first == "_"):
            if not tok.isascii():
                return _ERR  # lark's IGNORECASE classes take a few non-ASCII letters
            if "#" in tok:
                return "TIME_LIT"
            if "\\" in tok:
                return "BUFFER_DEVICE"
            return self.keywords.get(tok.upper(), "IDENT")
        if first.isascii() and first.isdigit():
            if not tok.isascii():
                return _ERR
            if "#" in tok:
                return "BASED_INT"
            if "." in tok or "e" in tok or "E" in tok:
                return "REAL"
            return "INT"
        if first == "'":
            return "STRING_LIT"
        if first == '"':
            return "WSTRING_LIT"
        return self.punct.get(tok, _ERR)

    def tokenize(self, text: str, gxworks2: bool) -> tuple[list, list, list, list]:
        """Kinds, values, lines and columns (1-based, as lark counts) of the significant
        tokens, then the end marker. Raises Bail on a character no terminal reads and on
        a comment GX Works2 does not accept."""
        for opener, closer in (("(*", "*)"), ("/*", "*/")):
            # a comment opened after the last closer is never closed; the split tries each
            # such opener as a comment to the end of the text, in the square of its length
            # (20,000 of them: 12 s), where lark stops at the first
            last = text.rfind(opener)
            if last >= 0 and text.find(closer, last + 2) < 0:
                raise Bail
        lines = text.split("\n")
        widths = list(map(len, lines))
        if max(widths) > LONG_LINE and any(len(line) > LONG_LINE and ("'" in line or '"' in line)
                                           for line in lines):
            # likewise each quote of a string not closed on its line is tried to the line's
            # end: on a line of 40,000 characters, 8 s
            raise Bail
        del lines
        parts = self.split(text)  # "", ignored, token, "", ignored, token, ..., "", ignored, "", ...
        if any(parts[0::3]):  # text no terminal reads
            raise Bail
        V = parts[2::3]
        n = V.index("") + 1  # the \Z match: the end (empty matches may follow it)
        del V[n:]
        skips = parts[1:3 * n:3]
        if gxworks2 and "/" in "".join(skips):
            self._check_comments(skips)
        starts = list(accumulate(map(len, parts[:3 * n])))[1::3]  # where each token starts
        LN = list(accumulate(map(str.count, skips, repeat("\n")), initial=1))
        del LN[0]
        if LN[-1] == len(widths):
            # no token holds a line feed (all of them are in the skipped text): the last one
            # before a token is the one that ends the line before the token's line, found by
            # the line number, not by a search per token (a twentieth of the parse)
            before_line = list(accumulate(map(add, widths, repeat(1)), initial=-1))
            before_line.insert(0, None)  # by line number: where the line before it ends
            CL = list(map(sub, starts, map(before_line.__getitem__, LN)))
        else:
            CL = list(map(sub, starts, map(text.rfind, repeat("\n"), repeat(0), starts)))
        kinds = self.kinds
        K = list(map(kinds.get, V))
        if max(map(len, V)) > MAX_NUMBER_CHARS:
            self._check_numbers(K, V)
        if None in K:
            j = -1
            try:
                while True:
                    j = K.index(None, j + 1)
                    tok = V[j]
                    kind = self.classify(tok)
                    if kind == _ERR:
                        raise Bail
                    if kind != "STRING_LIT" and kind != "WSTRING_LIT":
                        if len(kinds) > 200_000:
                            kinds.clear()
                            kinds.update(self.punct)
                        kinds[tok] = kind
                    K[j] = kind
            except ValueError:
                pass
        return K, V, LN, CL

    def _check_numbers(self, K: list, V: list[str]) -> None:
        for kind, tok in zip(K, V):
            if number_too_long(kind or self.classify(tok), tok):
                raise Bail  # the lark path reports it

    def _check_comments(self, skips: list[str]) -> None:
        for skip in skips:
            if "/" in skip:
                for m in self.comment_style(skip):
                    if m.lastgroup in ("LINE_COMMENT", "C_COMMENT"):
                        raise Bail  # the lark path reports it


# ----------------------------------------------------------------------------- parser
_STATEMENT_START = frozenset({"IDENT", "BUFFER_DEVICE", "IF", "CASE", "FOR", "WHILE", "REPEAT",
                              "EXIT", "RETURN", "SEMI"})
_VAR_KEYWORDS = frozenset({"VAR", "VAR_INPUT", "VAR_OUTPUT", "VAR_IN_OUT", "VAR_TEMP", "VAR_GLOBAL",
                           "VAR_EXTERNAL", "VAR_CONSTANT", "VAR_RETAIN", "VAR_GLOBAL_CONSTANT",
                           "VAR_GLOBAL_RETAIN", "VAR_OUTPUT_RETAIN", "VAR_PUBLIC", "VAR_PUBLIC_RETAIN"})
_QUALIFIERS = frozenset({"CONSTANT", "RETAIN", "NON_RETAIN", "PERSISTENT"})
_POU_END = {"FUNCTION": "END_FUNCTION", "FUNCTION_BLOCK": "END_FUNCTION_BLOCK", "PROGRAM": "END_PROGRAM"}
#: binary operators: precedence (grammar level, lowest first) and the text the builder
#: stores (`op.value.upper()`, with `&` read as AND)
_PREC = {"OR": 1, "XOR": 2, "AND": 3, "AMP": 3, "EQ": 4, "NE": 4, "LT": 5, "GT": 5, "LE": 5,
         "GE": 5, "PLUS": 6, "MINUS": 6, "STAR": 7, "SLASH": 7, "MOD": 7}
_OP_TEXT = {"OR": "OR", "XOR": "XOR", "AND": "AND", "AMP": "AND", "EQ": "=", "NE": "<>", "LT": "<",
            "GT": ">", "LE": "<=", "GE": ">=", "PLUS": "+", "MINUS": "-", "STAR": "*", "SLASH": "/",
            "MOD": "MOD", "POW": "**"}
_HEX_DIGIT = frozenset("0123456789ABCDEFabcdef")

# how an identifier in an expression reads (`_classify_ident`), by its text
_NAME, _KCONST, _HCONST, _DEVICE = 0, 1, 2, 3
_ident_cache: dict[str, tuple] = {}


def _ident_class(text: str) -> tuple:
    found = _ident_cache.get(text)
    if found is None:
        m = K_CONST_RE.fullmatch(text)
        if m:
            found = (_KCONST, int(m["value"]))
        else:
            m = H_CONST_RE.fullmatch(text)
            if m:
                found = (_HCONST, int(m["value"], 16))
            else:
                fields = parse_device(text)
                found = (_NAME,) if fields is None else (_DEVICE, fields)
        if len(_ident_cache) > 100_000:
            _ident_cache.clear()
        _ident_cache[text] = found
    return found


def _ident_node(text: str, span: ast.Span, cls: tuple) -> ast.Expr:
    """The node of an identifier that is not a plain name (`_classify_ident`)."""
    tag = cls[0]
    if tag == _DEVICE:
        return ast.Device(text=text, span=span, **cls[1])
    if tag == _KCONST:
        return ast.IntLiteral(cls[1], 10, "K", text, span=span)
    if tag == _HCONST:
        return ast.IntLiteral(cls[1], 16, "H", text, span=span)
    return ast.Name(text, span=span)


#: what may follow a name inside a longer operand (member, index, call, power)
_AFTER_NAME = frozenset({"DOT", "LSQB", "LPAR", "POW"})


def _decode(text: str) -> str:
    """The value of a STRING_LIT/WSTRING_LIT token (`_decode_string` without a
    diagnostic: an unknown escape bails)."""
    def unknown(code: str) -> str:
        raise Bail

    return decode_escapes(text[1:-1], unknown)


class Parser:
    """Recursive descent over the token lists, one method per grammar rule."""

    __slots__ = ("K", "V", "LN", "CL", "i", "file")

    def __init__(self, tokens, file: str) -> None:
        self.K, self.V, self.LN, self.CL = tokens
        self.i = 0
        self.file = file

    # ------------------------------------------------------------- helpers
    def expect(self, kind: str) -> int:
        i = self.i
        if self.K[i] != kind:
            raise Bail
        self.i = i + 1
        return i

    def tok_span(self, i: int) -> ast.Span:
        line = self.LN[i]
        col = self.CL[i]
        return make_span(self.file, line, col, line, col + len(self.V[i]))

    def span_tokens(self, a: int, b: int) -> ast.Span:
        """From the start of token a to the end of token b."""
        line = self.LN[b]
        return make_span(self.file, self.LN[a], self.CL[a], line, self.CL[b] + len(self.V[b]))

    def span_node_token(self, node, b: int) -> ast.Span:
        s = node.span
        return make_span(self.file, s.line, s.col, self.LN[b], self.CL[b] + len(self.V[b]))

    def span_token_node(self, a: int, node) -> ast.Span:
        e = node.span
        return make_span(self.file, self.LN[a], self.CL[a], e.end_line, e.end_col)

    # ------------------------------------------------------------- file
    def source_file(self, filename: str, target: str) -> ast.SourceFile:
        K = self.K
        source = ast.SourceFile(filename, target=target)
        while True:
            kind = K[self.i]
            if kind == _END:
                break
            if kind in _POU_END:
                pou, closed = self.pou()
                source.pous.append(pou)
                if not closed:  # allowed for the last item of the file only
                    if K[self.i] != _END:
                        raise Bail
                    break
            elif kind == "TYPE":
                source.types.extend(self.type_decl())
            elif kind in _VAR_KEYWORDS:
                source.globals.append(self.var_block())
            else:
                raise Bail
        return source

    def pou(self) -> tuple[ast.Pou, bool]:
        K, V = self.K, self.V
        start = self.i
        kind_tok = K[start]
        kind = V[start].upper()
        self.i = start + 1
        name_i = self.expect("IDENT")
        return_type = None
        if kind_tok == "FUNCTION":
            self.expect("COLON")
            return_type = self.type_spec()
        blocks = []
        while K[self.i] in _VAR_KEYWORDS:
            blocks.append(self.var_block())
        body = self.stmt_list()
        if K[self.i] == _POU_END[kind_tok]:
            end = self.expect(_POU_END[kind_tok])
            return ast.Pou(kind, V[name_i], return_type, blocks, body,
                           span=self.span_tokens(start, end)), True
        if body:
            span = self.span_token_node(start, body[-1])
        elif blocks:
            span = self.span_token_node(start, blocks[-1])
        else:
            span = self.span_tokens(start, name_i)
        return ast.Pou(kind, V[name_i], return_type, blocks, body, span=span), False

    # ------------------------------------------------------------- types
    def type_decl(self) -> list[ast.StructDecl]:
        self.expect("TYPE")
        structs = [self.struct_decl()]
        while self.K[self.i] == "IDENT":
            structs.append(self.struct_decl())
        self.expect("END_TYPE")
        return structs

    def struct_decl(self) -> ast.StructDecl:
        name_i = self.expect("IDENT")
        self.expect("COLON")
        self.expect("STRUCT")
        fields = []
        while self.K[self.i] == "IDENT":
            fields.extend(self.var_decl("VAR", False, False))
        last = self.expect("END_STRUCT")
        if self.K[self.i] == "SEMI":
            last = self.expect("SEMI")
        return ast.StructDecl(self.V[name_i], fields, span=self.span_tokens(name_i, last))

    # ------------------------------------------------------------- declarations
    def var_block(self) -> ast.VarBlock:
        K, V = self.K, self.V
        start = self.i
        keyword = V[start].upper()
        self.i = start + 1
        qualifiers = []
        while K[self.i] in _QUALIFIERS:
            qualifiers.append(V[self.i].upper())
            self.i += 1
        section, constant, retain = _section(keyword, qualifiers)
        variables = []
        while K[self.i] == "IDENT":
            variables.extend(self.var_decl(section, constant, retain))
        end = self.expect("END_VAR")
        return ast.VarBlock(keyword, qualifiers, variables, span=self.span_tokens(start, end))

    def var_decl(self, section: str, constant: bool, retain: bool) -> list[ast.VarDecl]:
        K, V = self.K, self.V
        names = [self.expect("IDENT")]
        while K[self.i] == "COMMA":
            self.i += 1
            names.append(self.expect("IDENT"))
        at = None
        if K[self.i] == "AT":
            i = self.i + 1
            if K[i] != "IDENT" and K[i] != "BUFFER_DEVICE":
                raise Bail
            fields = parse_device(V[i])
            if fields is None:
                raise Bail  # the lark path reports it
            at = ast.Device(text=V[i], span=self.tok_span(i), **fields)
            self.i = i + 1
        self.expect("COLON")
        type_ref = self.type_spec()
        init = None
        if K[self.i] == "ASSIGN":
            self.i += 1
            init = self.initializer()
        semi = self.expect("SEMI")
        end_line = self.LN[semi]
        end_col = self.CL[semi] + 1
        file, LN, CL = self.file, self.LN, self.CL
        return [ast.VarDecl(V[n], type_ref, init, section, constant, retain, at,
                            span=make_span(file, LN[n], CL[n], end_line, end_col)) for n in names]

    def type_spec(self) -> ast.TypeRef:
        K = self.K
        i = self.i
        kind = K[i]
        if kind == "IDENT":
            self.i = i + 1
            return ast.NamedType(self.V[i], span=self.tok_span(i))
        if kind == "STRING_KW" or kind == "WSTRING_KW":
            self.i = i + 1
            length = None
            last = i
            following = K[self.i]
            if following == "LPAR" or following == "LSQB":
                self.i += 1
                n = self.expect("INT")
                last = self.expect("RPAR" if following == "LPAR" else "RSQB")
                length = int(self.V[n].replace("_", ""))
            return ast.StringType(length, kind == "WSTRING_KW", span=self.span_tokens(i, last))
        if kind == "ARRAY":
            self.i = i + 1
            self.expect("LSQB")
            dims = [self.subrange()]
            while K[self.i] == "COMMA":
                self.i += 1
                dims.append(self.subrange())
            self.expect("RSQB")
            self.expect("OF")
            element = self.type_spec()
            return ast.ArrayType(dims, element, span=self.span_token_node(i, element))
        raise Bail

    def subrange(self) -> ast.Subrange:
        low = self.signed_int()
        self.expect("DOTDOT")
        high = self.signed_int()
        s, e = low.span, high.span
        return ast.Subrange(low.value, high.value, span=make_span(self.file, s.line, s.col, e.end_line, e.end_col))

    def signed_int(self) -> ast.IntLiteral:
        K = self.K
        i = self.i
        minus = K[i] == "MINUS"
        if minus:
            i += 1
        kind = K[i]
        if kind == "INT":
            lit = self.int_lit(i)
        elif kind == "BASED_INT":
            lit = self.based_lit(i)
        else:
            raise Bail
        self.i = i + 1
        if minus:
            lit.value = -lit.value
            lit.text = "-" + lit.text
            lit.span = self.span_tokens(i - 1, i)
        return lit

    def initializer(self):
        K = self.K
        i = self.i
        kind = K[i]
        if kind == "LSQB":
            self.i = i + 1
            items = [self.array_item()]
            while K[self.i] == "COMMA":
                self.i += 1
                items.append(self.array_item())
            end = self.expect("RSQB")
            return ast.ArrayInit(items, span=self.span_tokens(i, end))
        if kind == "LPAR" and K[i + 1] == "IDENT" and K[i + 2] == "ASSIGN":
            self.i = i + 1
            fields = [self.field_init()]
            while K[self.i] == "COMMA":
                self.i += 1
                fields.append(self.field_init())
            end = self.expect("RPAR")
            return ast.StructInit(fields, span=self.span_tokens(i, end))
        return self.expression(1)

    def array_item(self) -> ast.ArrayInitItem:
        K = self.K
        i = self.i
        if K[i] == "INT" and K[i + 1] == "LPAR":
            self.i = i + 2
            value = None
            if K[self.i] != "RPAR":
                value = self.initializer()
            end = self.expect("RPAR")
            return ast.ArrayInitItem(value, int(self.V[i].replace("_", "")), span=self.span_tokens(i, end))
        value = self.initializer()
        return ast.ArrayInitItem(value, None, span=value.span)

    def field_init(self) -> tuple:
        name = self.expect("IDENT")
        self.expect("ASSIGN")
        return (self.V[name], self.initializer())

    # ------------------------------------------------------------- statements
    def stmt_list(self) -> list[ast.Stmt]:
        K = self.K
        out = []
        statement = self.statement
        while K[self.i] in _STATEMENT_START:
            out.append(statement())
        return out

    def statement(self) -> ast.Stmt:
        K = self.K
        i = self.i
        kind = K[i]
        if kind == "IDENT" or kind == "BUFFER_DEVICE":
            target = self.variable()
            following = K[self.i]
            if following == "ASSIGN":
                self.i += 1
                value = self.expression(1)
                semi = self.i
                if K[semi] != "SEMI":
                    raise Bail
                self.i = semi + 1
                s = target.span
                return ast.Assign(target, value, span=make_span(self.file, s.line, s.col, self.LN[semi], self.CL[semi] + 1))
            if following == "LPAR":
                call = self.call(target)
                semi = self.expect("SEMI")
                return ast.CallStmt(call, span=self.span_node_token(call, semi))
            raise Bail
        if kind == "IF":
            return self.if_statement()
        if kind == "CASE":
            return self.case_statement()
        if kind == "FOR":
            return self.for_statement()
        if kind == "WHILE":
            self.i = i + 1
            cond = self.expression(1)
            self.expect("DO")
            body = self.stmt_list()
            self.expect("END_WHILE")
            semi = self.expect("SEMI")
            return ast.While(cond, body, span=self.span_tokens(i, semi))
        if kind == "REPEAT":
            self.i = i + 1
            body = self.stmt_list()
            self.expect("UNTIL")
            until = self.expression(1)
            self.expect("END_REPEAT")
            semi = self.expect("SEMI")
            return ast.Repeat(body, until, span=self.span_tokens(i, semi))
        if kind == "EXIT":
            self.i = i + 1
            semi = self.expect("SEMI")
            return ast.Exit(span=self.span_tokens(i, semi))
        if kind == "RETURN":
            self.i = i + 1
            semi = self.expect("SEMI")
            return ast.Return(span=self.span_tokens(i, semi))
        if kind == "SEMI":
            self.i = i + 1
            return ast.Empty(span=self.tok_span(i))
        raise Bail

    def if_statement(self) -> ast.If:
        K = self.K
        start = self.i
        self.i = start + 1
        cond = self.expression(1)
        then = self.expect("THEN")
        branches = [ast.IfBranch(cond, self.stmt_list(), span=self.span_tokens(start, then))]
        while K[self.i] == "ELSIF":
            head = self.i
            self.i = head + 1
            cond = self.expression(1)
            then = self.expect("THEN")
            branches.append(ast.IfBranch(cond, self.stmt_list(), span=self.span_tokens(head, then)))
        else_body = None
        if K[self.i] == "ELSE":
            self.i += 1
            else_body = self.stmt_list()
        self.expect("END_IF")
        semi = self.expect("SEMI")
        return ast.If(branches, else_body, span=self.span_tokens(start, semi))

    def case_statement(self) -> ast.Case:
        K = self.K
        start = self.i
        self.i = start + 1
        selector = self.expression(1)
        self.expect("OF")
        clauses = [self.case_clause()]
        while K[self.i] in ("INT", "BASED_INT", "MINUS"):
            clauses.append(self.case_clause())
        else_body = None
        if K[self.i] == "ELSE":
            self.i += 1
            else_body = self.stmt_list()
        self.expect("END_CASE")
        semi = self.expect("SEMI")
        return ast.Case(selector, clauses, else_body, span=self.span_tokens(start, semi))

    def case_clause(self) -> ast.CaseClause:
        labels = [self.case_label()]
        while self.K[self.i] == "COMMA":
            self.i += 1
            labels.append(self.case_label())
        colon = self.expect("COLON")
        span = self.span_node_token(labels[0], colon)
        return ast.CaseClause(labels, self.stmt_list(), span=span)

    def case_label(self):
        low = self.signed_int()
        if self.K[self.i] != "DOTDOT":
            return low
        self.i += 1
        high = self.signed_int()
        s, e = low.span, high.span
        return ast.CaseRange(low, high, span=make_span(self.file, s.line, s.col, e.end_line, e.end_col))

    def for_statement(self) -> ast.For:
        start = self.i
        self.i = start + 1
        var = self.variable()
        self.expect("ASSIGN")
        first = self.expression(1)
        self.expect("TO")
        last = self.expression(1)
        step = None
        if self.K[self.i] == "BY":
            self.i += 1
            step = self.expression(1)
        self.expect("DO")
        body = self.stmt_list()
        self.expect("END_FOR")
        semi = self.expect("SEMI")
        return ast.For(var, first, last, step, body, span=self.span_tokens(start, semi))

    # ------------------------------------------------------------- expressions
    def expression(self, min_prec: int):
        """Binary operators by precedence climbing: left-associative at every level, as
        the grammar's left-recursive rules read them. A lone name or integer (the most
        common operands) is read here; anything else by `unary`."""
        K = self.K
        i = self.i
        kind = K[i]
        if kind == "IDENT" and K[i + 1] not in _AFTER_NAME:
            self.i = i + 1
            text = self.V[i]
            line = self.LN[i]
            col = self.CL[i]
            span = make_span(self.file, line, col, line, col + len(text))
            cls = _ident_cache.get(text) or _ident_class(text)
            left = ast.Name(text, span=span) if cls[0] == _NAME else _ident_node(text, span, cls)
        elif kind == "INT" and K[i + 1] != "POW":
            self.i = i + 1
            text = self.V[i]
            line = self.LN[i]
            col = self.CL[i]
            left = ast.IntLiteral(int(text.replace("_", "")), 10, "", text,
                                  span=make_span(self.file, line, col, line, col + len(text)))
        else:
            left = self.unary()
        while True:
            kind = K[self.i]
            prec = _PREC.get(kind)
            if prec is None or prec < min_prec:
                return left
            self.i += 1
            right = self.expression(prec + 1)
            s, e = left.span, right.span
            left = ast.BinaryOp(_OP_TEXT[kind], left, right,
                                span=make_span(self.file, s.line, s.col, e.end_line, e.end_col))

    def unary(self):
        i = self.i
        kind = self.K[i]
        if kind == "MINUS" or kind == "NOT":
            self.i = i + 1
            operand = self.unary()
            e = operand.span
            return ast.UnaryOp("-" if kind == "MINUS" else "NOT", operand,
                               span=make_span(self.file, self.LN[i], self.CL[i], e.end_line, e.end_col))
        if kind == "PLUS":
            self.i = i + 1
            return self.unary()
        left = self.primary()
        while self.K[self.i] == "POW":
            self.i += 1
            right = self.primary()
            s, e = left.span, right.span
            left = ast.BinaryOp("**", left, right, span=make_span(self.file, s.line, s.col, e.end_line, e.end_col))
        return left

    def primary(self):
        K = self.K
        i = self.i
        kind = K[i]
        if kind == "IDENT" or kind == "BUFFER_DEVICE":
            var = self.variable()
            if K[self.i] == "LPAR":
                return self.call(var)
            return var
        if kind == "LPAR":
            self.i = i + 1
            inner = self.expression(1)
            self.expect("RPAR")
            return inner
        self.i = i + 1
        V = self.V
        if kind == "INT":
            return self.int_lit(i)
        if kind == "TRUE" or kind == "FALSE":
            return ast.BoolLiteral(kind == "TRUE", span=self.tok_span(i))
        if kind == "REAL":
            return ast.RealLiteral(float(V[i].replace("_", "")), V[i], span=self.tok_span(i))
        if kind == "BASED_INT":
            return self.based_lit(i)
        if kind == "TIME_LIT":
            return ast.TimeLiteral(time_literal_ms(V[i]), V[i], span=self.tok_span(i))
        if kind == "STRING_LIT" or kind == "WSTRING_LIT":
            return ast.StringLiteral(_decode(V[i]), kind == "WSTRING_LIT", span=self.tok_span(i))
        raise Bail

    def int_lit(self, i: int) -> ast.IntLiteral:
        text = self.V[i]
        return ast.IntLiteral(int(text.replace("_", "")), 10, "", text, span=self.tok_span(i))

    def based_lit(self, i: int) -> ast.IntLiteral:
        text = self.V[i]
        radix, digits = text.split("#", 1)
        radix = int(radix)
        try:
            value = int(digits.replace("_", ""), radix)
        except ValueError:
            raise Bail from None  # the lark path reports it
        return ast.IntLiteral(value, radix, "", text, span=self.tok_span(i))

    def call(self, callee) -> ast.Call:
        """`callee ( arg_list? )`; the current token is the '('."""
        K, V = self.K, self.V
        self.i += 1
        args = []
        if K[self.i] != "RPAR":
            while True:
                i = self.i
                if K[i] == "IDENT" and K[i + 1] == "ASSIGN":
                    self.i = i + 2
                    value = self.expression(1)
                    args.append(ast.Arg(value, V[i], span=self.span_token_node(i, value)))
                elif K[i] == "IDENT" and K[i + 1] == "ASSIGN_OUT":
                    self.i = i + 2
                    value = self.variable()
                    args.append(ast.Arg(value, V[i], True, span=self.span_token_node(i, value)))
                else:
                    value = self.expression(1)
                    args.append(ast.Arg(value, span=value.span))
                if K[self.i] != "COMMA":
                    break
                self.i += 1
        end = self.expect("RPAR")
        return ast.Call(callee, args, span=self.span_node_token(callee, end))

    def variable(self):
        K, V = self.K, self.V
        i = self.i
        kind = K[i]
        text = V[i]
        if kind == "IDENT":
            span = self.tok_span(i)
            cls = _ident_cache.get(text) or _ident_class(text)
            node = ast.Name(text, span=span) if cls[0] == _NAME else _ident_node(text, span, cls)
        elif kind == "BUFFER_DEVICE":
            node = ast.Device(text=text, span=self.tok_span(i), **parse_device(text))
        else:
            raise Bail
        i += 1
        while True:
            kind = K[i]
            if kind == "DOT":
                i += 1
                kind = K[i]
                self.i = i + 1
                if kind == "IDENT":
                    if type(node) is ast.Device and len(V[i]) == 1 and V[i] in _HEX_DIGIT:
                        node = self._device_bit(node, i)
                    else:
                        node = ast.Member(node, V[i], span=self.span_node_token(node, i))
                elif kind == "INT":
                    if type(node) is ast.Device:
                        node = self._device_bit(node, i)
                    else:
                        node = ast.BitAccess(node, int(V[i].replace("_", "")), span=self.span_node_token(node, i))
                else:
                    raise Bail
                i += 1
            elif kind == "LSQB":
                self.i = i + 1
                indices = [self.expression(1)]
                while K[self.i] == "COMMA":
                    self.i += 1
                    indices.append(self.expression(1))
                end = self.expect("RSQB")
                node = ast.Index(node, indices, span=self.span_node_token(node, end))
                i = self.i
            else:
                self.i = i
                return node

    def _device_bit(self, base: ast.Device, i: int) -> ast.Device:
        text = self.V[i]
        try:
            bit = int(text, 16)
        except ValueError:
            bit = 16
        if bit > 15 or base.bit is not None or base.digits is not None or base.is_bit:
            raise Bail  # the lark path reports it
        base.bit = bit
        base.text = f"{base.text}.{text}"
        base.span = self.span_node_token(base, i)
        return base


#: sha256 of the st.lark this module follows rule by rule. Another grammar turns the fast
#: path off (everything is read by lark) until this module is brought in line with it
#: and the digest updated (tests/test_st_fastpath.py says so).
GRAMMAR_SHA256 = "188ee0a0583cfcc2b268a6996c24c4cf218ea19e8043ea663a974910e6875dd0"

_tokenizer: Tokenizer | None = None
_unavailable: str | None = None  # why the fast path is off, once known


def grammar_digest(lark_parser) -> str:
    return hashlib.sha256(lark_parser.source_grammar.encode("utf-8")).hexdigest()


def unavailable(lark_parser) -> str | None:
    """Why the fast path is off (None when it is on): another grammar, or a lark whose
    lexer is not built as this module expects."""
    tokenizer(lark_parser)
    return _unavailable


def tokenizer(lark_parser) -> Tokenizer | None:
    global _tokenizer, _unavailable
    if _tokenizer is None and _unavailable is None:
        if grammar_digest(lark_parser) != GRAMMAR_SHA256:
            _unavailable = "st.lark is not the grammar verifier/st/fastparse.py follows"
        else:
            try:
                _tokenizer = Tokenizer(lark_parser)
            except Exception as exc:  # a lark of another make: lark reads everything
                _unavailable = f"cannot build the tokenizer from lark's lexer: {exc!r}"
    return _tokenizer


def parse_fast(text: str, filename: str, target: str, lark_parser) -> ast.SourceFile:
    """The file as `verifier.st.parser.parse_reference` reads it, for text that reads with
    no diagnostic; raises Bail (or RecursionError) for anything else. A lone carriage
    return ends a line, as parse_reference reads it (the fast path given one counted a
    line fewer after it: a test's random mutation found spans one line off)."""
    text = lone_cr_as_line_feed(text)
    # The tree has no reference cycles: the cyclic garbage collector has nothing to find
    # while it is built, yet would walk the young nodes again and again (a tenth of the
    # time); it runs as usual once the file is read.
    collecting = gc.isenabled()
    gc.disable()
    try:
        tok = _tokenizer or tokenizer(lark_parser)
        if tok is None:
            raise Bail
        tokens = tok.tokenize(text, target == "gxworks2")
        source = Parser(tokens, filename).source_file(filename, target)
    finally:
        if collecting:
            gc.enable()
    source.text = text
    return source
