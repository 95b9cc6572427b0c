"""`uitamr check SOURCES...`: parse and type-check GX Works structured text.

Prints each finding as `file:line:col: error|warning: message`, the source line and a
caret under the column. Exit status: 1 if any error, 0 otherwise (warnings allowed),
2 for usage errors (missing file, not a regular file, bad option). Every file is read and checked even when
another one is broken; POUs may use POUs from the other files given.
"""
from __future__ import annotations

import json
import sys
from pathlib import Path

import click

from verifier.st import TARGETS
from verifier.st.ast import Diagnostic, SourceFile

EXIT_OK, EXIT_ERRORS, EXIT_USAGE = 0, 1, 2


def expand_sources(sources: tuple[str, ...]) -> list[Path]:
    """Files named on the command line; directories give their *.st files (recursive)."""
    paths: list[Path] = []
    for s in sources:
        p = Path(s)
        if p.is_dir():
            paths.extend(sorted(p.rglob("*.st")))
        else:
            paths.append(p)
    return paths


def _not_a_source(path: Path) -> str | None:
    """Why `path` cannot be checked at all (missing, a device, a pipe ...), or None.
    Files that exist but hold no text are diagnosed with file:line:col instead."""
    from verifier.st import read_source

    if path.is_file():
        return None
    if not path.exists() and not path.is_symlink():
        return "no such file"
    problems = read_source(path)[1]
    return problems[0].message if problems else None


def check_paths(paths: list[Path], target: str) -> tuple[list[SourceFile], list[Diagnostic]]:
    """Parse every file and check them together; all diagnostics, parse ones included."""
    from verifier.st import check, parse, read_source

    files: list[SourceFile] = []
    diagnostics: list[Diagnostic] = []
    for p in paths:
        text, problems = read_source(p)
        diagnostics += problems
        if not problems:  # an unreadable file is reported once, not also as empty
            files.append(parse(text, str(p), target))
    diagnostics += [d for f in files for d in f.diagnostics]
    diagnostics += check(files, target)
    order = {str(p): i for i, p in enumerate(paths)}
    diagnostics.sort(key=lambda d: (order.get(d.file, len(order)), d.line, d.col))
    return files, diagnostics


def render(diag: Diagnostic, lines: list[str] | None) -> str:
    """The diagnostic line, then the source line and a caret (when the line exists)."""
    out = str(diag)
    if lines is not None and 1 <= diag.line <= len(lines):
        src = lines[diag.line - 1].rstrip("\r\n").expandtabs(1)
        width = 1
        if diag.end_line == diag.line and diag.end_col and diag.end_col > diag.col:
            width = diag.end_col - diag.col
        out += f"\n    {src}\n    {' ' * max(diag.col - 1, 0)}{'^' * min(width, max(1, len(src) - diag.col + 1))}"
    return out


@click.command(name="check")
@click.argument("sources", nargs=-1, required=True, type=click.Path())
@click.option("--target", type=click.Choice(TARGETS), default="gxworks2", show_default=True,
              help="Which engineering tool's dialect to accept.")
@click.option("--format", "fmt", type=click.Choice(["text", "json"]), default="text",
              show_default=True, help="Human text, or JSON for CI tools.")
def command(sources: tuple[str, ...], target: str, fmt: str) -> None:
    """Parse and type-check GX Works structured text (files or directories of .st)."""
    paths = expand_sources(sources)
    unusable = [(p, _not_a_source(p)) for p in paths]
    unusable = [(p, why) for p, why in unusable if why]
    if unusable:
        for p, why in unusable:
            click.echo(f"uitamr check: {p}: {why}", err=True)
        sys.exit(EXIT_USAGE)
    if not paths:
        click.echo("uitamr check: no .st files found in the given directories", err=True)
        sys.exit(EXIT_USAGE)
    files, diagnostics = check_paths(paths, target)
    errors = sum(d.is_error for d in diagnostics)
    warnings = len(diagnostics) - errors
    if fmt == "json":
        click.echo(json.dumps({
            "target": target,
            "files": [str(p) for p in paths],
            "errors": errors,
            "warnings": warnings,
            "diagnostics": [
                {"file": d.file, "line": d.line, "col": d.col, "end_line": d.end_line,
                 "end_col": d.end_col, "severity": d.severity, "message": d.message}
                for d in diagnostics
            ],
        }, indent=2))
    else:
        texts = {f.filename: f.text.splitlines() for f in files}
        for d in diagnostics:
            click.echo(render(d, texts.get(d.file)))
        click.echo(f"{len(paths)} file(s) checked for {target}: {errors} error(s), {warnings} warning(s)")
    sys.exit(EXIT_ERRORS if errors else EXIT_OK)
