"""docs/protocol.md stays true: its frames, CRCs and `uitamr frame` sessions are re-run here."""
from __future__ import annotations

import re
import shlex
from pathlib import Path

from click.testing import CliRunner

from doc_helpers import code_blocks
from verifier.cli import main
from verifier.protocol import Settings, command_from_words, crc_ok, encode, hex_bytes

DOC = Path(__file__).resolve().parents[1] / "docs" / "protocol.md"
TEXT = DOC.read_text(encoding="utf-8")
HEX_FRAME = re.compile(r"`((?:[0-9A-F]{2} ){4,}[0-9A-F]{2})`")
SETTING = re.compile(r'`(\w+)="([\w-]+)"`')


def table_rows():
    for line in TEXT.splitlines():
        if line.startswith("|") and not line.startswith("|---"):
            yield [cell.strip() for cell in line.strip("|").split("|")]


def test_every_frame_in_the_doc_has_a_good_crc():
    frames = HEX_FRAME.findall(TEXT)
    assert len(frames) > 50
    for text in frames:
        assert crc_ok(bytes.fromhex(text)), text


def test_command_tables_match_the_encoder():
    checked = 0
    for cells in table_rows():
        if len(cells) == 3 and cells[0].startswith("`") and not SETTING.fullmatch(cells[0]) \
                and HEX_FRAME.fullmatch(cells[2]):
            words = cells[0].strip("`").split()
            assert hex_bytes(encode(command_from_words(words), Settings())) == cells[2].strip("`"), cells
            checked += 1
    assert checked >= 37  # every control command row and the four reads


def test_settings_table_matches_the_encoder():
    checked = 0
    for cells in table_rows():
        setting = SETTING.fullmatch(cells[0]) if cells else None
        if len(cells) == 3 and setting and HEX_FRAME.fullmatch(cells[2]):
            settings = Settings(**{setting.group(1): setting.group(2)})
            words = cells[1].strip("`").split()
            assert hex_bytes(encode(command_from_words(words), settings)) == cells[2].strip("`"), cells
            checked += 1
    assert checked == 5


def sessions():
    """(argv, expected output) for each `$ uitamr frame ...` in the doc's code blocks."""
    for block in code_blocks(TEXT, ""):
        lines = block.splitlines()
        for index, line in enumerate(lines):
            if line.startswith("$ uitamr frame"):
                output = []
                for following in lines[index + 1:]:
                    if following.startswith("$ "):
                        break
                    output.append(following)
                yield shlex.split(line[2:])[1:], output


def test_cli_sessions_in_the_doc_are_what_the_cli_prints():
    runs = list(sessions())
    assert len(runs) >= 7
    for argv, expected in runs:
        result = CliRunner().invoke(main, argv)
        assert result.output.splitlines() == expected, argv


def test_documented_error_messages_are_real():
    from verifier.protocol import FrameError, decode_request, with_crc
    block = TEXT.split("Errors name exactly what is wrong, for example:")[1].split("```")[1]
    samples = {
        "byte 6: too short": bytes.fromhex("01 06 01 A0 00 01"),
        "byte 6: bad CRC": bytes.fromhex("01 06 01 A0 00 00 88 15"),
        "byte 1: unknown function": with_crc(bytes.fromhex("01 03 00 00 00 01")),
        "byte 5: quantity": with_crc(bytes.fromhex("01 01 00 00 00 08")),
        "byte 5: value field": with_crc(bytes.fromhex("01 06 01 A0 00 01")),
        "byte 3: unknown robot command": with_crc(bytes.fromhex("01 06 01 20 00 00")),
        "byte 3: value 32": with_crc(bytes.fromhex("01 06 02 20 00 00")),
        "byte 3: unknown control code 0xA0": bytes.fromhex("01 06 01 A0 00 00 88 14"),
    }
    documented = [line for line in block.splitlines() if line.strip()]
    assert len(documented) == len(samples)
    for line, (prefix, data) in zip(documented, samples.items()):
        assert line.startswith(prefix)
        settings = Settings(field_order="code-low") if "code-low" in line else Settings()
        try:
            decode_request(data, settings)
        except FrameError as err:
            assert str(err) == line
        else:
            raise AssertionError(f"{data.hex()} decoded without error")
