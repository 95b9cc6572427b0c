"""FUNCTIONs whose result depends on their inputs alone, so the simulator may remember it.

A CRC or a table lookup written in ST runs its loops every time it is called; when the
same frame is checked again and again (a master polls the same few requests), the
result can be looked up instead.  That is only correct for a FUNCTION that:
- has VAR_INPUT parameters of elementary types or arrays of them, a result of an
  elementary type, locals of elementary types or arrays of them, and no VAR_OUTPUT,
  VAR_IN_OUT or VAR_EXTERNAL;
- reads no device and no global label, calls no instruction, and calls only such
  FUNCTIONs and the standard functions listed below, which cannot fail;
- divides nowhere (a division by zero is an operation error: flags and a diagnostic are
  side effects a remembered result would skip).
Anything raised inside (an index out of range, the watchdog) is raised on every call:
only returned results are remembered.
"""
from __future__ import annotations

import dataclasses

from verifier.st import ast

from .typesys import ArrayT, StringT

_INTEGERS = ("BOOL", "INT", "UINT", "WORD", "DINT", "UDINT", "DWORD")
SAFE_STD = frozenset({"SHL", "SHR", "ROL", "ROR", "MIN", "MAX", "LIMIT", "SEL", "MOVE"} |
                     {f"{a}_TO_{b}" for a in _INTEGERS for b in _INTEGERS if a != b})
MEMO_SIZE = 4096  # remembered results per FUNCTION (oldest forgotten first)


def _plain(t) -> bool:
    """An elementary type or an array of them (values that can be copied into a key)."""
    if isinstance(t, ArrayT):
        return isinstance(t.elem, (str, StringT))
    return isinstance(t, (str, StringT))


def _signature_ok(info) -> bool:
    if not _plain(info.return_type) or isinstance(info.return_type, ArrayT):
        return False
    for sym in info.symbols.values():
        if sym.section == "RETURN":
            continue
        if sym.section not in ("VAR_INPUT", "VAR", "VAR_TEMP") or not _plain(sym.type):
            return False
    return True


def _body_calls(info, functions) -> set[str] | None:
    """The FUNCTIONs the body calls, or None when the body is not pure."""
    called: set[str] = set()
    stack: list = list(info.pou.body)
    while stack:
        node = stack.pop()
        if isinstance(node, list):
            stack.extend(node)
            continue
        if not dataclasses.is_dataclass(node):
            continue
        if isinstance(node, ast.Device):
            return None
        if isinstance(node, ast.Name) and node.key not in info.symbols and node.key not in functions:
            return None  # a global label (or anything else not the function's own)
        if isinstance(node, ast.BinaryOp) and node.op in ("/", "MOD", "**"):
            return None
        if isinstance(node, ast.Call):
            key = node.callee.key if isinstance(node.callee, ast.Name) else None
            if key in functions:
                called.add(key)
            elif key not in SAFE_STD:
                return None
            stack.extend(a.value for a in node.args)
            continue
        stack.extend(ast.syntax_fields(node))
    return called


def pure_functions(functions: dict) -> set[str]:
    """Keys of the FUNCTIONs (PouInfo by key) that satisfy the module docstring."""
    calls = {}
    for key, info in functions.items():
        if _signature_ok(info):
            called = _body_calls(info, functions)
            if called is not None:
                calls[key] = called
    pure = set(calls)
    changed = True
    while changed:  # a FUNCTION calling one that is not pure is not pure either
        changed = False
        for key in list(pure):
            if not calls[key] <= pure:
                pure.discard(key)
                changed = True
    return pure


def remembered(function):
    """`function` with its results remembered per argument values (arrays by content)."""
    memo: dict = {}

    def call(*args):
        key = tuple(tuple(a) if isinstance(a, list) else a for a in args)
        value = memo.get(key)
        if value is None:
            value = function(*args)
            if len(memo) >= MEMO_SIZE:
                del memo[next(iter(memo))]
            memo[key] = value
        return value

    call.__wrapped__ = function
    return call
