"""The part of a POU that goes into the GX Works ST editor: its header comment and its
statements, without the declarations (they go into the label table)."""
from __future__ import annotations

import re

from verifier.st import ast
from verifier.textfile import text_lines

_END_POU = re.compile(r"^\s*END_(FUNCTION_BLOCK|FUNCTION|PROGRAM)\b.*$", re.IGNORECASE)
_START_POU = re.compile(r"^\s*(FUNCTION_BLOCK|FUNCTION|PROGRAM)\b", re.IGNORECASE)


def header_comment(lines: list[str], pou: ast.Pou) -> list[str]:
    """Comment lines right above the POU keyword (the library's header block)."""
    start = pou.span.line - 1
    first = start
    while first > 0 and lines[first - 1].strip() and not _START_POU.match(lines[first - 1]) \
            and not _END_POU.match(lines[first - 1]):
        first -= 1
    block = lines[first:start]
    return block if "".join(block).lstrip().startswith(("(*", "//")) else []


def body_text(pou: ast.Pou, source_text: str) -> str:
    """Header comment + statements of `pou`, ready to paste into the ST editor."""
    lines = text_lines(source_text)
    if pou.var_blocks:
        after = max((b.span.end_line, b.span.end_col) for b in pou.var_blocks)
        begin_line, begin_col = after
    else:
        head = lines[pou.span.line - 1]
        begin_line, begin_col = pou.span.line, len(head) + 1
    end_line = pou.span.end_line if pou.span.end_line else len(lines)
    body = [lines[begin_line - 1][begin_col - 1:]] + lines[begin_line:end_line]
    while body and (not body[-1].strip() or _END_POU.match(body[-1])):
        body.pop()
    while body and not body[0].strip():
        body.pop(0)
    header = header_comment(lines, pou)
    text = "\n".join(header + ([""] if header else []) + body)
    return text.rstrip() + "\n"
