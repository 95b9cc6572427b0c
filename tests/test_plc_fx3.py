"""FX3U specifics: the CRC-instruction variant of the CRC function, and the example still
passing its scenario when the library is switched over to it."""
from __future__ import annotations

import shutil
from pathlib import Path

import pytest
from hypothesis import given, settings as hsettings, strategies as st

import verifier
from verifier.protocol import crc16
from verifier.verify.runner import run_scenario
from verifier.verify.scenario import load_scenario

PLC = Path(__file__).resolve().parents[1] / "plc"


@pytest.fixture(scope="module")
def project():
    return verifier.load(PLC / "fx3" / "UITAMR_Crc16Fx3u.st", PLC / "core" / "UITAMR_CRC16.st", cpu="fx3u")


@hsettings(max_examples=100, deadline=None)
@given(st.binary(min_size=1, max_size=16))
def test_crc_instruction_variant_matches_the_protocol(project, data):
    assert project.call("UITAMR_Crc16Fx3u", list(data), len(data)) == crc16(data)
    assert project.call("UITAMR_Crc16Fx3u", list(data), len(data)) == project.call("UITAMR_CRC16", list(data), len(data))


def test_crc_instruction_variant_leaves_8_bit_mode_off(project):
    project.devices["M8161"] = False
    project.call("UITAMR_Crc16Fx3u", [1, 6, 1, 0xA0, 0, 0], 6)
    assert project.devices["M8161"] is False or project.devices["M8161"] == 0


def test_library_runs_with_the_crc_instruction(tmp_path):
    for folder in ("core", "fx3", "examples/common", "examples/fx3"):
        (tmp_path / folder).mkdir(parents=True)
        for src in (PLC / folder).glob("*.st"):
            text = src.read_text()
            if src.name != "UITAMR_CRC16.st":
                text = text.replace("UITAMR_CRC16(", "UITAMR_Crc16Fx3u(")
            (tmp_path / folder / src.name).write_text(text)
    assert "UITAMR_Crc16Fx3u(" in (tmp_path / "core" / "UITAMR_ParseReply.st").read_text()
    (tmp_path / "scenarios").mkdir()
    scenario = tmp_path / "scenarios" / "healthy.toml"
    shutil.copy(PLC / "scenarios" / "fx3u-healthy.toml", scenario)
    result = run_scenario(load_scenario(scenario))
    problems = [v.message for v in result.all_violations()[:5]] + [str(e) for e in result.failed_expectations]
    assert result.passed, "\n".join(problems)
