"""The GX Works type system: elementary types per target, arrays, structures, FB types,
and the signatures of standard functions, standard FBs and MELSEC instructions.

Sources (see docs/st-dialect.md for the full list): operator operand classes
(`+ - * /` ANY_NUM, `AND OR XOR NOT` ANY_BIT, `MOD` ANY_INT, comparisons ANY_SIMPLE) as
GX Works documents them; GX Works2 data types Bit, Word [Signed], Double Word [Signed],
Word [Unsigned]/Bit String [16-bit], Double Word [Unsigned]/Bit String [32-bit],
FLOAT, String, Time — GX Works3 adds UINT, UDINT, LREAL, WSTRING; neither has BYTE.
"""
from __future__ import annotations

from dataclasses import dataclass, field


# ----------------------------------------------------------------------------- types
@dataclass(frozen=True)
class Type:
    """Base of resolved types. `name` is what messages print."""

    name: str

    def __str__(self) -> str:
        return self.name


@dataclass(frozen=True)
class Elementary(Type):
    """BOOL, INT, DINT, UINT, UDINT, WORD, DWORD, REAL, LREAL, TIME, STRING, WSTRING.
    `group` is "bool", "int", "bits", "real", "time" or "string"; `bits` the width."""

    group: str = ""
    bits: int = 0
    signed: bool = False
    length: int | None = None  # STRING length


@dataclass(frozen=True)
class Generic(Type):
    """A type not yet fixed: an integer literal (`value` known), a real literal, or a
    MELSEC word device (`D100` reads as INT or WORD as the context needs: ANY16)."""

    group: str = ""            # "int-literal", "real-literal", "any16", "any32", "any"
    value: int | float | None = None


@dataclass(frozen=True)
class ArrayOf(Type):
    """ARRAY [lo..hi, ...] OF element."""

    element: Type = None  # type: ignore[assignment]
    dims: tuple[tuple[int, int], ...] = ()

    @property
    def size(self) -> int:
        n = 1
        for lo, hi in self.dims:
            n *= hi - lo + 1
        return n


@dataclass(frozen=True)
class StructOf(Type):
    """A structure (DUT): ordered fields."""

    fields: tuple[tuple[str, Type], ...] = ()

    def field(self, name: str) -> Type | None:
        key = name.upper()
        for n, t in self.fields:
            if n.upper() == key:
                return t
        return None


@dataclass(frozen=True)
class FbType(Type):
    """A function block type: standard (TON ...) or user-written. Parameters are
    (name, type) in declaration order."""

    inputs: tuple[tuple[str, Type], ...] = ()
    outputs: tuple[tuple[str, Type], ...] = ()
    in_outs: tuple[tuple[str, Type], ...] = ()
    publics: tuple[tuple[str, Type], ...] = ()
    standard: bool = False

    def param(self, name: str) -> tuple[str, Type] | None:
        """(kind, type) of the parameter spelt `name` (any case), the first in the order
        inputs, outputs, in_outs, publics; None when there is none."""
        groups = (self.inputs, self.outputs, self.in_outs, self.publics)
        cached = self.__dict__.get("_param_index")
        # the check looks parameters up once per call argument and member: an index built
        # once per instance, rebuilt when the groups are not the ones it was built from
        # (the collection fills a user FB's groups in after creating it, object.__setattr__)
        if cached is None or cached[0] != groups:
            index: dict[str, tuple[str, Type]] = {}
            for kind, group in zip(("input", "output", "in_out", "public"), groups):
                for n, t in group:
                    index.setdefault(n.upper(), (kind, t))
            cached = (groups, index)
            object.__setattr__(self, "_param_index", cached)
        return cached[1].get(name.upper())


@dataclass(frozen=True)
class PouRef(Type):
    """The type of a name that denotes a POU (a FUNCTION or FB type), not a value."""


def _e(name: str, group: str, bits: int, signed: bool = False) -> Elementary:
    return Elementary(name, group, bits, signed)


BOOL = _e("BOOL", "bool", 1)
INT = _e("INT", "int", 16, True)
DINT = _e("DINT", "int", 32, True)
UINT = _e("UINT", "int", 16)
UDINT = _e("UDINT", "int", 32)
WORD = _e("WORD", "bits", 16)
DWORD = _e("DWORD", "bits", 32)
REAL = _e("REAL", "real", 32, True)
LREAL = _e("LREAL", "real", 64, True)
TIME = _e("TIME", "time", 32, True)
STRING = Elementary("STRING", "string", 0, False, None)
WSTRING = Elementary("WSTRING", "string", 0, False, None)

ANY16 = Generic("ANY16", "any16")
ANY32 = Generic("ANY32", "any32")
ANY = Generic("ANY", "any")
VOID = Type("(no value)")

ELEMENTARY_BY_TARGET = {
    "gxworks2": {t.name: t for t in (BOOL, INT, DINT, WORD, DWORD, REAL, LREAL, TIME, STRING)},
    "gxworks3": {t.name: t for t in (BOOL, INT, DINT, UINT, UDINT, WORD, DWORD, REAL, LREAL,
                                     TIME, STRING, WSTRING)},
}
#: IEC types GX Works does not have, with the advice given when they are used
MISSING_TYPES = {
    "BYTE": "GX Works has no BYTE; keep one byte per WORD (or two packed, low byte first)",
    "SINT": "GX Works has no SINT; use INT",
    "USINT": "GX Works has no USINT; use WORD or INT",
    "LINT": "GX Works has no LINT; use DINT",
    "ULINT": "GX Works has no ULINT; use DWORD",
    "LWORD": "GX Works has no LWORD; use DWORD",
    "DATE": "GX Works has no DATE type; keep dates in WORDs",
    "TIME_OF_DAY": "GX Works has no TIME_OF_DAY; keep clock values in WORDs",
    "TOD": "GX Works has no TOD; keep clock values in WORDs",
    "DATE_AND_TIME": "GX Works has no DATE_AND_TIME; keep clock values in WORDs",
    "DT": "GX Works has no DT; keep clock values in WORDs",
    "CHAR": "GX Works has no CHAR; use STRING or a WORD",
    "UINT": "GX Works2 has no UINT; use WORD (or --target gxworks3)",
    "UDINT": "GX Works2 has no UDINT; use DWORD (or --target gxworks3)",
    "WSTRING": "GX Works2 has no WSTRING; use STRING (or --target gxworks3)",
}
INT_RANGE = {"INT": (-32768, 32767), "DINT": (-2**31, 2**31 - 1), "UINT": (0, 65535),
             "UDINT": (0, 2**32 - 1), "WORD": (0, 65535), "DWORD": (0, 2**32 - 1)}


def int_literal(value: int) -> Generic:
    return Generic("integer constant", "int-literal", value)


def real_literal(value: float) -> Generic:
    return Generic("REAL constant", "real-literal", value)


def is_group(t: Type, *groups: str) -> bool:
    return getattr(t, "group", None) in groups


def is_any_int(t: Type) -> bool:
    return is_group(t, "int", "int-literal", "any16", "any32")


def is_any_num(t: Type) -> bool:
    return is_group(t, "int", "real", "int-literal", "real-literal", "any16", "any32")


def is_any_bit(t: Type) -> bool:
    return is_group(t, "bool", "bits", "int-literal", "any16", "any32")


def is_bool(t: Type) -> bool:
    return t == BOOL or is_group(t, "any")


def width(t: Type) -> int:
    if isinstance(t, Elementary):
        return t.bits
    if is_group(t, "any16"):
        return 16
    if is_group(t, "any32"):
        return 32
    return 0


# ----------------------------------------------------------------------------- compatibility
def fits(value: int, t: Type) -> bool:
    lo, hi = INT_RANGE.get(t.name, (None, None))
    return lo is None or lo <= value <= hi


def assignable(target: Type, source: Type, target_name: str = "gxworks2") -> str | None:
    """None when a value of type `source` may be stored in `target` under GX Works'
    rules; otherwise the reason, phrased as what to do."""
    if target == source or is_group(target, "any") or is_group(source, "any"):
        return None
    if isinstance(target, Elementary) and target.group == "string" and isinstance(source, Elementary) and source.group == "string":
        return None if target.name == source.name else f"{source} cannot be stored in {target}"
    if is_group(source, "int-literal"):
        if is_group(target, "any16", "any32"):
            return None
        if isinstance(target, Elementary) and target.group in ("int", "bits"):
            return None  # range checked separately (warning/error with the value)
        if isinstance(target, Elementary) and target.group == "real":
            return f"an integer constant cannot be stored in {target}; write it as a REAL constant (e.g. 1.0)"
        if target == BOOL:
            return "an integer constant cannot be stored in BOOL; write TRUE or FALSE"
        if target == TIME:
            return ("an integer constant cannot be stored in TIME; write a TIME literal, T# and a number with its "
                    "unit, e.g. T#500ms or T#1s")
        return f"an integer constant cannot be stored in {target}"
    if is_group(source, "real-literal"):
        if isinstance(target, Elementary) and target.group == "real":
            return None
        return f"a REAL constant cannot be stored in {target}"
    if is_group(target, "any16"):
        return None if width(source) == 16 and not is_group(source, "real") else f"{source} is not a 16-bit value; a word device holds INT or WORD"
    if is_group(target, "any32"):
        return None if width(source) == 32 and not is_group(source, "real") else f"{source} is not a 32-bit value"
    if is_group(source, "any16"):
        return None if width(target) == 16 and not is_group(target, "real") else f"a word device (16 bits) cannot be stored in {target}"
    if is_group(source, "any32"):
        return None if width(target) == 32 and not is_group(target, "real") else f"a double-word device cannot be stored in {target}"
    if isinstance(target, ArrayOf) and isinstance(source, ArrayOf):
        if target.size == source.size and assignable(target.element, source.element, target_name) is None and target.element == source.element:
            return None
        return f"{source} cannot be stored in {target}: arrays need the same element type and size"
    if isinstance(target, Elementary) and isinstance(source, Elementary):
        if target_name == "gxworks3" and _widening(source, target):
            return None
        from verifier.st.library import conversion  # the library is built on these types

        conv = conversion(source, target, target_name)
        if conv is None:
            return f"{source} cannot be stored in {target}: GX Works has no function converting one to the other"
        return f"{source} cannot be stored in {target} without conversion; use {conv}(...)"
    return f"{source} cannot be stored in {target}"


def _widening(source: Elementary, target: Elementary) -> bool:
    """GX Works3 implicit conversions (ASSUMPTION, docs/st-dialect.md): to a wider type
    of the same kind, or integer to real."""
    pairs = {("INT", "DINT"), ("INT", "REAL"), ("INT", "LREAL"), ("DINT", "LREAL"),
             ("REAL", "LREAL"), ("UINT", "UDINT"), ("UINT", "DINT"), ("WORD", "DWORD"),
             ("UINT", "REAL"), ("UINT", "LREAL"), ("UDINT", "LREAL")}
    return (source.name, target.name) in pairs


def unify(a: Type, b: Type) -> Type | None:
    """The common type of two operands of a binary operator, or None if GX Works would
    reject mixing them."""
    if a == b:
        return a
    if is_group(a, "any"):
        return b
    if is_group(b, "any"):
        return a
    la, lb = is_group(a, "int-literal"), is_group(b, "int-literal")
    if la and lb:
        return int_literal(None)
    if la and (isinstance(b, Elementary) and b.group in ("int", "bits") or is_group(b, "any16", "any32")):
        return b
    if lb and (isinstance(a, Elementary) and a.group in ("int", "bits") or is_group(a, "any16", "any32")):
        return a
    ra, rb = is_group(a, "real-literal"), is_group(b, "real-literal")
    if ra and rb:
        return real_literal(None)
    if ra and is_group(b, "real"):
        return b
    if rb and is_group(a, "real"):
        return a
    if is_group(a, "any16") and width(b) == 16 and not is_group(b, "real"):
        return b
    if is_group(b, "any16") and width(a) == 16 and not is_group(a, "real"):
        return a
    if is_group(a, "any32") and width(b) == 32 and not is_group(b, "real"):
        return b
    if is_group(b, "any32") and width(a) == 32 and not is_group(a, "real"):
        return a
    return None


def concrete(t: Type) -> Type:
    """A literal's default type once nothing else decides it."""
    if is_group(t, "int-literal"):
        v = t.value
        return INT if v is None or -32768 <= v <= 32767 else DINT
    if is_group(t, "real-literal"):
        return REAL
    return t


# ----------------------------------------------------------------------------- signatures
@dataclass(frozen=True)
class Param:
    """One parameter of a function or instruction. `accepts` is a class name checked by
    `accepts()`: "BOOL", "ANY16", "ANY32", "ANY_NUM", "ANY_INT", "ANY_BIT", "ANY_REAL",
    "ANY_SIMPLE", "ANY", "BLOCK16" (head of a block of words), "BITS" (a bit, or the head of bits), "BITS2" (the head of two completion bits),
    "TIME", "STRING", or an elementary type name. `direction` "in", "out" or "inout"."""

    name: str
    accepts: str
    direction: str = "in"


@dataclass(frozen=True)
class Signature:
    """A callable: `params` in call order; `result` a type, "SAME" (the type of the
    generic operands), or None (instruction: returns ENO as BOOL). `variadic` repeats
    the last parameter (AND, MAX ...). `targets` limits where it exists."""

    name: str
    kind: str  # "function", "instruction"
    params: tuple[Param, ...]
    result: Type | str | None
    variadic: bool = False
    targets: tuple[str, ...] = ("gxworks2", "gxworks3")
    note: str = ""


@dataclass
class CallTarget:
    """What a `Call` resolved to (set on `ast.Call.resolved` by the check).
    kind: "fb" (instance call), "function" (user FUNCTION), "standard_function",
    "instruction". `pou` is the user POU for "function"/"fb" of user types, `fb_type`
    the FbType for "fb", `signature` for standard functions and instructions,
    `generic` the type the generic parameters resolved to (e.g. INT for ADD of INTs)."""

    kind: str
    name: str
    pou: object = None
    fb_type: FbType | None = None
    signature: Signature | None = None
    generic: Type | None = None
    extra: dict = field(default_factory=dict)
    # the check's errors about the call against `signature` (argument count, operands): a
    # CPU check that finds the instruction missing there reports that alone
    signature_errors: list = field(default_factory=list, compare=False, repr=False)
