"""MELSEC elementary data types: their ranges, defaults and how a value is normalised.

Every ST value lives in Python in one canonical form per type, so generated code and the
instruction models agree:

| ST type | Python value | normalised by |
|---|---|---|
| BOOL | bool | `bool(x)` |
| INT (Word [Signed]) | int -32768..32767 | two's-complement wrap |
| DINT (Double Word [Signed]), TIME (ms) | int -2**31..2**31-1 | two's-complement wrap |
| WORD (Bit String [16-bit]), UINT | int 0..65535 | `& 0xFFFF` |
| DWORD (Bit String [32-bit]), UDINT | int 0..2**32-1 | `& 0xFFFFFFFF` |
| REAL (FLOAT [Single Precision]) | float rounded to IEEE single | `struct.pack('<f')` |
| LREAL (FLOAT [Double Precision]) | float | none |
| STRING | str (at most 255 characters in GX Works; the length is kept as declared) | truncation |
"""
from __future__ import annotations

import math
import struct
from dataclasses import dataclass

_F32 = struct.Struct("<f")


def wrap16(v: int) -> int:
    return ((v + 0x8000) & 0xFFFF) - 0x8000


def wrap32(v: int) -> int:
    return ((v + 0x80000000) & 0xFFFFFFFF) - 0x80000000


def to_f32(v: float) -> float:
    """Round a Python float to IEEE-754 single precision (what a REAL label can hold).

    Values beyond the single range become +/-inf; the caller decides whether that is an
    operation error."""
    try:
        return _F32.unpack(_F32.pack(v))[0]
    except OverflowError:
        return math.copysign(math.inf, v)


@dataclass(frozen=True)
class ElementaryType:
    name: str
    kind: str  # "bool" | "signed" | "unsigned" | "real" | "string"
    bits: int
    default: object
    # Python expression template normalising `{x}` into the canonical form of this type.
    norm: str

    @property
    def is_integer(self) -> bool:
        return self.kind in ("signed", "unsigned")

    def normalize(self, value):
        return NORMALIZERS[self.name](value)


_INT_NORM = "(({x}) + 32768 & 65535) - 32768"
_DINT_NORM = "(({x}) + 2147483648 & 4294967295) - 2147483648"

TYPES: dict[str, ElementaryType] = {
    t.name: t
    for t in (
        ElementaryType("BOOL", "bool", 1, False, "bool({x})"),
        ElementaryType("INT", "signed", 16, 0, _INT_NORM),
        ElementaryType("DINT", "signed", 32, 0, _DINT_NORM),
        ElementaryType("TIME", "signed", 32, 0, _DINT_NORM),
        ElementaryType("WORD", "unsigned", 16, 0, "({x}) & 65535"),
        ElementaryType("UINT", "unsigned", 16, 0, "({x}) & 65535"),
        ElementaryType("DWORD", "unsigned", 32, 0, "({x}) & 4294967295"),
        ElementaryType("UDINT", "unsigned", 32, 0, "({x}) & 4294967295"),
        ElementaryType("REAL", "real", 32, 0.0, "_f32({x})"),
        ElementaryType("LREAL", "real", 64, 0.0, "float({x})"),
        ElementaryType("STRING", "string", 0, "", "str({x})"),
    )
}
# Spellings GX Works uses in its label editor for the same types.
ALIASES = {
    "BIT": "BOOL",
    "FLOAT": "REAL",
    "WORD [SIGNED]": "INT",
    "DOUBLE WORD [SIGNED]": "DINT",
}

NORMALIZERS = {
    "BOOL": bool,
    "INT": wrap16,
    "DINT": wrap32,
    "TIME": wrap32,
    "WORD": lambda v: int(v) & 0xFFFF,
    "UINT": lambda v: int(v) & 0xFFFF,
    "DWORD": lambda v: int(v) & 0xFFFFFFFF,
    "UDINT": lambda v: int(v) & 0xFFFFFFFF,
    "REAL": lambda v: to_f32(float(v)),
    "LREAL": float,
    "STRING": str,
}

def lookup(name: str) -> ElementaryType | None:
    key = name.upper()
    key = ALIASES.get(key, key)
    return TYPES.get(key)


def common_type(a: str, b: str) -> str:
    """Type an arithmetic result takes from two operand types (wider one wins; a REAL
    operand makes the operation REAL)."""
    if a == b:
        return a
    rank = ["BOOL", "INT", "UINT", "WORD", "TIME", "DINT", "UDINT", "DWORD", "REAL", "LREAL"]
    ia = rank.index(a) if a in rank else 0
    ib = rank.index(b) if b in rank else 0
    return a if ia >= ib else b
