"""Compile-time view of ST types and declared labels (what the code generator needs to
know about each name: where it lives in Python and how its values are normalised)."""
from __future__ import annotations

import math
from dataclasses import dataclass, field

from verifier.st import ast

from . import datatypes


class CompileError(Exception):
    """A construct the simulator cannot run, reported at its ST location."""

    def __init__(self, span, message: str):
        self.span = span
        self.message = message
        super().__init__(f"{span}: {message}" if span else message)


@dataclass(frozen=True)
class ArrayT:
    dims: tuple[tuple[int, int], ...]
    elem: object  # str | ArrayT | StructT | FbT

    @property
    def size(self) -> int:
        return math.prod(hi - lo + 1 for lo, hi in self.dims)

    def __str__(self) -> str:
        ds = ", ".join(f"{lo}..{hi}" for lo, hi in self.dims)
        return f"ARRAY[{ds}] OF {self.elem}"


@dataclass(frozen=True)
class StructT:
    name: str  # upper-case key

    def __str__(self) -> str:
        return self.name


@dataclass(frozen=True)
class FbT:
    name: str  # upper-case key
    standard: bool

    def __str__(self) -> str:
        return self.name


@dataclass(frozen=True)
class StringT:
    length: int

    def __str__(self) -> str:
        return f"STRING({self.length})"


ANYINT = "ANYINT"  # an integer literal: takes the type of what it meets
ANYREAL = "ANYREAL"


def is_int(t) -> bool:
    return t == ANYINT or (isinstance(t, str) and t in datatypes.TYPES and datatypes.TYPES[t].is_integer)


def is_real(t) -> bool:
    return t in ("REAL", "LREAL", ANYREAL)


def is_string(t) -> bool:
    return isinstance(t, StringT) or t == "STRING"


def bits_of(t) -> int:
    if t in ("WORD", "INT", "UINT"):
        return 16
    if t in ("DWORD", "DINT", "UDINT", "TIME"):
        return 32
    if t == "BOOL":
        return 1
    return 16


def concrete(t):
    """The type an untyped literal defaults to when nothing else decides."""
    if t == ANYINT:
        return "INT"
    if t == ANYREAL:
        return "REAL"
    return t


def unify(a, b):
    """Type of a binary arithmetic operation on types a and b."""
    if a == ANYINT and b == ANYINT:
        return ANYINT
    if a == ANYINT:
        return b if b != ANYREAL else ANYREAL
    if b == ANYINT:
        return a if a != ANYREAL else ANYREAL
    if a == ANYREAL or b == ANYREAL:
        other = b if a == ANYREAL else a
        return other if is_real(other) else "REAL"
    if is_real(a) or is_real(b):
        return "LREAL" if "LREAL" in (a, b) else "REAL"
    return datatypes.common_type(a, b)


def norm_code(t, code: str) -> str:
    """Python expression normalising `code` (a value of any numeric kind) into type t."""
    t = concrete(t)
    if isinstance(t, StringT):
        return f"({code})[:{t.length}]"
    if isinstance(t, str) and t in datatypes.TYPES:
        if datatypes.TYPES[t].is_integer and ANYINT_STEP in code:
            # constant arithmetic meeting type t: every step of it wraps in t
            code = code.replace(ANYINT_STEP, f"_anyint_{t}(")
        return datatypes.TYPES[t].norm.format(x=code)
    return code


ANYINT_STEP = "_anyint("  # marks a step of untyped constant arithmetic in generated code


def anyint_helpers() -> dict:
    """`_anyint` (a step not yet typed: exact) and `_anyint_<T>` (the step wrapped in T)
    for the generated module's namespace."""
    helpers = {"_anyint": lambda x: x}
    for name, et in datatypes.TYPES.items():
        if et.is_integer:
            helpers[f"_anyint_{name}"] = et.normalize
    return helpers


@dataclass
class Symbol:
    """A declared label as the generated code reaches it."""

    name: str  # as declared
    key: str
    type: object
    decl: ast.VarDecl | None
    code: str  # Python expression reaching the value ("self.wBuf", "l_i", "_G.bRun")
    section: str = "VAR"
    constant_value: object = None
    is_constant: bool = False
    device: object = None  # for globals assigned to a device (AT)
    write: str | None = None  # write template ({v}) when not a plain assignment to `code`


@dataclass
class PouInfo:
    pou: ast.Pou
    kind: str
    key: str
    symbols: dict[str, Symbol] = field(default_factory=dict)
    inputs: list[Symbol] = field(default_factory=list)  # VAR_INPUT + VAR_IN_OUT, declaration order
    outputs: list[Symbol] = field(default_factory=list)
    return_type: object = None
    class_name: str = ""

