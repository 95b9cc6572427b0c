"""Typed syntax tree of GX Works structured text.

Every node is a dataclass. `span` (where the node sits in its file) and the fields the
semantic check fills in (`type`, `symbol`, `resolved`) are excluded from equality, so two
trees of the same program compare equal wherever they were parsed from: that is what the
printer round-trip relies on.

Names keep the spelling the author wrote; GX Works compares them case-insensitively, so
use `.key` (upper case) to look them up.

Stability: this module is a contract with the simulator (verifier/sim compiles it to
Python). Only additive changes: new nodes, new optional fields at the end.
"""
from __future__ import annotations

from dataclasses import dataclass, field, fields, is_dataclass
from typing import Iterator

from verifier.place import Place


# ----------------------------------------------------------------------------- places
@dataclass(frozen=True, slots=True)
class Span:
    """Where a node sits: 1-based line and column of its first and last character
    (end_col is one past the last character, as lark counts). Its start is a
    verifier.place.Place (`place`); the end is kept beside it, not in a Place, for the
    caret under a source line and SARIF's region: spans are made for every token the
    parser reads (fastparse makes them without calling the constructor), so they stay
    five flat fields."""

    file: str
    line: int
    col: int
    end_line: int
    end_col: int

    @property
    def place(self) -> Place:
        """Where the node starts, as every message places it."""
        return Place(self.file, self.line, self.col)

    def __str__(self) -> str:
        return str(self.place)


NO_SPAN = Span("<none>", 0, 0, 0, 0)


def syntax_fields(node) -> list:
    """The values of a node's syntax fields (nodes, lists of nodes, plain values): those
    that take part in comparison, so not its span nor what the check filled in. Walkers
    of the tree (the simulator's purity and reach analyses) descend through these."""
    names = _SYNTAX_FIELD_NAMES.get(type(node))
    if names is None:
        names = _SYNTAX_FIELD_NAMES[type(node)] = tuple(f.name for f in fields(node) if f.compare)
    return [getattr(node, name) for name in names]


_SYNTAX_FIELD_NAMES: dict[type, tuple[str, ...]] = {}  # by node class: fields() builds its tuple on every call


def walk(*roots) -> Iterator:
    """Every node under `roots` (nodes, lists or tuples of them), the roots' own included,
    through their syntax fields; in no particular order."""
    stack = list(roots)
    shape_of = _WALK_SHAPE
    while stack:
        node = stack.pop()
        shape = shape_of.get(type(node))
        if shape is None:
            shape = _walk_shape(node)
        if shape is _LEAF:
            continue
        if shape is _SEQUENCE:
            stack.extend(node)
            continue
        yield node
        stack.extend([getattr(node, name) for name in shape])


_LEAF, _SEQUENCE = object(), object()
#: by class, what walk does with a value: skip it (_LEAF), descend into its items
#: (_SEQUENCE), or yield it and descend into the syntax fields named (a node); the class
#: tests once per class, not once per value (a tenth of `uitamr check`'s time was
#: is_dataclass on every string and number of the tree)
_WALK_SHAPE: dict[type, object] = {}


def _walk_shape(value) -> object:
    cls = type(value)
    if isinstance(value, (list, tuple)):
        shape = _SEQUENCE
    elif is_dataclass(value) and not isinstance(value, type):
        shape = _SYNTAX_FIELD_NAMES.get(cls) or tuple(f.name for f in fields(value) if f.compare)
        _SYNTAX_FIELD_NAMES[cls] = shape
    else:
        shape = _LEAF
    _WALK_SHAPE[cls] = shape
    return shape


@dataclass(slots=True)
class Diagnostic:
    """One finding about the source: `severity` is "error" or "warning"."""

    file: str
    line: int
    col: int
    severity: str
    message: str
    end_line: int | None = None
    end_col: int | None = None

    @classmethod
    def of_span(cls, span: Span, severity: str, message: str) -> "Diagnostic":
        """A finding about the node at `span`, its end included."""
        return cls(span.file, span.line, span.col, severity, message, span.end_line, span.end_col)

    @property
    def place(self) -> Place:
        """Where the finding is (its start; `end_line`/`end_col` are SARIF's and the caret's)."""
        return Place(self.file, self.line, self.col)

    def __str__(self) -> str:
        return f"{self.place}: {self.severity}: {self.message}"

    @property
    def is_error(self) -> bool:
        return self.severity == "error"


class Node:
    """Base of every syntax node (gives `span`)."""

    __slots__ = ()


# ----------------------------------------------------------------------------- types
@dataclass(slots=True)
class TypeRef(Node):
    """A type as written in a declaration (base class)."""

    span: Span = field(default=NO_SPAN, compare=False, repr=False, kw_only=True)


@dataclass(slots=True)
class NamedType(TypeRef):
    """An elementary type (BOOL, INT, WORD, TIME ...), a structure or a FB type, by name."""

    name: str

    @property
    def key(self) -> str:
        return self.name.upper()


@dataclass(slots=True)
class StringType(TypeRef):
    """STRING / WSTRING with an optional length: `STRING(32)` or `STRING[32]`."""

    length: int | None = None
    wide: bool = False


@dataclass(slots=True)
class Subrange(Node):
    """Array bounds `low..high` (inclusive)."""

    low: int
    high: int
    span: Span = field(default=NO_SPAN, compare=False, repr=False, kw_only=True)


@dataclass(slots=True)
class ArrayType(TypeRef):
    """`ARRAY [a..b, c..d] OF element`."""

    dims: list[Subrange]
    element: TypeRef


# ----------------------------------------------------------------------------- expressions
@dataclass(slots=True)
class Expr(Node):
    """Base of expressions. `type` is filled by the semantic check with the resolved
    `verifier.st.types.Type` of the value (None until checked)."""

    span: Span = field(default=NO_SPAN, compare=False, repr=False, kw_only=True)
    type: object = field(default=None, compare=False, repr=False, kw_only=True)


@dataclass(slots=True)
class IntLiteral(Expr):
    """Integer constant: `42`, `-1` is UnaryOp, `16#01A0`, `2#1010_0000`, `8#17`,
    MELSEC `K100` (radix 10, prefix "K") or `H1F` (radix 16, prefix "H").
    `value` is the mathematical value."""

    value: int
    radix: int = 10
    prefix: str = ""  # "", "K" or "H"
    text: str = field(default="", compare=False)


@dataclass(slots=True)
class RealLiteral(Expr):
    """REAL constant: `1.5`, `2.0E-3`."""

    value: float
    text: str = field(default="", compare=False)


@dataclass(slots=True)
class BoolLiteral(Expr):
    """TRUE / FALSE."""

    value: bool


@dataclass(slots=True)
class TimeLiteral(Expr):
    """`T#1s500ms`, `TIME#2h`, `T#-5ms`: `ms` is the duration in milliseconds (GX Works
    TIME is a signed 32-bit count of ms)."""

    ms: int
    text: str = field(default="", compare=False)


@dataclass(slots=True)
class StringLiteral(Expr):
    """'text' (STRING) or "text" (WSTRING); `value` has the `$` escapes decoded."""

    value: str
    wide: bool = False


@dataclass(slots=True)
class Name(Expr):
    """A label (variable) reference. `symbol` is set by the check to the declaring
    `VarDecl` (or a POU/FB type for calls)."""

    name: str
    symbol: object = field(default=None, compare=False, repr=False, kw_only=True)

    @property
    def key(self) -> str:
        return self.name.upper()


@dataclass(slots=True)
class Device(Expr):
    """A MELSEC device written directly: `D100`, `M0`, `X1F`, `SM400`, `D0.F` (bit 15
    of D0), `K4M0` (16 bits M0..M15), `D0Z1` (index-modified), `U0\\G100` (buffer
    memory of the module at start I/O 0).

    kind: device letters upper case ("D", "M", "X", "SM", "G" for buffer memory ...).
    address: the number as written, upper case (X/Y are hexadecimal on Q/L/iQ-R and
    octal on FX: keep the text, `key` identifies the device).
    number: `address` read in the radix the device uses on Q/L CPUs (X, Y, B, W, SB, SW
    hexadecimal; the rest decimal).
    """

    kind: str
    address: str
    number: int
    bit: int | None = None        # D0.F -> 15
    digits: int | None = None     # K4M0 -> 4 (nibbles)
    index: int | None = None      # D0Z1 -> 1
    module: str | None = None     # U0\G100 -> "0"
    text: str = field(default="", compare=False)

    @property
    def key(self) -> str:
        """Canonical device name without bit/digit/index decorations: "D100", "X1F",
        "U0\\G100"."""
        if self.module is not None:
            return f"U{self.module}\\{self.kind}{self.address}"
        return f"{self.kind}{self.address}"

    @property
    def is_bit(self) -> bool:
        """True when the reference denotes one bit (M0, X1, D0.F), False for a word or
        a digit-specified group."""
        from verifier.st.devices import is_bit_device  # local: avoid import cycle

        if self.digits is not None:
            return False
        return self.bit is not None or is_bit_device(self.kind)


@dataclass(slots=True)
class Index(Expr):
    """Array element: `base[i]` or `base[i, j]`."""

    base: Expr
    indices: list[Expr]


@dataclass(slots=True)
class Member(Expr):
    """Structure member or FB instance variable: `tmr.Q`, `stData.wCode`."""

    base: Expr
    member: str

    @property
    def key(self) -> str:
        return self.member.upper()


@dataclass(slots=True)
class BitAccess(Expr):
    """Bit of a word label: `wData.3` (bit 3)."""

    base: Expr
    bit: int


@dataclass(slots=True)
class UnaryOp(Expr):
    """`NOT x`, `-x` (op is "NOT" or "-")."""

    op: str
    operand: Expr


@dataclass(slots=True)
class BinaryOp(Expr):
    """`left op right`; op is one of "**", "*", "/", "MOD", "+", "-", "<", ">", "<=",
    ">=", "=", "<>", "AND", "XOR", "OR" (`&` is read as "AND")."""

    op: str
    left: Expr
    right: Expr


@dataclass(slots=True)
class Arg(Node):
    """One call argument: positional (`name` None), input `name := value`, or output
    binding `name => value` (`output` True; value is the receiving variable)."""

    value: Expr
    name: str | None = None
    output: bool = False
    span: Span = field(default=NO_SPAN, compare=False, repr=False, kw_only=True)

    @property
    def key(self) -> str | None:
        return self.name.upper() if self.name is not None else None


@dataclass(slots=True)
class Call(Expr):
    """A call: user FUNCTION, standard function (ADD, INT_TO_WORD ...), MELSEC
    instruction (`RS2(EN, ...)`), or FB instance (`tmr(IN := b, PT := T#1s)`).
    The check sets `resolved` to a `verifier.st.types.CallTarget` saying which."""

    callee: Expr
    args: list[Arg]
    resolved: object = field(default=None, compare=False, repr=False, kw_only=True)

    @property
    def name(self) -> str:
        """The called name as written ("" for calls through array elements)."""
        return self.callee.name if isinstance(self.callee, Name) else ""

    @property
    def key(self) -> str:
        return self.name.upper()


# ----------------------------------------------------------------------------- initial values
@dataclass(slots=True)
class ArrayInit(Node):
    """`[1, 2, 3(0)]`: items with an optional repeat count (`3(0)` = three zeros)."""

    items: list[ArrayInitItem]
    span: Span = field(default=NO_SPAN, compare=False, repr=False, kw_only=True)


@dataclass(slots=True)
class ArrayInitItem(Node):
    """One item of an array initialiser; `repeat` None means once."""

    value: Expr | ArrayInit | StructInit
    repeat: int | None = None
    span: Span = field(default=NO_SPAN, compare=False, repr=False, kw_only=True)


@dataclass(slots=True)
class StructInit(Node):
    """`(wCode := 1, bOn := TRUE)`."""

    fields: list[tuple[str, Expr | ArrayInit | StructInit]]
    span: Span = field(default=NO_SPAN, compare=False, repr=False, kw_only=True)


Initializer = Expr | ArrayInit | StructInit


# ----------------------------------------------------------------------------- statements
@dataclass(slots=True)
class Stmt(Node):
    """Base of statements."""

    span: Span = field(default=NO_SPAN, compare=False, repr=False, kw_only=True)


@dataclass(slots=True)
class Assign(Stmt):
    """`target := value;`"""

    target: Expr
    value: Expr


@dataclass(slots=True)
class CallStmt(Stmt):
    """A call used as a statement: FB invocation or instruction/function call."""

    call: Call


@dataclass(slots=True)
class IfBranch(Node):
    """`IF cond THEN body` or `ELSIF cond THEN body`."""

    cond: Expr
    body: list[Stmt]
    span: Span = field(default=NO_SPAN, compare=False, repr=False, kw_only=True)


@dataclass(slots=True)
class If(Stmt):
    """IF / ELSIF ... / ELSE / END_IF; `else_body` None when there is no ELSE."""

    branches: list[IfBranch]
    else_body: list[Stmt] | None = None


@dataclass(slots=True)
class CaseRange(Node):
    """`low..high` in a CASE label list."""

    low: Expr
    high: Expr
    span: Span = field(default=NO_SPAN, compare=False, repr=False, kw_only=True)


@dataclass(slots=True)
class CaseClause(Node):
    """`1, 3..5: body` — labels are integer expressions or CaseRange."""

    labels: list[Expr | CaseRange]
    body: list[Stmt]
    span: Span = field(default=NO_SPAN, compare=False, repr=False, kw_only=True)


@dataclass(slots=True)
class Case(Stmt):
    """CASE selector OF clauses [ELSE else_body] END_CASE."""

    selector: Expr
    clauses: list[CaseClause]
    else_body: list[Stmt] | None = None


@dataclass(slots=True)
class For(Stmt):
    """FOR var := start TO end [BY step] DO body END_FOR; `step` None means 1."""

    var: Expr
    start: Expr
    end: Expr
    step: Expr | None
    body: list[Stmt]


@dataclass(slots=True)
class While(Stmt):
    """WHILE cond DO body END_WHILE."""

    cond: Expr
    body: list[Stmt]


@dataclass(slots=True)
class Repeat(Stmt):
    """REPEAT body UNTIL cond END_REPEAT."""

    body: list[Stmt]
    until: Expr


@dataclass(slots=True)
class Exit(Stmt):
    """EXIT: leave the innermost loop."""


@dataclass(slots=True)
class Return(Stmt):
    """RETURN: leave the POU."""


@dataclass(slots=True)
class Empty(Stmt):
    """A lone `;`."""


# ----------------------------------------------------------------------------- declarations
@dataclass(slots=True)
class VarDecl(Node):
    """One declared label. `section` is the block it was declared in ("VAR",
    "VAR_INPUT", "VAR_OUTPUT", "VAR_IN_OUT", "VAR_TEMP", "VAR_GLOBAL", "VAR_EXTERNAL",
    "VAR_PUBLIC" ...), normalised so that `VAR_CONSTANT` / `VAR CONSTANT` give
    section "VAR" with `constant` True, `VAR_RETAIN` / `VAR RETAIN` give `retain` True.
    `at` is the device a global label is assigned to (`bX AT X0 : BOOL`), if any."""

    name: str
    type: TypeRef
    init: Initializer | None = None
    section: str = "VAR"
    constant: bool = False
    retain: bool = False
    at: Device | None = None
    span: Span = field(default=NO_SPAN, compare=False, repr=False, kw_only=True)

    @property
    def key(self) -> str:
        return self.name.upper()


@dataclass(slots=True)
class VarBlock(Node):
    """A VAR... END_VAR block as written (keyword and qualifiers kept for printing)."""

    keyword: str          # as normalised upper case: "VAR", "VAR_INPUT", "VAR_CONSTANT" ...
    qualifiers: list[str]  # "CONSTANT", "RETAIN" written after the keyword
    variables: list[VarDecl]
    span: Span = field(default=NO_SPAN, compare=False, repr=False, kw_only=True)


@dataclass(slots=True)
class StructDecl(Node):
    """`TYPE name : STRUCT fields END_STRUCT END_TYPE` (a GX Works structure)."""

    name: str
    fields: list[VarDecl]
    span: Span = field(default=NO_SPAN, compare=False, repr=False, kw_only=True)

    @property
    def key(self) -> str:
        return self.name.upper()


@dataclass(slots=True)
class Pou(Node):
    """A program organisation unit: kind "FUNCTION", "FUNCTION_BLOCK" or "PROGRAM".
    `return_type` only for FUNCTION (its result is assigned to the function's name)."""

    kind: str
    name: str
    return_type: TypeRef | None
    var_blocks: list[VarBlock]
    body: list[Stmt]
    span: Span = field(default=NO_SPAN, compare=False, repr=False, kw_only=True)

    @property
    def key(self) -> str:
        return self.name.upper()

    @property
    def variables(self) -> list[VarDecl]:
        return [v for block in self.var_blocks for v in block.variables]


@dataclass(slots=True)
class SourceFile(Node):
    """One parsed .st file: its POUs, structure types and global label blocks, plus the
    diagnostics found while reading it (syntax errors leave `pous` partial or empty)."""

    filename: str
    pous: list[Pou] = field(default_factory=list)
    types: list[StructDecl] = field(default_factory=list)
    globals: list[VarBlock] = field(default_factory=list)
    diagnostics: list[Diagnostic] = field(default_factory=list, compare=False)
    target: str = field(default="gxworks2", compare=False)
    text: str = field(default="", compare=False, repr=False)

    @property
    def ok(self) -> bool:
        """True when reading the file produced no error."""
        return not any(d.is_error for d in self.diagnostics)
