"""Shared helper of the tests that read the Markdown pages."""
from __future__ import annotations

import re


def code_blocks(text: str, kind: str = r"\w*") -> list[str]:
    """The bodies of the fenced code blocks of `text` whose info string matches `kind` (a
    regular expression: any language by default, "" for blocks with none, "python" ...)."""
    return re.findall(rf"```{kind}\n(.*?)```", text, flags=re.S)
