"""The platform-neutral PLC library (plc/core) run in the simulator: the CRC function, the
frame builders and the reply parser against verifier.protocol, the one source of truth.
"""
from __future__ import annotations

from pathlib import Path

import pytest
from hypothesis import given, settings as hsettings, strategies as st

import verifier
from verifier.protocol import (
    ControlRequest, ExceptionReply, Settings, StatusReply, StatusRequest, crc16, encode, with_crc,
)

ROOT = Path(__file__).resolve().parents[1]
CORE = ROOT / "plc" / "core"

HARNESS = """
PROGRAM T_Frames
VAR
    fbCtl : UITAMR_BuildControl;
    fbSts : UITAMR_BuildStatus;
    fbParse : UITAMR_ParseReply;
    uFrame : ARRAY[0..15] OF WORD;
    uReply : ARRAY[0..15] OF WORD;
    wAddress : INT;
    wCode : INT;
    wCommand : INT;
    wQuery : INT;
    wFunction : INT;
    wLen : INT;
    wWhat : INT;
END_VAR
IF wWhat = 1 THEN
    fbCtl(i_bEN := TRUE, i_wAddress := wAddress, i_wCode := wCode, i_wCommand := wCommand, io_uFrame := uFrame);
ELSIF wWhat = 2 THEN
    fbSts(i_bEN := TRUE, i_wAddress := wAddress, i_wQuery := wQuery, io_uFrame := uFrame);
ELSIF wWhat = 3 THEN
    fbParse(i_bEN := TRUE, i_wAddress := wAddress, i_wFunction := wFunction, i_wLen := wLen, io_uReply := uReply);
END_IF;
END_PROGRAM
"""


def _project(replace: dict[str, tuple[str, str]] | None = None):
    """The core library plus a harness; `replace` edits one file's text (file -> (old, new))."""
    sources = {"T_Frames.st": HARNESS}
    for name, (old, new) in (replace or {}).items():
        text = (CORE / name).read_text()
        assert old in text, f"{old!r} not in {name}"
        sources[str(CORE / name)] = text.replace(old, new)
    return verifier.load(CORE, sources=sources)


@pytest.fixture(scope="module")
def project():
    return _project()


@pytest.fixture(scope="module")
def harness(project):
    return project.program("T_Frames")


def build_control(h, address, code, command) -> tuple[bytes, object]:
    h.wWhat, h.wAddress, h.wCode, h.wCommand = 1, address, code, command
    h.scan()
    fb = h.fbCtl
    return bytes(h.uFrame[i] for i in range(fb.o_wLen)), fb


def build_status(h, address, query) -> tuple[bytes, object]:
    h.wWhat, h.wAddress, h.wQuery = 2, address, query
    h.scan()
    fb = h.fbSts
    return bytes(h.uFrame[i] for i in range(fb.o_wLen)), fb


def parse(h, data: bytes, function: int, address: int = 1):
    for i in range(16):
        h.uReply[i] = data[i] if i < len(data) else 0
    h.wWhat, h.wAddress, h.wFunction, h.wLen = 3, address, function, len(data)
    h.scan()
    return h.fbParse


# ---------------------------------------------------------------------------- CRC
def test_crc_of_the_manuals_stop_frame(project):
    assert project.call("UITAMR_CRC16", [0x01, 0x06, 0x01, 0xA0, 0x00, 0x00], 6) == 0x1488


@hsettings(max_examples=150, deadline=None)
@given(st.binary(min_size=0, max_size=16))
def test_crc_function_matches_protocol_crc16(project, data):
    assert project.call("UITAMR_CRC16", list(data), len(data)) == crc16(data)


@hsettings(max_examples=50, deadline=None)
@given(st.binary(min_size=1, max_size=16), st.integers(min_value=1, max_value=255))
def test_crc_ignores_the_high_byte_of_each_element(project, data, high):
    words = [b | (high << 8) for b in data]
    assert project.call("UITAMR_CRC16", words, len(data)) == crc16(data)


def test_crc_clamps_the_length(project):
    data = bytes(range(16))
    assert project.call("UITAMR_CRC16", list(data), 40) == crc16(data)
    assert project.call("UITAMR_CRC16", list(data), -3) == crc16(b"")


# ---------------------------------------------------------------------------- builders
@hsettings(max_examples=150, deadline=None)
@given(st.integers(1, 247), st.integers(1, 13), st.integers(0, 255))
def test_control_builder_matches_protocol_encode(harness, address, code, command):
    frame, fb = build_control(harness, address, code, command)
    assert fb.o_bOK and not fb.o_bErr and fb.o_uErrId == 0
    assert frame == encode(ControlRequest(address, code, command), Settings(address=address), strict=False)


@pytest.mark.parametrize("address,code,command", [(0, 1, 0xA0), (248, 1, 0xA0), (1, 0, 0), (1, 14, 0),
                                                  (1, 1, -1), (1, 1, 256)])
def test_control_builder_rejects_out_of_range(harness, address, code, command):
    _, fb = build_control(harness, address, code, command)
    assert fb.o_bErr and not fb.o_bOK and fb.o_uErrId == 0x0301 and fb.o_wLen == 0


@pytest.mark.parametrize("query", [0, 1, 2, 3])
@pytest.mark.parametrize("address", [1, 17, 247])
def test_status_builder_matches_protocol_encode(harness, address, query):
    frame, fb = build_status(harness, address, query)
    assert fb.o_bOK
    assert frame == encode(StatusRequest(address, query), Settings(address=address))


@pytest.mark.parametrize("query", [-1, 4])
def test_status_builder_rejects_unknown_queries(harness, query):
    _, fb = build_status(harness, 1, query)
    assert fb.o_bErr and fb.o_uErrId == 0x0301


def test_field_order_choice_is_one_constant():
    """Flipping FIELD_ORDER_CODE_HIGH gives the manual's other reading, as the protocol does."""
    project = _project({"UITAMR_BuildControl.st": ("FIELD_ORDER_CODE_HIGH : BOOL := TRUE",
                                                   "FIELD_ORDER_CODE_HIGH : BOOL := FALSE")})
    h = project.program("T_Frames")
    for code, command in [(1, 0xA0), (2, 3), (12, 40)]:
        frame, _ = build_control(h, 1, code, command)
        assert frame == encode(ControlRequest(1, code, command), Settings(field_order="code-low"), strict=False)


def test_codes_10_13_choice_is_one_constant():
    project = _project({"UITAMR_BuildControl.st": ("CODES_10_13_HEX : BOOL := FALSE",
                                                   "CODES_10_13_HEX : BOOL := TRUE")})
    h = project.program("T_Frames")
    for code in range(1, 14):
        frame, _ = build_control(h, 1, code, 5)
        assert frame == encode(ControlRequest(1, code, 5), Settings(codes_10_13="hex"), strict=False)
    assert build_control(h, 1, 10, 5)[0][2] == 0x10


def test_status_order_choice_is_one_constant():
    project = _project({"UITAMR_BuildStatus.st": ("STATUS_ORDER_RETURN : BOOL := FALSE",
                                                  "STATUS_ORDER_RETURN : BOOL := TRUE")})
    h = project.program("T_Frames")
    for query in range(4):
        frame, _ = build_status(h, 1, query)
        assert frame == encode(StatusRequest(1, query), Settings(status_order="return"))


# ---------------------------------------------------------------------------- parser
@hsettings(max_examples=80, deadline=None)
@given(st.integers(1, 247), st.integers(0, 3), st.integers(0, 255))
def test_parser_reads_status_replies(harness, address, error, value):
    reply = encode(StatusReply(address, error, value), Settings(address=address), strict=False)
    fb = parse(harness, reply, 1, address)
    assert fb.o_bOK and not fb.o_bErr and fb.o_uErrId == 0
    assert (fb.o_wRobotErr, fb.o_wValue) == (error, value)


def test_parser_accepts_the_fc06_echo(harness):
    echo = bytes.fromhex("01 06 01 A0 00 00 88 14")
    assert parse(harness, echo, 6).o_bOK


@pytest.mark.parametrize("code", [1, 2, 3, 4, 6])
def test_parser_reports_exceptions_with_their_code(harness, code):
    frame = encode(ExceptionReply(1, 6, code), Settings())
    fb = parse(harness, frame, 6)
    assert fb.o_bErr and fb.o_bException and fb.o_uErrId == 0x0103 and fb.o_uDetail == code


def test_parser_rejects_a_bad_crc(harness):
    reply = bytearray(encode(StatusReply(1, 0, 1), Settings()))
    reply[-1] ^= 0x55
    fb = parse(harness, bytes(reply), 1)
    assert fb.o_bErr and fb.o_uErrId == 0x0102


def test_parser_rejects_another_address(harness):
    reply = encode(StatusReply(2, 0, 1), Settings(address=2))
    fb = parse(harness, reply, 1, address=1)
    assert fb.o_uErrId == 0x0104 and fb.o_uDetail == 2


def test_parser_rejects_the_wrong_function(harness):
    fb = parse(harness, bytes.fromhex("01 06 01 A0 00 00 88 14"), 1)
    assert fb.o_uErrId == 0x0104 and fb.o_uDetail == 6


def test_parser_rejects_a_wrong_byte_count(harness):
    fb = parse(harness, with_crc(bytes([1, 1, 2, 0, 0, 0])), 1)
    assert fb.o_uErrId == 0x0105 and fb.o_uDetail == 2
    # the header's o_uDetail said "received length (16#0105)" only: 2 is the byte count here
    header = (ROOT / "plc" / "core" / "UITAMR_ParseReply.st").read_text(encoding="utf-8").split("*)", 1)[0]
    detail = " ".join(header.split("o_uDetail", 1)[1].split("o_bException", 1)[0].split())
    assert "byte count of a status reply" in detail


@pytest.mark.parametrize("length", [0, 1, 4, 17])
def test_parser_rejects_impossible_lengths(harness, length):
    fb = parse(harness, bytes(min(length, 16)), 1) if length <= 16 else None
    if fb is None:
        harness.wWhat, harness.wLen = 3, length
        harness.scan()
        fb = harness.fbParse
    assert fb.o_bErr and fb.o_uErrId == 0x0105


@hsettings(max_examples=150, deadline=None)
@given(st.binary(min_size=5, max_size=16))
def test_garbage_is_never_accepted_unless_it_is_a_valid_reply(harness, data):
    fb = parse(harness, data, 1)
    if fb.o_bOK:
        assert len(data) == 8 and data[:3] == bytes([1, 1, 3]) and crc16(data[:-2]) == int.from_bytes(data[-2:], "little")
