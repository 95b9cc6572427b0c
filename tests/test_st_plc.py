"""Everything the PLC library ships in plc/ must be accepted by GX Works: no error from
`uitamr check` for either engineering tool the files are meant for."""
from __future__ import annotations

import pytest

from st_helpers import PLC_FILES, ROOT, diagnose
from verifier.st import parse

def platform_target(path) -> str | None:
    """gxworks3 for FX5 files, gxworks2 for FX3 and Q files, None for portable ones."""
    parts = [p.lower() for p in path.relative_to(ROOT / "plc").parts]
    if "fx5" in parts or "fx5" in path.stem.lower():
        return "gxworks3"
    if "fx3" in parts or "q" in parts or "fx3" in path.stem.lower():
        return "gxworks2"
    return None


def files_for(target: str):
    return [p for p in PLC_FILES if platform_target(p) in (None, target)]


def test_plc_library_exists():
    assert PLC_FILES, "plc/ has no .st files"


@pytest.mark.parametrize("target", ["gxworks2", "gxworks3"])
def test_plc_files_check_without_errors(target):
    files = files_for(target)
    _, diags = diagnose(*files, target=target)
    errors = [str(d) for d in diags if d.is_error]
    assert errors == []


@pytest.mark.parametrize("path", PLC_FILES, ids=lambda p: str(p.relative_to(ROOT / "plc")))
def test_each_plc_file_parses(path):
    source = parse(path.read_text(encoding="utf-8"), str(path))
    assert source.ok, [str(d) for d in source.diagnostics]
    assert len(source.pous) == 1, "one POU per file"
    assert source.pous[0].name == path.stem, "file named after its POU"
