"""Refuse label memory the simulator cannot build, before it tries.

The checker (verifier.st) already rejects recursion and sizes GX Works cannot hold; this
is the simulator's own guard for whatever reaches it anyway (a checker gap, a future
dialect): an FB or structure that contains itself would make Python recurse without end
while building the instance, and an absurd array would exhaust memory.  Both become a
CompileError at the label's file:line:col instead of a RecursionError or MemoryError.

Sizes are counted in stored values ("cells": one per BOOL, word, number or string;
arrays multiply, structures and FB instances add up their labels).  The limits are the
simulator's, far above anything a MELSEC CPU holds (see docs/instructions.md, CPU
profiles), so no program a PLC can run is refused.
"""
from __future__ import annotations

from .stdfbs import STANDARD_FBS
from .typesys import ArrayT, CompileError, FbT, StructT

LABEL_LIMIT = 1 << 20  # cells in one label (an FB instance counts everything it holds)
INSTANCE_LIMIT = 1 << 22  # cells in one structure, FB, PROGRAM or the global labels
NOT_STORED = ("VAR_GLOBAL", "VAR_IN_OUT", "RETURN")  # references to memory held elsewhere


class StorageCheck:
    """Cell counts of the types of one project, with the circle that makes one infinite."""

    def __init__(self, struct_fields: dict, pous: dict, struct_names: dict[str, str]):
        self.struct_fields = struct_fields
        self.pous = pous
        self.names = dict(struct_names)
        self.names.update((key, info.pou.name) for key, info in pous.items())
        self._cells: dict[tuple[str, str], int] = {}
        self._building: list[tuple[tuple[str, str], str]] = []  # (type, label) being counted

    def run(self, global_symbols: dict) -> None:
        for key in self.struct_fields:
            self.cells(StructT(key), None)
        for info in self.pous.values():
            if info.kind != "FUNCTION":
                self.cells(FbT(info.key, False), None)
            else:
                self._members("FUNCTION " + info.pou.name, info.symbols.values())
        self._members("the global labels", global_symbols.values(), stored=("VAR_GLOBAL",))

    def cells(self, t, decl) -> int:
        if isinstance(t, ArrayT):
            return t.size * self.cells(t.elem, decl)
        if isinstance(t, StructT):
            key, members, what = ("STRUCT", t.name), self.struct_fields[t.name].values(), "structure"
        elif isinstance(t, FbT) and not t.standard and t.name not in STANDARD_FBS:
            info = self.pous[t.name]
            key, members = ("FB", t.name), info.symbols.values()
            what = "PROGRAM" if info.kind == "PROGRAM" else "function block"
        else:
            return 1
        known = self._cells.get(key)
        if known is not None:
            return known
        open_types = [k for k, _ in self._building]
        if key in open_types:
            self._refuse_circle(open_types.index(key), what, t.name, decl)
        self._building.append((key, ""))
        try:
            total = self._members(f"{what} {self.names[t.name]}", members)
        except RecursionError:
            raise CompileError(getattr(decl, "span", None),
                               f"{what} {t.name}: types nested too deeply to simulate") from None
        self._building.pop()
        self._cells[key] = total
        return total

    def _members(self, owner: str, symbols, stored: tuple[str, ...] = ()) -> int:
        total = 0
        for sym in symbols:
            if (sym.section in NOT_STORED and sym.section not in stored) or sym.decl is None:
                continue
            if self._building:
                self._building[-1] = (self._building[-1][0], sym.name)
            n = self.cells(sym.type, sym.decl)
            if n > LABEL_LIMIT:
                raise CompileError(sym.decl.span, f"label '{sym.name}' of {owner} needs {n:,} values; "
                                                  f"the simulator holds at most {LABEL_LIMIT:,} per label")
            total += n
            if total > INSTANCE_LIMIT:
                raise CompileError(sym.decl.span, f"{owner} needs more than {INSTANCE_LIMIT:,} values "
                                                  f"of labels (at '{sym.name}'); the simulator refuses it")
        return total

    def _refuse_circle(self, start: int, what: str, name: str, decl) -> None:
        circle = self._building[start:]
        path = " -> ".join(f"{self.names[k[1]]}.{label}" for k, label in circle) + f" -> {self.names[name]}"
        first_label = circle[0][1]
        span = decl.span if decl is not None else None
        owner = self.struct_fields.get(circle[0][0][1]) if circle[0][0][0] == "STRUCT" else \
            self.pous[circle[0][0][1]].symbols
        sym = owner.get(first_label.upper()) if owner else None
        if sym is not None and sym.decl is not None:
            span = sym.decl.span
        raise CompileError(span, f"{what} {self.names[name]} contains itself ({path}): "
                                 "an instance of it would never end")


def check_storage(struct_fields: dict, pous: dict, global_symbols: dict, struct_names: dict[str, str]) -> None:
    """Raise CompileError at the first label that cannot be built (circle or size)."""
    StorageCheck(struct_fields, pous, struct_names).run(global_symbols)
