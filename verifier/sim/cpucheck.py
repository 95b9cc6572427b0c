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

from .cpu import CpuProfile, type_not_on_cpu
from .devices import DeviceError, fx3_special_elsewhere, locate, locate_buffer
from .instructions import not_on_cpu


def cpu_diagnostics(files: list[ast.SourceFile], cpu: CpuProfile, superseded: list[ast.Diagnostic] | None = None,
                    pous: set[str] | None = None) -> list[ast.Diagnostic]:
    """An error for every device (in bodies, initial values and `AT` assignments) and every
    instruction call of `files` that `cpu` does not have, in file order. Instruction calls
    are recognised by the check's resolution (`ast.Call.resolved`): run
    `verifier.st.check` on the files first. The check's errors about the arguments and
    operands of an instruction `cpu` lacks (judged against another CPU's instruction; the
    fix is another instruction) are appended to `superseded` when given. `pous`: the keys of
    the POUs to look at (the global labels and structures always), None for all."""
    found: list[ast.Diagnostic] = []
    for f in files:
        mine: list[ast.Diagnostic] = []
        chosen = f.pous if pous is None else [pou for pou in f.pous if pou.key in pous]
        for node in ast.walk(f.globals, f.types, chosen):
            if isinstance(node, ast.Device) and node.module is not None:
                try:
                    locate_buffer(node, cpu)
                except DeviceError as e:
                    mine.append(_at(node.span, str(e)))
            elif isinstance(node, ast.Device):
                try:
                    locate(node, cpu)
                except DeviceError as e:
                    mine.append(_at(node.span, str(e)))
                else:
                    why = fx3_special_elsewhere(node, cpu)
                    if why:
                        mine.append(_at(node.span, why, "warning"))
            elif isinstance(node, ast.NamedType):
                why = type_not_on_cpu(node.key, cpu)
                if why:
                    mine.append(_at(node.span, why))
            elif isinstance(node, ast.Call) and getattr(node.resolved, "kind", None) == "instruction":
                why = not_on_cpu(node.name, cpu)
                if why:
                    mine.append(_at(node.callee.span, why))
                    if superseded is not None:
                        superseded.extend(node.resolved.signature_errors)
        found += sorted(mine, key=lambda d: (d.line, d.col))
    return found


def on_cpu(files: list[ast.SourceFile], cpu: CpuProfile, diagnostics: list[ast.Diagnostic]
           ) -> tuple[list[ast.Diagnostic], list[ast.Diagnostic]]:
    """What `uitamr check --platform` reports about `files` on `cpu`: the check's
    `diagnostics` that still stand there (not the argument and operand errors of an
    instruction `cpu` lacks: the fix is another instruction), and `cpu_diagnostics`'
    findings. `uitamr export --platform` asks the same, of the POUs it writes."""
    superseded: list[ast.Diagnostic] = []
    found = cpu_diagnostics(files, cpu, superseded)
    gone = {id(d) for d in superseded}
    return [d for d in diagnostics if id(d) not in gone], found


def _at(span: ast.Span, message: str, severity: str = "error") -> ast.Diagnostic:
    return ast.Diagnostic.of_span(span, severity, message)
