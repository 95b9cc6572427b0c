"""An operator input the program never sees: a label or device an `[[inputs]]` entry sets
that the program overwrites in every scan before it reads it.

Inputs are applied before a scan (docs/scenarios.md). When the first thing every scan does
with the label is to assign it - `bLamp := nStarts > 0;` at the top level of the PROGRAM,
an FB call that binds it, `fbCycle(i_bStart := X0, ...)` for `fbCycle.i_bStart`, or an
assignment in the body of the FB the PROGRAM calls - the value set is gone before anything reads it: the scenario's button
press did nothing. A label the program resets only sometimes (`IF bStartPb THEN ...
bStartPb := FALSE; END_IF`), or after reading it (`IF bStart THEN ... END_IF; bStart :=
FALSE;`, a one-scan pulse), is seen, and is not reported.

The search is conservative: it follows the PROGRAM's statements in order, and the body of
an FB instance it calls, and stops without a finding at the first statement that might
read or partly write the label - one that names it, or a part or a whole of it (`wBuf[i]`
for `wBuf[2]`, `fbCycle` passed on), inside a condition, a loop, a call's arguments (an
instruction's operand stands for the block it reaches), or a RETURN. A device might be
reached by any call: for one it stops at the first call too. A label that is not the
PROGRAM's own (a global one, which any POU may read) is not followed at all.
"""
from __future__ import annotations

import os
from dataclasses import dataclass
from typing import Any

from verifier.st import ast
from verifier.st.devices import parse_device
from verifier.textfile import text_lines

_ANY = None  # an index the source computes: it may be any element


@dataclass(frozen=True)
class Overwrite:
    """Where the program overwrites the label (`span`), and what it assigns (`value`,
    None for an FB's output written back through `=>`), in the `pou` that does it."""

    span: ast.Span
    value: ast.Expr | None
    pou: ast.Pou


class _Touched(Exception):
    """The label may be read (or partly written) here: no finding."""


class _Context:
    def __init__(self, pous: dict[str, ast.Pou], pou: ast.Pou, calls_touch: bool):
        self.pous = pous
        self.pou = pou
        self.labels = {v.name.upper(): v for v in pou.variables}
        self.calls_touch = calls_touch  # a device or a global label: any call may reach it

    def inside(self, pou: ast.Pou) -> "_Context":
        return _Context(self.pous, pou, self.calls_touch)


def first_overwrite(files: list[ast.SourceFile], program: str, name: str) -> Overwrite | None:
    """Where the PROGRAM `program` overwrites `name` (a label path such as
    "fbCycle.i_bStart" or a device such as "Y0") in every scan before it can read it, or
    None when it may read it first, or writes it only sometimes, or never."""
    pous = {pou.key: pou for f in files for pou in f.pous}
    pou = pous.get(program.upper())
    if pou is None or pou.kind != "PROGRAM":
        return None
    device = parse_device(name.upper())
    if device is not None and device["digits"] is None and device["index"] is None:
        if any(v.at is not None for f in files for block in f.globals for v in block.variables) or \
                any(v.at is not None for p in pous.values() for v in p.variables):
            return None  # a label bound to a device is another name for it
        target: list = [("dev", device["kind"], _address(device["address"]), _module(device["module"]))]
        context = _Context(pous, pou, calls_touch=True)
    else:
        target = _label_path(name)
        context = _Context(pous, pou, calls_touch=False)
        declared = context.labels.get(target[0]) if target else None
        if declared is None or declared.section not in ("VAR", "VAR_INPUT", "VAR_OUTPUT") or declared.constant \
                or declared.at is not None:
            return None  # a global label (reached by any POU), or one that is not the program's to keep
    try:
        return _first(pou.body, target, context)
    except _Touched:
        return None


def _label_path(name: str) -> list:
    path: list = []
    for part in name.replace("[", ".[").split("."):
        if not part:
            continue
        path.append(int(part[1:-1]) if part.startswith("[") else part.upper())
    return path


def _first(body: list[ast.Stmt], target: list, context: _Context) -> Overwrite | None:
    """The statement of `body` that overwrites `target` before anything reads it; None when
    no statement touches it; _Touched when one may read it first."""
    for statement in body:
        found = _statement(statement, target, context)
        if found is not None:
            return found
    return None


def _statement(statement: ast.Stmt, target: list, context: _Context) -> Overwrite | None:
    if isinstance(statement, ast.Assign):
        _reads(statement.value, target, context)
        path = _path(statement.target)
        if path is None:
            raise _Touched
        for index in _index_expressions(statement.target):
            _reads(index, target, context)
        if path == target:
            return Overwrite(statement.span, statement.value, context.pou)
        if _overlap(path, target):
            raise _Touched  # a part of it, or the whole it is part of, or an element of any index
        return None
    if isinstance(statement, ast.CallStmt):
        return _call(statement.call, target, context)
    if isinstance(statement, ast.Empty):
        return None
    # IF, CASE, loops: what they do happens only sometimes; RETURN and EXIT end the scan's path
    if isinstance(statement, (ast.Return, ast.Exit)) or _anywhere(statement, target, context):
        raise _Touched
    return None


def _anywhere(node: Any, target: list, context: _Context) -> bool:
    """Whether `node` (a statement and all inside it) names the target, calls what may reach
    it, or holds a RETURN or EXIT (after which the statements that follow may not run)."""
    stack = [node]
    while stack:
        item = stack.pop()
        if isinstance(item, (ast.Return, ast.Exit)):
            return True
        if isinstance(item, ast.Call) and (context.calls_touch or _call_may_reach(item, target)):
            return True
        path = _path(item) if isinstance(item, ast.Expr) else None
        if path is not None:  # a reference: itself, and the indices it computes (not its base)
            if _overlap(path, target):
                return True
            stack += _index_expressions(item)
        elif isinstance(item, list):
            stack += item
        elif isinstance(item, ast.Node):
            stack += [getattr(item, f) for f in item.__dataclass_fields__ if f not in ("span", "type", "symbol",
                                                                                       "resolved")]
    return False


def _call_may_reach(call: ast.Call, target: list) -> bool:
    path = _path(call.callee)
    return path is None or _overlap(path, target) or any(
        _overlap(_root(arg.value), target) for arg in call.args if _root(arg.value) is not None)


def _call(call: ast.Call, target: list, context: _Context) -> Overwrite | None:
    if context.calls_touch:
        raise _Touched
    callee = _path(call.callee)
    if callee is None:
        raise _Touched
    member_of_it = len(target) > len(callee) and _overlap(callee, target)
    if _overlap(callee, target) and not member_of_it:
        raise _Touched  # the instance itself is the target, or the target holds it
    if any(arg.name is not None and arg.name.upper() == "EN" for arg in call.args):
        raise _Touched  # with EN off the call does nothing: it may or may not run
    declared = context.labels.get(callee[0]) if len(callee) == 1 else None
    pou = _fb_pou(declared, context)
    inputs = [arg for arg in call.args if not arg.output]
    for arg in inputs:  # evaluated before the body runs; an instruction's operand reaches a block
        _reads(arg.value, target, context, whole=pou is None)
    written = None
    for arg in call.args:
        if arg.output:  # `o_x => dest`: dest written after the body, from the member
            path = _path(arg.value)
            if path is None:
                raise _Touched
            for index in _index_expressions(arg.value):  # `Q => bits[n]` reads n
                _reads(index, target, context)
            if path == target:
                written = Overwrite(arg.span, None, context.pou)
            elif _overlap(path, target):
                raise _Touched
    if not member_of_it:
        return written  # the body reaches only its own members and what the arguments name
    rest = target[len(callee):]
    if declared is None or not isinstance(declared.type, ast.NamedType) or not isinstance(rest[0], str):
        raise _Touched  # an array of instances, or an element of the instance
    member = {v.name.upper(): v for v in pou.variables}.get(rest[0]) if pou is not None else None
    if pou is not None and (member is None or member.section not in ("VAR", "VAR_INPUT", "VAR_OUTPUT")
                            or member.constant):
        raise _Touched  # VAR_IN_OUT, VAR_EXTERNAL: another name for something outside
    for arg in inputs:
        if arg.name is not None and arg.name.upper() == rest[0]:  # the call assigns the input
            if len(rest) == 1:  # (a standard FB's too: TON's PT)
                return Overwrite(arg.span, arg.value, context.pou)
            raise _Touched
    if pou is None:
        raise _Touched  # a standard FB (TON): no ST body here to follow
    inner = _first(pou.body, rest, context.inside(pou))
    if inner is not None:
        return inner
    if any(arg.output and arg.name is not None and arg.name.upper() == rest[0] for arg in call.args):
        raise _Touched  # `member => x` reads it after the body
    return None


def _fb_pou(declared: ast.VarDecl | None, context: _Context) -> ast.Pou | None:
    if declared is None or not isinstance(declared.type, ast.NamedType):
        return None
    pou = context.pous.get(declared.type.name.upper())
    return pou if pou is not None and pou.kind == "FUNCTION_BLOCK" else None


def _reads(expr: ast.Expr, target: list, context: _Context, whole: bool = False) -> None:
    """_Touched when evaluating `expr` may read the target (`whole`: a reference stands for
    all of its variable, as an instruction's operand does)."""
    if whole:
        root = _root(expr)
        if root is not None and _overlap(root, target):
            raise _Touched
    if _anywhere(expr, target, context):
        raise _Touched


def _path(expr: ast.Expr) -> list | None:
    """The reference `expr` names, as a path: label names upper case, constant indices as
    numbers (_ANY for one the source computes), a bit of a word as ("bit", n), a device as
    ("dev", kind, address or _ANY for a group or a bit of a word, module). None when `expr`
    is no reference."""
    if isinstance(expr, ast.Name):
        return [expr.name.upper()]
    if isinstance(expr, ast.Member):
        base = _path(expr.base)
        return None if base is None else base + [expr.member.upper()]
    if isinstance(expr, ast.Index):
        base = _path(expr.base)
        if base is None:
            return None
        return base + [i.value if isinstance(i, ast.IntLiteral) else _ANY for i in expr.indices]
    if isinstance(expr, ast.BitAccess):
        base = _path(expr.base)
        return None if base is None else base + [("bit", expr.bit)]
    if isinstance(expr, ast.Device):
        exact = expr.bit is None and expr.digits is None and expr.index is None
        return [("dev", expr.kind.upper(), _address(expr.address) if exact else _ANY, _module(expr.module))]
    return None


def _address(written: str) -> str:
    """A device address as written, compared as written (X10 is octal on an FX, hex on a
    Q: the same reading on both sides either way), leading zeros aside."""
    return written.upper().lstrip("0") or "0"


def _module(written: str | None) -> str | None:
    """A module number (U00\\G10's) as the simulator reads it: hexadecimal, U00 is U0."""
    return None if written is None else format(int(written, 16), "X")


def _root(expr: ast.Expr) -> list | None:
    """The whole variable (or any device of the kind) a reference belongs to."""
    path = _path(expr)
    if path is None:
        return None
    if isinstance(path[0], tuple):
        return [("dev", path[0][1], _ANY, path[0][3])]
    return path[:1]


def _index_expressions(expr: ast.Expr) -> list[ast.Expr]:
    found = []
    while isinstance(expr, (ast.Member, ast.Index, ast.BitAccess)):
        if isinstance(expr, ast.Index):
            found += expr.indices
        expr = expr.base
    if isinstance(expr, ast.Device) and expr.index is not None:  # D100Z0 reads the index register Z0
        found.append(ast.Device(kind="Z", address=str(expr.index), number=expr.index))
    return found


def _overlap(a: list, b: list) -> bool:
    """Whether two references may share a memory cell: one is a part of the other."""
    for x, y in zip(a, b):
        devices = [isinstance(v, tuple) and v[0] == "dev" for v in (x, y)]
        if any(devices):
            if not all(devices) or x[1] != y[1] or x[3] != y[3]:
                return False  # a label and a device (none is bound to one: first_overwrite), or two kinds
            if x[2] is not _ANY and y[2] is not _ANY and x[2] != y[2]:
                return False
            continue
        if isinstance(x, tuple) or isinstance(y, tuple):  # a bit of a word: part of it
            return not (isinstance(x, tuple) and isinstance(y, tuple) and x != y)
        if x is _ANY or y is _ANY:
            continue
        if x != y:
            return False
    return True


def overwritten_input_notes(scenario, files: list[ast.SourceFile], program: str, relative) -> list[str]:
    """A note for each label an `[[inputs]]` entry sets that the program overwrites in every
    scan before reading it, at the input's place, naming the ST place that overwrites it."""
    notes = []
    cwd = os.getcwd()
    texts = {f.filename: f.text for f in files}
    for step in scenario.inputs:
        key = f"{step.key}.set"
        for name, value in step.values.items():
            found = first_overwrite(files, program, name)
            if found is None:
                continue
            where = scenario.where(key, scenario.key_lines.get(f"{key}.{name}", scenario.key_lines.get(key)))
            span = found.span
            snippet = _snippet(texts.get(span.file, ""), span)
            shown = "true" if value is True else "false" if value is False else str(value)
            note = (f"{where}: {name} = {shown} does nothing: the program overwrites {name} in every scan before "
                    f"reading it, at {relative(str(span), cwd)}")
            if snippet:
                note += f" ({snippet})"
            source = _source(found, files, program, texts)
            if source is not None:
                note += f"; set {source} instead"
            notes.append(note)
    return notes


def _source(found: Overwrite, files: list[ast.SourceFile], program: str, texts: dict[str, str]) -> str | None:
    """The label or device the PROGRAM assigns to the input's label, as written, when an
    input could set that one instead (not one the program overwrites first in turn)."""
    if found.value is None or found.pou.kind != "PROGRAM":
        return None
    path = _path(found.value)
    if path is None or _ANY in path or any(isinstance(part, tuple) and part[0] == "bit" for part in path):
        return None
    if any(isinstance(part, str) for part in path[1:]):
        return None  # a member of an FB instance or structure (tmr.Q): the FB's next call may write it again
    if isinstance(path[0], str) and not _kept(path[0], found.pou, files):
        return None
    text = _snippet(texts.get(found.value.span.file, ""), found.value.span)
    if not text or first_overwrite(files, program, text) is not None:
        return None
    return text


def _kept(name: str, program: ast.Pou, files: list[ast.SourceFile]) -> bool:
    """Whether an input could set the label `name` (the PROGRAM's own, or else a global
    one) and the program keep it: not a constant (refused), nor a VAR_TEMP (set afresh at
    the start of every scan)."""
    declared = next((v for v in program.variables if v.name.upper() == name), None)
    if declared is None:
        declared = next((v for f in files for block in f.globals for v in block.variables
                         if v.name.upper() == name), None)
    return declared is None or not (declared.constant or declared.section == "VAR_TEMP")


def _snippet(text: str, span: ast.Span) -> str:
    """The source of `span` when it fits on one line (the statement or binding as written)."""
    if span.line != span.end_line or span.line < 1:
        return ""
    lines = text_lines(text)  # numbered as the parser numbers them (line feeds only)
    if span.line > len(lines):
        return ""
    return lines[span.line - 1][span.col - 1:span.end_col - 1].strip()
