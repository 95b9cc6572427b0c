"""What `uitamr export --program NAME` writes: NAME and every POU and structure type it
needs, down to the last function (`verifier.sim.reach.needed`, which the simulator's
compiler asks too), so that an integrator pastes into GX Works only the part of the
library a program uses (GX Works2 takes each POU by hand).
"""
from __future__ import annotations

import dataclasses

from verifier.sim import reach
from verifier.st import ast


class UnknownProgram(ValueError):
    """A name given to --program that is not a POU of the sources."""


def needed(files: list[ast.SourceFile], programs: list[str]) -> set[str]:
    """Upper-case keys of the POUs and structure types `programs` need (themselves
    included). UnknownProgram names what the sources define instead."""
    pous = {pou.key: pou for f in files for pou in f.pous}
    unknown = [name for name in programs if name.upper() not in pous]
    if unknown:
        defined = ", ".join(sorted(p.name for p in pous.values() if p.kind == "PROGRAM")) or "none"
        raise UnknownProgram(f"no POU {', '.join(unknown)} in the sources (their PROGRAMs: {defined})")
    return reach.needed(files, programs)


def only(f: ast.SourceFile, keys: set[str]) -> ast.SourceFile:
    """`f` with only the POUs and structure types named in `keys` (its global labels are
    kept: every program shares them)."""
    return dataclasses.replace(f, pous=[p for p in f.pous if p.key in keys],
                               types=[s for s in f.types if s.key in keys])
