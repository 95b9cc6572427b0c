"""The devices and instructions of checked ST against one CPU profile (`uitamr check
--platform`), without compiling anything.

The rules are the simulator's own: `devices.locate` (device areas, numbering, ranges,
index registers, digit and bit access) and `instructions.not_on_cpu` (which CPU family an
instruction exists on) are what its compiler asks too. So `check --platform fx3u` reports
the device and instruction errors `uitamr verify` and `verifier.load(..., cpu="fx3u")`
would stop at, every one of them rather than the first, and no table of its own.
"""
from __future__ import annotations

from verifier.st import ast

from .cpu import CpuProfile
from .devices import DeviceError, fx3_special_elsewhere, locate
from .instructions import not_on_cpu


def cpu_diagnostics(files: list[ast.SourceFile], cpu: CpuProfile,
                    foreign_calls: list[ast.Call] | None = None) -> list[ast.Diagnostic]:
    """An error for every device (in bodies, initial values and `AT` assignments) and every
    instruction call of `files` that `cpu` does not have, in file order. Instruction calls
    are recognised by the check's resolution (`ast.Call.resolved`): run
    `verifier.st.check` on the files first. The calls of instructions `cpu` lacks are
    appended to `foreign_calls` when given (their operands were checked against another
    CPU's instruction: `foreign_call_finding` tells those findings apart)."""
    found: list[ast.Diagnostic] = []
    for f in files:
        mine: list[ast.Diagnostic] = []
        for node in ast.walk(f.globals, f.types, f.pous):
            if isinstance(node, ast.Device) and node.module is None:
                try:
                    locate(node, cpu)
                except DeviceError as e:
                    mine.append(_at(node.span, str(e)))
                else:
                    why = fx3_special_elsewhere(node, cpu)
                    if why:
                        mine.append(_at(node.span, why, "warning"))
            elif isinstance(node, ast.Call) and getattr(node.resolved, "kind", None) == "instruction":
                why = not_on_cpu(node.name, cpu)
                if why:
                    mine.append(_at(node.callee.span, why))
                    if foreign_calls is not None:
                        foreign_calls.append(node)
        found += sorted(mine, key=lambda d: (d.line, d.col))
    return found


def _at(span: ast.Span, message: str, severity: str = "error") -> ast.Diagnostic:
    return ast.Diagnostic(span.file, span.line, span.col, severity, message, span.end_line, span.end_col)


def foreign_call_finding(d: ast.Diagnostic, calls: list[ast.Call]) -> bool:
    """Is `d` the checker's complaint about the arguments or operands of one of `calls`
    (instructions the CPU lacks: `RS2 takes 6 argument(s)`, `RS2 operand s: ...`)? Those
    judge the call by an instruction the program cannot use there; the fix is another
    instruction, so `uitamr check --platform` reports the missing instruction alone."""
    for c in calls:
        span = c.span
        if (d.file == span.file and d.message.startswith((f"{c.name} takes ", f"{c.name} operand "))
                and (span.line, span.col) <= (d.line, d.col) <= (span.end_line, span.end_col)):
            return True
    return False
