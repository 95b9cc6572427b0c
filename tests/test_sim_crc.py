"""CRC computed by ST running in the simulator equals the Python reference
(verifier.protocol.crc16) on thousands of random frames."""
from __future__ import annotations

from pathlib import Path

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from sim_helpers import load_st
from verifier.protocol import crc16

ROOT = Path(__file__).resolve().parents[1]

ST_CRC = """
FUNCTION F_CRC : WORD
VAR_INPUT uData : ARRAY[0..255] OF WORD; wLen : INT; END_VAR
VAR wI, wJ : INT; uReg : WORD; END_VAR
uReg := 16#FFFF;
FOR wI := 0 TO wLen - 1 DO
    uReg := uReg XOR (uData[wI] AND 16#00FF);
    FOR wJ := 1 TO 8 DO
        IF (uReg AND 16#0001) <> 0 THEN
            uReg := SHR(uReg, 1) XOR 16#A001;
        ELSE
            uReg := SHR(uReg, 1);
        END_IF;
    END_FOR;
END_FOR;
F_CRC := uReg;
END_FUNCTION

FUNCTION_BLOCK FB_CRC_INSTR
VAR_INPUT uBuf : ARRAY[0..127] OF WORD; wLen : INT; END_VAR
VAR_OUTPUT uCrc : WORD; END_VAR
CRC(TRUE, uBuf[0], wLen, uCrc);
END_FUNCTION_BLOCK
"""


@pytest.fixture(scope="module")
def project():
    return load_st(ST_CRC)


@pytest.fixture(scope="module")
def library():
    """The PLC library's own CRC function, as shipped in plc/core."""
    path = ROOT / "plc" / "core" / "UITAMR_CRC16.st"
    return load_st(path.read_text(encoding="utf-8"), name=str(path))


frames = st.binary(min_size=1, max_size=256)


@settings(max_examples=2000, deadline=None)
@given(frames)
def test_st_crc_function_matches_reference(project, data):
    assert project.call("F_CRC", list(data), len(data)) == crc16(data)


@settings(max_examples=1000, deadline=None)
@given(frames)
def test_crc_instruction_matches_reference(project, data):
    fb = project.instance("FB_CRC_INSTR")
    padded = data + b"\0" * (len(data) % 2)
    fb.uBuf = [padded[i] | (padded[i + 1] << 8) for i in range(0, len(padded), 2)]
    fb.wLen = len(data)
    fb.scan()
    assert fb.uCrc == crc16(data)


@settings(max_examples=1000, deadline=None)
@given(st.binary(min_size=0, max_size=16))
def test_plc_library_crc_matches_reference(library, data):
    assert library.call("UITAMR_CRC16", list(data), len(data)) == crc16(data)
