"""Data type names as the GX Works label editors spell them.

GX Works2 (structured project) and GX Works3 show elementary types by description, not by
IEC keyword: BOOL is "Bit", INT "Word[Signed]", WORD "Word[Unsigned]/Bit String[16-bit]".
GX Works3 writes a space before each bracket. Arrays are "<element>(low..high)", several
dimensions "(a..b,c..d)". Function block types (standard ones such as TON, and the
user's) are written by name.
Source: the data-type column of the label editors as listed in the GX Works2 Version 1
Operating Manual (Common) and the GX Works3 Operating Manual (label setting); the exact
GX Works3 spacing is an ASSUMPTION noted in docs/import-gxworks3.md.
"""
from __future__ import annotations

from verifier.st import ast

_GXW2 = {
    "BOOL": "Bit",
    "INT": "Word[Signed]",
    "DINT": "Double Word[Signed]",
    "WORD": "Word[Unsigned]/Bit String[16-bit]",
    "DWORD": "Double Word[Unsigned]/Bit String[32-bit]",
    "REAL": "FLOAT (Single Precision)",
    "LREAL": "FLOAT (Double Precision)",
    "TIME": "Time",
    "STRING": "String",
    "UINT": "Word[Unsigned]",
    "UDINT": "Double Word[Unsigned]",
    "TIMER": "Timer",
    "COUNTER": "Counter",
    "RETENTIVETIMER": "Retentive Timer",
}
_GXW3 = {
    "BOOL": "Bit",
    "INT": "Word [Signed]",
    "DINT": "Double Word [Signed]",
    "WORD": "Word [Unsigned]/Bit String [16-bit]",
    "DWORD": "Double Word [Unsigned]/Bit String [32-bit]",
    "REAL": "FLOAT [Single Precision]",
    "LREAL": "FLOAT [Double Precision]",
    "TIME": "Time",
    "STRING": "String",
    "WSTRING": "String [Unicode]",
    "UINT": "Word [Unsigned]",
    "UDINT": "Double Word [Unsigned]",
    "TIMER": "Timer",
    "COUNTER": "Counter",
    "RETENTIVETIMER": "Retentive Timer",
}
TABLES = {"gxworks2": _GXW2, "gxworks3": _GXW3}


def type_name(t: ast.TypeRef, target: str) -> str:
    """The label editor's spelling of type `t` for `target` ("gxworks2" | "gxworks3")."""
    table = TABLES[target]
    if isinstance(t, ast.ArrayType):
        dims = ",".join(f"{d.low}..{d.high}" for d in t.dims)
        return f"{type_name(t.element, target)}({dims})"
    if isinstance(t, ast.StringType):
        base = table["WSTRING" if t.wide and "WSTRING" in table else "STRING"]
        return f"{base}({t.length})" if t.length is not None else base
    if isinstance(t, ast.NamedType):
        return table.get(t.key, t.name)
    raise TypeError(f"cannot name type {t!r}")
