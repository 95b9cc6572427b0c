"""The corpus: valid ST is accepted without a finding; each rejected construct gets
exactly the diagnostics written in its file, at the right line and column."""
from __future__ import annotations

import pytest

from st_helpers import CORPUS, INVALID, VALID, diagnose, expectations, target_of

SINGLE_VALID = [p for p in VALID if not p.name.startswith("multi_file_")]


@pytest.mark.parametrize("path", SINGLE_VALID, ids=lambda p: p.name)
def test_valid_file_has_no_findings(path):
    _, diags = diagnose(path, target=target_of(path))
    assert [str(d) for d in diags] == []


def test_pou_may_use_pous_of_other_files():
    a, b = CORPUS / "valid" / "multi_file_a.st", CORPUS / "valid" / "multi_file_b.st"
    _, together = diagnose(a, b)
    assert [str(d) for d in together] == []
    _, alone = diagnose(a)
    messages = [d.message for d in alone if d.is_error]
    assert any("unknown type 'FB_MultiB'" in m for m in messages)
    assert any("unknown function or instruction 'Twice'" in m for m in messages)


def test_whole_valid_corpus_checks_together_for_gxworks3():
    _, diags = diagnose(*VALID, target="gxworks3")
    assert [str(d) for d in diags] == []


@pytest.mark.parametrize("path", INVALID, ids=lambda p: p.name)
def test_invalid_file_gets_exactly_the_expected_diagnostics(path):
    expected = expectations(path.read_text(encoding="utf-8"))
    assert expected, f"{path.name} has no (* expect ... *) line"
    _, diags = diagnose(path, target=target_of(path))
    unmatched = list(diags)
    for line, col, severity, part in expected:
        hit = next((d for d in unmatched
                    if (d.line, d.col, d.severity) == (line, col, severity) and part in d.message), None)
        assert hit is not None, (f"missing {line}:{col} {severity}: {part!r}; got:\n"
                                 + "\n".join(str(d) for d in diags))
        unmatched.remove(hit)
    assert [str(d) for d in unmatched] == [], "unexpected extra diagnostics"
    assert all(d.file == str(path) for d in diags)


def test_gxworks3_accepts_what_gxworks2_rejects():
    gx3 = CORPUS / "valid" / "gx3_only.st"
    _, as_gx2 = diagnose(gx3, target="gxworks2")
    messages = " | ".join(d.message for d in as_gx2)
    assert "does not accept // comments" in messages
    assert "does not accept /* */ comments" in messages
    _, as_gx3 = diagnose(gx3, target="gxworks3")
    assert as_gx3 == []
