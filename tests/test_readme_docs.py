"""README.zh-TW.md says what README.md says: the same commands, options, frames, pages and
figures. The two drifted once (the Chinese one linked verifier.md and st-dialect.md, which
the English one did not, and named the robot's errors otherwise than `uitamr frame` prints
them); these tests compare what can be compared without reading Chinese."""
from __future__ import annotations

import re
from pathlib import Path

from doc_helpers import code_blocks
from verifier.amr.faults import FAULT_KINDS
from verifier.protocol.catalogue import ERROR_TITLES, RobotError
from verifier.verify.rules import RULES

ROOT = Path(__file__).resolve().parents[1]
EN = (ROOT / "README.md").read_text(encoding="utf-8")
ZH = (ROOT / "README.zh-TW.md").read_text(encoding="utf-8")
READMES = {"README.md": EN, "README.zh-TW.md": ZH}


def _pages(text: str) -> set[str]:
    """The files the README links to (anchors dropped), but for the two READMEs themselves."""
    targets = {t.split("#", 1)[0] for t in re.findall(r"\]\(([^)\s]+)\)", text) if not t.startswith("http")}
    return targets - {"README.md", "README.zh-TW.md"}


def _options(text: str) -> set[str]:
    return set(re.findall(r"--[a-z][a-z0-9-]*", text))


def _subcommands(text: str) -> set[str]:
    return set(re.findall(r"`uitamr ([a-z]+)", text))


def _frames(text: str) -> set[str]:
    return set(re.findall(r"(?:[0-9A-F]{2} ){4,}[0-9A-F]{2}", text))


def _hex_words(text: str) -> set[str]:
    """Four-digit hex values with a letter (the manual's placeholder CRCs, 68AA ...), but for
    the function codes FC01 and FC06, which the Chinese text calls 功能碼 01 and 06."""
    return set(re.findall(r"\b(?=[0-9]*[A-F])[0-9A-F]{4}\b", text)) - {"FC01", "FC06"}


def _versions(text: str) -> set[str]:
    """Numbers with a decimal point: the Python version and the manual's (V2.05)."""
    return set(re.findall(r"(?<![\d.])\d+\.\d+(?![\d.])", text))


def test_the_same_commands_are_shown():
    assert code_blocks(ZH) == code_blocks(EN)
    assert _subcommands(ZH) == _subcommands(EN)
    assert _options(ZH) == _options(EN)


def test_the_same_pages_are_linked():
    assert _pages(ZH) == _pages(EN), (f"only in README.md: {sorted(_pages(EN) - _pages(ZH))}; "
                                      f"only in README.zh-TW.md: {sorted(_pages(ZH) - _pages(EN))}")
    for page in _pages(EN):
        assert (ROOT / page).exists(), page


def test_the_same_frames_and_figures():
    assert _frames(ZH) == _frames(EN)
    assert _hex_words(ZH) == _hex_words(EN)
    assert _versions(ZH) == _versions(EN), (f"only in README.md: {sorted(_versions(EN) - _versions(ZH))}; "
                                            f"only in README.zh-TW.md: {sorted(_versions(ZH) - _versions(EN))}")
    assert len(RULES) == 8
    assert "the eight rules of `verify`" in EN and "`verify` 的八條規則" in ZH


def test_the_manuals_error_codes_go_by_the_names_the_tool_prints():
    """The glossary of the manual's terms: its error codes are named as `uitamr frame
    --decode` and the emulator's log name them, and as fault files spell them."""
    for name, text in READMES.items():
        glossary = text.split("錯誤代碼 01", 1)
        assert len(glossary) == 2, f"{name} has no glossary row for the error codes"
        row = glossary[1].split("\n", 1)[0]
        for error in (RobotError.ANTI_COLLISION, RobotError.OFF_TAPE, RobotError.BATTERY_LOW):
            assert ERROR_TITLES[error] in row, (name, ERROR_TITLES[error])
        for kind in ("anti_collision", "off_tape", "low_battery"):
            assert kind in FAULT_KINDS and f"`{kind}`" in row, (name, kind)


def test_each_readme_links_the_other():
    """A reader who lands on either README can reach the other: README.md ends with the
    Chinese one's link, and README.zh-TW.md had no way back to the English one."""
    assert "](README.zh-TW.md)" in EN
    assert "](README.md)" in ZH
