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


def needed(files: list[ast.SourceFile], programs) -> set[str]:
    """Upper-case keys of the POUs and structure types `programs` (POU names) need,
    themselves included: the types of their labels (FB instances, arrays of them,
    structures and their members), their result types, the FUNCTIONs they call, and so
    on down; plus what the global labels need. Worked out on the parsed files, so that
    `uitamr export --program` asks the same as the simulator's compiler. Names that are
    no POU of `files` are left out."""
    pous = {pou.key: pou for f in files for pou in f.pous}
    structs = {struct.key: struct for f in files for struct in f.types}
    keys: set[str] = set()
    stack = [name.upper() for name in programs]
    stack += [k for f in files for block in f.globals for v in block.variables for k in type_names(v.type)]
    while stack:
        key = stack.pop()
        if key in keys:
            continue
        if key in structs:
            keys.add(key)
            stack += [k for v in structs[key].fields for k in type_names(v.type)]
        elif key in pous:
            keys.add(key)
            pou = pous[key]
            stack += [k for v in pou.variables for k in type_names(v.type)]
            if pou.return_type is not None:
                stack += type_names(pou.return_type)
            stack += called_functions(pou, pous)
    return keys


def type_names(t: ast.TypeRef) -> list[str]:
    """The type names a declared type refers to (an array's element type's too)."""
    while isinstance(t, ast.ArrayType):
        t = t.element
    return [t.key] if isinstance(t, ast.NamedType) else []


def called_functions(pou: ast.Pou, pous: dict) -> list[str]:
    """The user FUNCTIONs called anywhere in `pou` (its body and its initial values)."""
    return [node.key for node in ast.walk(pou.var_blocks, pou.body)
            if isinstance(node, ast.Call) and node.key in pous and pous[node.key].kind == "FUNCTION"]
