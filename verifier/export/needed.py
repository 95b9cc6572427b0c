"""What `uitamr export --program NAME` writes: NAME and every POU and structure type it
needs, down to the last function, so that an integrator pastes into GX Works only the
part of the library a program uses (GX Works2 takes each POU by hand).

Worked out on the parsed (and checked) files, without a CPU: the label types of each
POU (FB instances, arrays of them, structures and their members), its result type, the
FUNCTIONs it calls (`verifier.sim.reach`, which `uitamr verify` uses to compile only
what a program runs, does the same on the simulator's resolved types); plus what the
global labels need, since every program shares them.
"""
from __future__ import annotations

import dataclasses

from verifier.st import ast
from verifier.sim.reach import called_functions


class UnknownProgram(ValueError):
    """A name given to --program that is not a POU of the sources."""


def needed(files: list[ast.SourceFile], programs: list[str]) -> set[str]:
    """Upper-case keys of the POUs and structure types `programs` need (themselves
    included). UnknownProgram names what the sources define instead."""
    pous = {pou.key: pou for f in files for pou in f.pous}
    structs = {struct.key: struct for f in files for struct in f.types}
    unknown = [name for name in programs if name.upper() not in pous]
    if unknown:
        defined = ", ".join(sorted(p.name for p in pous.values() if p.kind == "PROGRAM")) or "none"
        raise UnknownProgram(f"no POU {', '.join(unknown)} in the sources (their PROGRAMs: {defined})")
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


def only(f: ast.SourceFile, keys: set[str]) -> ast.SourceFile:
    """`f` with only the POUs and structure types named in `keys` (its global labels are
    kept: every program shares them)."""
    return dataclasses.replace(f, pous=[p for p in f.pous if p.key in keys],
                               types=[s for s in f.types if s.key in keys])
