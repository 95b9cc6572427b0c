"""Print an `ast` tree back as readable GX Works structured text.

Keywords upper case, names as the author wrote them, four-space indentation,
parentheses only where IEC precedence needs them. Parsing the output gives a tree equal
to the input tree (tests/test_st_printer.py checks that).
"""
from __future__ import annotations

from verifier.st import ast

INDENT = "    "

#: binding strength of binary operators (higher binds tighter), IEC 61131-3 table 55
PRECEDENCE = {
    "OR": 1, "XOR": 2, "AND": 3, "=": 4, "<>": 4, "<": 5, ">": 5, "<=": 5, ">=": 5,
    "+": 6, "-": 6, "*": 7, "/": 7, "MOD": 7, "**": 9,
}
UNARY_PRECEDENCE = 8
ATOM = 10

_STRING_ESCAPES = {"$": "$$", "\n": "$N", "\r": "$R", "\t": "$T", "\f": "$P"}


def _string(value: str, wide: bool) -> str:
    quote = '"' if wide else "'"
    out = []
    for ch in value:
        if ch in _STRING_ESCAPES:
            out.append(_STRING_ESCAPES[ch])
        elif ch == quote:
            out.append("$" + ch)
        elif ord(ch) < 0x20 or ord(ch) == 0x7F:
            out.append(f"${ord(ch):02X}")
        else:
            out.append(ch)
    return quote + "".join(out) + quote


def _int(lit: ast.IntLiteral) -> str:
    if lit.text:
        return lit.text
    if lit.prefix == "K":
        return f"K{lit.value}"
    if lit.prefix == "H":
        return f"H{lit.value:X}"
    if lit.radix == 16:
        return f"16#{lit.value:X}"
    if lit.radix == 2:
        return f"2#{lit.value:b}"
    if lit.radix == 8:
        return f"8#{lit.value:o}"
    return str(lit.value)


def _time(lit: ast.TimeLiteral) -> str:
    if lit.text:
        return lit.text
    ms = abs(lit.ms)
    return f"T#{'-' if lit.ms < 0 else ''}{ms}ms"


def _device(dev: ast.Device) -> str:
    if dev.text:
        return dev.text
    text = dev.key if dev.digits is None else f"K{dev.digits}{dev.key}"
    if dev.index is not None:
        text += f"Z{dev.index}"
    if dev.bit is not None:
        text += f".{dev.bit:X}"
    return text


def _precedence(expr: ast.Expr) -> int:
    if isinstance(expr, ast.BinaryOp):
        return PRECEDENCE[expr.op]
    if isinstance(expr, ast.UnaryOp):
        return UNARY_PRECEDENCE
    if isinstance(expr, ast.IntLiteral) and expr.value < 0:
        return UNARY_PRECEDENCE
    if isinstance(expr, ast.RealLiteral) and expr.value < 0:
        return UNARY_PRECEDENCE
    return ATOM


def expr_text(expr) -> str:
    """ST text of an expression (or initialiser)."""
    if isinstance(expr, ast.BinaryOp):
        prec = PRECEDENCE[expr.op]
        left = expr_text(expr.left)
        right = expr_text(expr.right)
        if _precedence(expr.left) < prec:
            left = f"({left})"
        # left-associative: an equal-precedence right operand needs parentheses
        if _precedence(expr.right) <= prec or expr.op == "**" and _precedence(expr.right) < ATOM:
            right = f"({right})"
        return f"{left} {expr.op} {right}"
    if isinstance(expr, ast.UnaryOp):
        operand = expr_text(expr.operand)
        if _precedence(expr.operand) < UNARY_PRECEDENCE:
            operand = f"({operand})"
        if expr.op == "NOT":
            return f"NOT {operand}"
        if operand.startswith("-"):
            return f"-({operand})"
        return f"-{operand}"
    if isinstance(expr, ast.Name):
        return expr.name
    if isinstance(expr, ast.Device):
        return _device(expr)
    if isinstance(expr, ast.IntLiteral):
        return _int(expr)
    if isinstance(expr, ast.RealLiteral):
        return expr.text or repr(expr.value)
    if isinstance(expr, ast.BoolLiteral):
        return "TRUE" if expr.value else "FALSE"
    if isinstance(expr, ast.TimeLiteral):
        return _time(expr)
    if isinstance(expr, ast.StringLiteral):
        return _string(expr.value, expr.wide)
    if isinstance(expr, ast.Index):
        return f"{expr_text(expr.base)}[{', '.join(expr_text(i) for i in expr.indices)}]"
    if isinstance(expr, ast.Member):
        return f"{expr_text(expr.base)}.{expr.member}"
    if isinstance(expr, ast.BitAccess):
        return f"{expr_text(expr.base)}.{expr.bit}"
    if isinstance(expr, ast.Call):
        return f"{expr_text(expr.callee)}({', '.join(_arg(a) for a in expr.args)})"
    if isinstance(expr, ast.ArrayInit):
        return "[" + ", ".join(_array_item(i) for i in expr.items) + "]"
    if isinstance(expr, ast.StructInit):
        return "(" + ", ".join(f"{name} := {expr_text(v)}" for name, v in expr.fields) + ")"
    raise TypeError(f"cannot print {type(expr).__name__}")


def _array_item(item: ast.ArrayInitItem) -> str:
    if item.repeat is None:
        return expr_text(item.value)
    inner = expr_text(item.value) if item.value is not None else ""
    return f"{item.repeat}({inner})"


def _arg(arg: ast.Arg) -> str:
    if arg.name is None:
        return expr_text(arg.value)
    return f"{arg.name} {'=>' if arg.output else ':='} {expr_text(arg.value)}"


def type_text(t: ast.TypeRef) -> str:
    if isinstance(t, ast.NamedType):
        return t.name
    if isinstance(t, ast.StringType):
        word = "WSTRING" if t.wide else "STRING"
        return word if t.length is None else f"{word}({t.length})"
    if isinstance(t, ast.ArrayType):
        dims = ", ".join(f"{d.low}..{d.high}" for d in t.dims)
        return f"ARRAY[{dims}] OF {type_text(t.element)}"
    raise TypeError(f"cannot print {type(t).__name__}")


class _Writer:
    def __init__(self) -> None:
        self.lines: list[str] = []
        self.depth = 0

    def line(self, text: str) -> None:
        self.lines.append(INDENT * self.depth + text)

    def body(self, stmts: list[ast.Stmt]) -> None:
        self.depth += 1
        for s in stmts:
            self.stmt(s)
        self.depth -= 1

    def stmt(self, s: ast.Stmt) -> None:
        if isinstance(s, ast.Assign):
            self.line(f"{expr_text(s.target)} := {expr_text(s.value)};")
        elif isinstance(s, ast.CallStmt):
            self.line(expr_text(s.call) + ";")
        elif isinstance(s, ast.If):
            for i, branch in enumerate(s.branches):
                self.line(f"{'IF' if i == 0 else 'ELSIF'} {expr_text(branch.cond)} THEN")
                self.body(branch.body)
            if s.else_body is not None:
                self.line("ELSE")
                self.body(s.else_body)
            self.line("END_IF;")
        elif isinstance(s, ast.Case):
            self.line(f"CASE {expr_text(s.selector)} OF")
            self.depth += 1
            for clause in s.clauses:
                labels = ", ".join(
                    f"{expr_text(l.low)}..{expr_text(l.high)}" if isinstance(l, ast.CaseRange) else expr_text(l)
                    for l in clause.labels
                )
                self.line(f"{labels}:")
                self.body(clause.body)
            self.depth -= 1
            if s.else_body is not None:
                self.line("ELSE")
                self.body(s.else_body)
            self.line("END_CASE;")
        elif isinstance(s, ast.For):
            by = f" BY {expr_text(s.step)}" if s.step is not None else ""
            self.line(f"FOR {expr_text(s.var)} := {expr_text(s.start)} TO {expr_text(s.end)}{by} DO")
            self.body(s.body)
            self.line("END_FOR;")
        elif isinstance(s, ast.While):
            self.line(f"WHILE {expr_text(s.cond)} DO")
            self.body(s.body)
            self.line("END_WHILE;")
        elif isinstance(s, ast.Repeat):
            self.line("REPEAT")
            self.body(s.body)
            self.line(f"UNTIL {expr_text(s.until)}")
            self.line("END_REPEAT;")
        elif isinstance(s, ast.Exit):
            self.line("EXIT;")
        elif isinstance(s, ast.Return):
            self.line("RETURN;")
        elif isinstance(s, ast.Empty):
            self.line(";")
        else:
            raise TypeError(f"cannot print {type(s).__name__}")

    def var_decl(self, v: ast.VarDecl) -> None:
        at = f" AT {_device(v.at)}" if v.at is not None else ""
        init = f" := {expr_text(v.init)}" if v.init is not None else ""
        self.line(f"{v.name}{at} : {type_text(v.type)}{init};")

    def var_block(self, b: ast.VarBlock) -> None:
        self.line(" ".join([b.keyword, *b.qualifiers]))
        self.depth += 1
        for v in b.variables:
            self.var_decl(v)
        self.depth -= 1
        self.line("END_VAR")

    def struct(self, s: ast.StructDecl) -> None:
        self.line("TYPE")
        self.depth += 1
        self.line(f"{s.name} :")
        self.line("STRUCT")
        self.depth += 1
        for v in s.fields:
            self.var_decl(v)
        self.depth -= 1
        self.line("END_STRUCT;")
        self.depth -= 1
        self.line("END_TYPE")

    def pou(self, p: ast.Pou) -> None:
        header = f"{p.kind} {p.name}"
        if p.return_type is not None:
            header += f" : {type_text(p.return_type)}"
        self.line(header)
        for b in p.var_blocks:
            self.var_block(b)
        self.depth += 1
        for s in p.body:
            self.stmt(s)
        self.depth -= 1
        self.line(f"END_{p.kind}")


def print_source(source: ast.SourceFile) -> str:
    """The whole file as ST text: structures, global label blocks, then POUs."""
    w = _Writer()
    for s in source.types:
        w.struct(s)
        w.lines.append("")
    for b in source.globals:
        w.var_block(b)
        w.lines.append("")
    for p in source.pous:
        w.pou(p)
        w.lines.append("")
    return "\n".join(w.lines)


def print_stmt(stmt: ast.Stmt) -> str:
    """One statement as ST text (with nested blocks indented)."""
    w = _Writer()
    w.stmt(stmt)
    return "\n".join(w.lines)
