"""Shared helpers of the ST front-end tests (corpus locations, expectation reading)."""
from __future__ import annotations

import re
from pathlib import Path

from verifier.st import check, parse

ROOT = Path(__file__).resolve().parent.parent
CORPUS = ROOT / "tests" / "corpus"
VALID = sorted((CORPUS / "valid").glob("*.st"))
INVALID = sorted((CORPUS / "invalid").glob("*.st"))
PLC_FILES = sorted((ROOT / "plc").rglob("*.st"))

_EXPECT = re.compile(r"\(\* expect (\d+):(\d+) (error|warning): (.*?) \*\)")


def target_of(path: Path) -> str:
    """Corpus files named gx3_* use GX Works3-only features."""
    return "gxworks3" if path.name.startswith("gx3_") else "gxworks2"


def expectations(text: str) -> list[tuple[int, int, str, str]]:
    """(line, col, severity, message part) from the file's `(* expect ... *)` lines."""
    return [(int(m[1]), int(m[2]), m[3], m[4]) for m in _EXPECT.finditer(text)]


def diagnose(*paths: Path, target: str = "gxworks2"):
    """Parse and check files together; every diagnostic, parse ones first."""
    files = [parse(p.read_text(encoding="utf-8"), str(p), target) for p in paths]
    return files, [d for f in files for d in f.diagnostics] + check(files, target)


#: the valid corpus and the PLC library as text: seeds for mutation tests
SEEDS = [p.read_text(encoding="utf-8") for p in VALID + PLC_FILES]
#: pieces of ST syntax that break a program when dropped into it (fuzz tests)
TOKENS = ["IF", "THEN", "END_IF", ";", ":=", "=>", "(", ")", "[", "]", "(*", "*)", "'", '"',
          "VAR", "END_VAR", "FUNCTION_BLOCK", "END_FUNCTION", "..", ".", ",", "#", "16#",
          "T#", "K4M0", "D0.F", "U0\\G", "NOT", "**", "\n", "$", "MOV(", "TON", ":", "ARRAY"]
