"""Which POUs some PROGRAMs need: themselves, the FUNCTION_BLOCKs their labels are
instances of (through arrays and VAR_IN_OUTs too), the FUNCTIONs they call, and so on
down; plus what the global labels need, which every program shares.

`uitamr verify` runs one PROGRAM of a library that holds several examples and function
blocks it never uses. Generating and compiling Python for those costs more than parsing
the whole library (a 27-file FX3 set: 7,600 generated lines, of which the FX3U example
needs 2,800), so the runner asks for the POUs its program needs and no more. Every file
is still parsed and checked in full: what GX Works would refuse is reported all the same.
"""
from __future__ import annotations


from verifier.st import ast

from .typesys import ArrayT, FbT, StructT


def needed_pous(pous: dict, struct_fields: dict, globals_: dict, programs) -> set[str]:
    """Keys of the POUs (`pous`: PouInfo by upper-case key) that `programs` need."""
    needed: set[str] = set()
    stack = [name.upper() for name in programs]
    for sym in globals_.values():
        stack += _fb_types(sym.type, struct_fields, set())
    while stack:
        key = stack.pop()
        if key in needed or key not in pous:
            continue
        needed.add(key)
        info = pous[key]
        for sym in info.symbols.values():
            stack += _fb_types(sym.type, struct_fields, set())
        stack += called_functions(info.pou, pous)
    return needed


def _fb_types(t, struct_fields: dict, seen: set) -> list[str]:
    """The user FUNCTION_BLOCK types a label of type `t` holds instances of."""
    if isinstance(t, FbT):
        return [] if t.standard else [t.name]
    if isinstance(t, ArrayT):
        return _fb_types(t.elem, struct_fields, seen)
    if isinstance(t, StructT) and t.name not in seen:
        seen.add(t.name)
        return [k for sym in struct_fields.get(t.name, {}).values()
                for k in _fb_types(sym.type, struct_fields, seen)]
    return []


def called_functions(pou: ast.Pou, pous: dict) -> list[str]:
    """The user FUNCTIONs called anywhere in `pou` (its body and its initial values)."""
    return [node.key for node in ast.walk(pou.var_blocks, pou.body)
            if isinstance(node, ast.Call) and node.key in pous and pous[node.key].kind == "FUNCTION"]
