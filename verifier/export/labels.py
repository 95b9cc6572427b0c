"""Label rows from a POU's declarations: class, name, type, constant value, comment."""
from __future__ import annotations

import re
from dataclasses import dataclass

from verifier.st import ast
from verifier.export.types import type_name
from verifier.textfile import text_lines

_COMMENT = re.compile(r"\(\*(.*?)\*\)|//(.*)$")


@dataclass(frozen=True)
class LabelRow:
    label_class: str   # VAR, VAR_CONSTANT, VAR_INPUT, VAR_OUTPUT, VAR_IN_OUT, ...
    name: str
    data_type: str     # in the editor's own words
    initial: str       # initial value as written ("" when none)
    constant: str      # the value of a VAR_CONSTANT label ("" otherwise)
    comment: str
    device: str = ""   # the device a global label is assigned to (`AT X0`)


def label_class(decl: ast.VarDecl) -> str:
    if decl.constant:
        return "VAR_GLOBAL_CONSTANT" if decl.section == "VAR_GLOBAL" else "VAR_CONSTANT"
    if decl.retain and decl.section in ("VAR", "VAR_OUTPUT", "VAR_PUBLIC"):
        return f"{decl.section}_RETAIN"
    return decl.section


def trailing_comment(lines: list[str], decl: ast.VarDecl) -> str:
    """The comment written after the declaration on its own line, if any."""
    line = decl.span.end_line or decl.span.line
    if not 1 <= line <= len(lines):
        return ""
    text = lines[line - 1][decl.span.end_col - 1:] if decl.span.end_line else lines[line - 1]
    m = _COMMENT.search(text)
    if m:
        return " ".join((m.group(1) or m.group(2) or "").split())
    start = text.find("(*")
    if start < 0:
        return ""
    # a comment begun after the declaration and closed on a later line: a label comment is
    # one line in the editors, so its lines are joined (it was dropped)
    following = "\n".join([text[start + 2:]] + lines[line:])
    end = following.find("*)")
    return " ".join(following[:end].split()) if end >= 0 else ""


def initial_text(source_text: str, lines: list[str], decl: ast.VarDecl) -> str:
    """The initial value exactly as written in the source (`16#A0`, `T#300ms`)."""
    init = decl.init
    if init is None or init.span.line < 1:
        return ""
    s = init.span
    if s.line == s.end_line:
        return lines[s.line - 1][s.col - 1:s.end_col - 1].strip()
    parts = [lines[s.line - 1][s.col - 1:]] + lines[s.line:s.end_line - 1] + [lines[s.end_line - 1][:s.end_col - 1]]
    return " ".join(" ".join(parts).split())


def label_rows(pou: ast.Pou, source_text: str, target: str) -> list[LabelRow]:
    """The rows of a POU's label table. Neither editor has a VAR_EXTERNAL class (GX Works3:
    MELSEC iQ-F FX5 Programming Manual (Program Design) §4.2; GX Works2: MELSEC-Q/L/F
    Structured Programming Manual (Fundamentals), Table 4.3.3-1): a POU uses a global label
    by its name, so its VAR_EXTERNAL declarations, which the check matched against the
    VAR_GLOBAL blocks, are no rows of it: the globals are in the global label table."""
    return rows_of([d for d in pou.variables if d.section != "VAR_EXTERNAL"], source_text, target)


def rows_of(decls: list[ast.VarDecl], source_text: str, target: str) -> list[LabelRow]:
    lines = text_lines(source_text)
    rows = []
    for decl in decls:
        value = initial_text(source_text, lines, decl)
        rows.append(LabelRow(
            label_class=label_class(decl),
            name=decl.name,
            data_type=type_name(decl.type, target),
            initial="" if decl.constant else value,
            constant=value if decl.constant else "",
            comment=trailing_comment(lines, decl),
            device=decl.at.text if decl.at is not None else "",
        ))
    return rows
