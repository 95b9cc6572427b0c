"""The machine-readable outputs of `uitamr check`: JSON, GitHub Actions annotations, SARIF.

Pure functions from diagnostics to text; the command prints them. Every diagnostic
carries a rule id (`Finding.rule`) so SARIF viewers (GitHub code scanning, the VS Code
SARIF viewer) can group them:

| rule | what |
|---|---|
| `UITAMR-ST-SOURCE` | a file that cannot be read as ST text (encoding, binary) |
| `UITAMR-ST-SYNTAX` | the parser's findings: syntax, literals, comment styles |
| `UITAMR-ST-CHECK` | the checker's errors: types, labels, GX Works rules |
| `UITAMR-ST-WARNING` | the checker's warnings (unused labels, ...) |
| `UITAMR-SCENARIO` | a scenario file (`.toml`) that `uitamr verify` would refuse |
| `UITAMR-ST-CPU` | with `--platform` only: a device or instruction that CPU does not have |
"""
from __future__ import annotations

import json
import os
from dataclasses import dataclass
from pathlib import Path
from urllib.parse import quote

from verifier.st.ast import Diagnostic
from verifier.textfile import reached_path, shown_path

TOOL_NAME = "uitamr check"
SARIF_SCHEMA = "https://json.schemastore.org/sarif-2.1.0.json"

RULES = {
    "UITAMR-ST-SOURCE": "The file cannot be read as ST text",
    "UITAMR-ST-SYNTAX": "ST syntax: the text does not parse as GX Works structured text",
    "UITAMR-ST-CHECK": "ST check: types, labels and GX Works rules",
    "UITAMR-ST-WARNING": "ST check warning",
    "UITAMR-SCENARIO": "Scenario file: a key or value uitamr verify refuses",
}
#: the rules of `uitamr check --platform` (listed only when it is given, so the output
#: without it stays what it was)
PLATFORM_RULES = {
    "UITAMR-ST-CPU": "CPU: a device or instruction the --platform CPU does not have (as uitamr verify loads it)",
}


@dataclass(frozen=True)
class Finding:
    """A diagnostic and the rule it comes under."""

    diagnostic: Diagnostic
    rule: str


def relative(file: str) -> str:
    """The path as CI annotations want it: relative to the working directory (the
    repository root in a CI job) when it lies below it, as reached (a symlinked
    vendor/uitamr stays vendor/uitamr/...: textfile.shown_path, as the reports show paths),
    with forward slashes; one outside it absolute, however it was given (`../lib/b.st` is
    as much outside as `/abs/lib/b.st`)."""
    cwd = os.getcwd()
    shown = Path(shown_path(file, cwd))
    if not shown.is_absolute() and Path(os.path.normpath(shown)).parts[:1] == ("..",):
        shown = reached_path(file, cwd)
    return shown.as_posix()


def to_json(findings: list[Finding], target: str, files: list[str], platform: str | None = None) -> str:
    errors = sum(f.diagnostic.is_error for f in findings)
    return json.dumps({
        "target": target,
        **({"platform": platform} if platform else {}),
        "files": files,
        "errors": errors,
        "warnings": len(findings) - errors,
        "diagnostics": [
            {"file": d.file, "line": d.line, "col": d.col, "end_line": d.end_line,
             "end_col": d.end_col, "severity": d.severity, "message": d.message, "rule": f.rule}
            for f in findings for d in (f.diagnostic,)
        ],
    }, indent=2)


def _escape_data(text: str) -> str:
    return text.replace("%", "%25").replace("\r", "%0D").replace("\n", "%0A")


def _escape_property(text: str) -> str:
    return _escape_data(text).replace(":", "%3A").replace(",", "%2C")


def to_github(findings: list[Finding]) -> str:
    """GitHub Actions workflow commands: `::error file=F,line=L,col=C,title=T::message`,
    shown inline on the pull request's changed files."""
    out = []
    for f in findings:
        d = f.diagnostic
        level = "error" if d.is_error else "warning"
        props = [f"file={_escape_property(relative(d.file))}"]
        if d.line >= 1:
            props.append(f"line={d.line}")
            if d.col >= 1:
                props.append(f"col={d.col}")
            if d.end_line and d.end_line >= d.line:
                props.append(f"endLine={d.end_line}")
                if d.end_col and d.end_line == d.line and d.end_col > d.col:
                    props.append(f"endColumn={d.end_col}")
        props.append(f"title={_escape_property(f'{TOOL_NAME} {f.rule}')}")
        out.append(f"::{level} {','.join(props)}::{_escape_data(d.message)}")
    return "\n".join(out)


def _artifact(file: str) -> dict:
    """A SARIF artifactLocation: a URI reference (percent-encoded: spaces, '%', non-ASCII
    letters, ':'), relative to %SRCROOT% below the working directory, else an absolute
    file: URI without a base (SARIF 2.1.0 §3.4.4)."""
    path = relative(file)
    if Path(path).is_absolute():
        return {"uri": Path(path).as_uri()}
    # the name's own bytes (os.fsencode), as Path.as_uri quotes them: a name that is not UTF-8
    # (b"\xfe.st", its bytes as lone surrogates) could not be encoded and ended in a traceback
    return {"uri": quote(os.fsencode(path), safe="/"), "uriBaseId": "%SRCROOT%"}


def to_sarif(findings: list[Finding], version: str, rules: dict[str, str] = RULES) -> str:
    """SARIF 2.1.0, one run, for GitHub code scanning (upload-sarif) and SARIF viewers;
    `rules` are those the run lists (RULES, and PLATFORM_RULES with --platform)."""
    used = sorted({f.rule for f in findings} | set(rules))
    index = {rule: i for i, rule in enumerate(used)}
    results = []
    for f in findings:
        d = f.diagnostic
        location: dict = {"artifactLocation": _artifact(d.file)}
        if d.line >= 1:
            region = {"startLine": d.line, "startColumn": max(d.col, 1)}
            if d.end_line and d.end_line >= d.line and d.end_col:
                region["endLine"] = d.end_line
                region["endColumn"] = d.end_col
            location["region"] = region
        results.append({
            "ruleId": f.rule,
            "ruleIndex": index[f.rule],
            "level": "error" if d.is_error else "warning",
            "message": {"text": d.message},
            "locations": [{"physicalLocation": location}],
        })
    sarif = {
        "$schema": SARIF_SCHEMA,
        "version": "2.1.0",
        "runs": [{
            "tool": {"driver": {
                "name": TOOL_NAME,
                "version": version,
                "rules": [{"id": rule, "name": rule.title().replace("-", ""),
                           "shortDescription": {"text": rules.get(rule, rule)}} for rule in used],
            }},
            "columnKind": "unicodeCodePoints",
            "originalUriBaseIds": {"%SRCROOT%": {"uri": Path.cwd().resolve().as_uri() + "/"}},
            "results": results,
        }],
    }
    return json.dumps(sarif, indent=2)
