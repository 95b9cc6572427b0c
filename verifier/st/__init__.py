"""Structured-text front end for the GX Works dialect: parse, check, print.

    from verifier import st
    text, problems = st.read_source("FB_X.st")   # UTF-8, else Shift-JIS; never raises
    source = st.parse(text, "FB_X.st", target="gxworks2")   # never raises for bad input
    diagnostics = st.check([source], target="gxworks2")

The AST is in `verifier.st.ast`; the type system in `verifier.st.types`.
"""
from __future__ import annotations

# The submodule `verifier.st.check` shares its name with the function `check` below:
# import it first so that the function, defined afterwards, is what `verifier.st.check`
# names on the package.
import verifier.st.check as _check_module  # noqa: E402,F401
from verifier.st.ast import Diagnostic, SourceFile
from verifier.st.source import read_source

TARGETS = ("gxworks2", "gxworks3")

__all__ = ["Diagnostic", "SourceFile", "TARGETS", "parse", "check", "format_source", "read_source"]


def parse(text: str, filename: str = "<string>", target: str = "gxworks2") -> SourceFile:
    """Read ST text into an `ast.SourceFile`; syntax errors become diagnostics."""
    from verifier.st.parser import parse as _parse

    return _parse(text, filename, target)


def check(files: list[SourceFile], target: str = "gxworks2", platform: str | None = None) -> list[Diagnostic]:
    """Semantic check of parsed files together (a POU may use POUs of other files).
    Annotates the trees in place (expression types, resolved names and calls).
    `platform` (fx3u, fx3g, fx5u, q): also refuse labels named like an instruction of that
    CPU; None: like one of any CPU the target's editor programs (docs/st-dialect.md §4)."""
    from verifier.st.check import check as _check

    return _check(files, target, platform)


def format_source(source: SourceFile) -> str:
    """Readable ST text of a parsed file (see `verifier.st.printer`)."""
    from verifier.st.printer import print_source

    return print_source(source)
