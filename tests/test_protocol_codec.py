"""encode/decode of every frame kind under every setting, and precise errors for bad frames."""
from __future__ import annotations

import pytest
from hypothesis import given
from hypothesis import strategies as st
from pymodbus.framer import FramerRTU
from pymodbus.pdu import DecodePDU, ExceptionResponse, ReadCoilsRequest
from pymodbus.pdu.bit_message import ReadCoilsResponse
from pymodbus.pdu.register_message import WriteSingleRegisterRequest

from verifier.protocol import (
    STOP_FRAME,
    ControlCode,
    ControlReply,
    ControlRequest,
    ExceptionCode,
    ExceptionReply,
    FrameError,
    Query,
    RobotCommand,
    RobotError,
    Settings,
    StatusReply,
    StatusRequest,
    addressed_to_robot,
    crc_ok,
    decode_reply,
    decode_request,
    encode,
    exception_reply_for,
    function_of,
    is_stop_command,
    wire_code,
    wire_query,
    with_crc,
)
from verifier.protocol.strategies import (
    control_requests,
    exception_replies,
    requests,
    settings as any_settings,
    status_replies,
    status_requests,
)

DEFAULT = Settings()


def frame(hex_text: str) -> bytes:
    return bytes.fromhex(hex_text)


def error_of(call, *args, **kwargs) -> FrameError:
    with pytest.raises(FrameError) as info:
        call(*args, **kwargs)
    return info.value


# --- worked examples --------------------------------------------------------------------

def test_stop_frame():
    assert STOP_FRAME == frame("01 06 01 A0 00 00 88 14")
    assert encode(ControlRequest(1, ControlCode.ROBOT, RobotCommand.STOP), DEFAULT) == STOP_FRAME


def test_status_read_frame():
    assert encode(StatusRequest(1, Query.TASK), DEFAULT) == frame("01 01 00 00 00 16 BD C4")


def test_code_low_field_order_swaps_the_bytes():
    request = ControlRequest(1, ControlCode.ROBOT, RobotCommand.STOP)
    data = encode(request, Settings(field_order="code-low"))
    assert data[:6] == frame("01 06 A0 01 00 00") and crc_ok(data)
    assert decode_request(data, Settings(field_order="code-low")) == request


def test_codes_10_13_hex_on_the_wire():
    request = ControlRequest(1, ControlCode.ROTATE_POS, 100)
    assert encode(request, Settings(codes_10_13="hex"))[2] == 0x12
    assert encode(request, Settings(codes_10_13="decimal"))[2] == 0x0C


def test_status_order_return_on_the_wire():
    assert encode(StatusRequest(1, Query.TASK), Settings(status_order="return"))[3] == 2


def test_exception_reply_frame():
    assert encode(ExceptionReply(1, 6, ExceptionCode.ILLEGAL_DATA_VALUE)) == frame("01 86 03 02 61")


def test_status_reply_frame():
    assert encode(StatusReply(1, RobotError.NONE, 1)) == frame("01 01 03 00 00 01 FD 8E")


# --- round trips (every frame kind, every setting) --------------------------------------

@given(any_settings, requests)
def test_request_round_trip(settings, request):
    data = encode(request, settings)
    assert len(data) == 8 and crc_ok(data)
    assert decode_request(data, settings) == request


@given(any_settings, requests)
def test_reply_round_trip_against_request(settings, request):
    if isinstance(request, ControlRequest):
        reply = ControlReply.echo(request)
    else:
        reply = StatusReply(request.address, RobotError.NONE, 0, request.query)
    data = encode(reply, settings)
    assert decode_reply(data, settings, request) == reply


@given(any_settings, status_replies(with_query=False))
def test_status_reply_round_trip_without_request(settings, reply):
    assert decode_reply(encode(reply, settings), settings) == reply


@given(any_settings, status_replies())
def test_status_reply_round_trip_with_request(settings, reply):
    request = StatusRequest(reply.address, reply.query)
    assert decode_reply(encode(reply, settings), settings, request) == reply


@given(any_settings, exception_replies())
def test_exception_reply_round_trip(settings, reply):
    data = encode(reply, settings)
    assert len(data) == 5
    assert decode_reply(data, settings) == reply
    request = (ControlRequest(reply.address, ControlCode.ROBOT, RobotCommand.STOP) if reply.function == 6
               else StatusRequest(reply.address, Query.TASK))
    assert decode_reply(data, settings, request) == reply


@given(any_settings, control_requests())
def test_control_reply_round_trip(settings, request):
    reply = ControlReply.echo(request)
    data = encode(reply, settings)
    assert data == encode(request, settings)  # the echo is byte-identical
    assert decode_reply(data, settings) == reply


# --- against pymodbus as an independent Modbus implementation ---------------------------

CLIENT_FRAMER = FramerRTU(DecodePDU(is_server=False))
SERVER_FRAMER = FramerRTU(DecodePDU(is_server=True))


@given(any_settings, control_requests())
def test_control_request_equals_pymodbus_write_single_register(settings, request):
    register = int.from_bytes(encode(request, settings)[2:4], "big")
    code_byte, command_byte = wire_code(request.code, settings), request.command
    expected_register = (code_byte << 8 | command_byte) if settings.field_order == "code-high" else (command_byte << 8 | code_byte)
    assert register == expected_register
    pdu = WriteSingleRegisterRequest(dev_id=request.address, address=register, registers=[0])
    assert encode(request, settings) == CLIENT_FRAMER.buildFrame(pdu)
    used, decoded = SERVER_FRAMER.handleFrame(encode(request, settings), 0, 0)
    assert used == 8 and decoded.function_code == 6 and decoded.address == register


@given(any_settings, status_requests())
def test_status_request_equals_pymodbus_read_coils(settings, request):
    pdu = ReadCoilsRequest(dev_id=request.address, address=wire_query(request.query, settings), count=22)
    assert encode(request, settings) == CLIENT_FRAMER.buildFrame(pdu)
    used, decoded = SERVER_FRAMER.handleFrame(encode(request, settings), 0, 0)
    assert used == 8 and decoded.function_code == 1 and decoded.count == 22
    assert decoded.address == wire_query(request.query, settings)


@given(status_replies())
def test_status_reply_equals_pymodbus_read_coils_response(reply):
    bits = [False] * 8 + [bool(reply.error >> i & 1) for i in range(8)] + [bool(reply.value >> i & 1) for i in range(6)]
    pdu = ReadCoilsResponse(dev_id=reply.address, bits=bits)
    assert encode(reply) == CLIENT_FRAMER.buildFrame(pdu)


@given(exception_replies())
def test_exception_reply_equals_pymodbus(reply):
    pdu = ExceptionResponse(reply.function, int(reply.exception_code), device_id=reply.address)
    assert encode(reply) == SERVER_FRAMER.buildFrame(pdu)


# --- bad requests: each error names the byte and the slave's answer ---------------------

def test_too_short_request():
    err = error_of(decode_request, frame("01 06 01 A0 00 00 88"))
    assert err.kind == "length" and err.offset == 7 and err.exception is None
    assert "too short for an FC06" in err.message and "7 bytes, expected 8" in err.message


def test_too_long_request():
    err = error_of(decode_request, STOP_FRAME + b"\x00")
    assert err.kind == "length" and err.offset == 8 and "too long" in err.message


def test_nothing_at_all():
    assert error_of(decode_request, b"").offset == 0
    assert error_of(decode_request, b"\x01").kind == "length"


def test_bad_crc_says_expected_and_got():
    err = error_of(decode_request, frame("01 06 01 A0 00 00 88 15"))
    assert err.kind == "crc" and err.offset == 6 and err.exception is None
    assert "expected 88 14" in err.message and "got 88 15" in err.message
    assert str(err).startswith("byte 6: bad CRC")


def test_unknown_function_with_good_crc_gets_exception_01():
    data = with_crc(frame("01 03 00 00 00 01"))
    err = error_of(decode_request, data)
    assert err.kind == "function" and err.offset == 1
    assert err.exception is ExceptionCode.ILLEGAL_FUNCTION
    assert exception_reply_for(err, DEFAULT) == ExceptionReply(1, 3, ExceptionCode.ILLEGAL_FUNCTION)
    assert encode(exception_reply_for(err, DEFAULT)) == frame("01 83 01 80 F0")


def test_unknown_function_with_bad_crc_is_silence():
    err = error_of(decode_request, frame("01 03 00 00 00 01 00 00"))
    assert err.kind == "function" and err.exception is None
    assert exception_reply_for(err, DEFAULT) is None


def test_value_field_not_zero():
    err = error_of(decode_request, with_crc(frame("01 06 01 A0 00 01")))
    assert err.kind == "value-field" and err.offset == 5 and err.exception is ExceptionCode.ILLEGAL_DATA_VALUE
    err = error_of(decode_request, with_crc(frame("01 06 01 A0 01 00")))
    assert err.offset == 4


def test_unknown_control_code():
    err = error_of(decode_request, with_crc(frame("01 06 0E 00 00 00")))
    assert err.kind == "code" and err.offset == 2 and err.exception is ExceptionCode.ILLEGAL_DATA_VALUE
    assert "unknown control code 0x0E" in err.message


def test_unknown_control_code_under_code_low_names_byte_3():
    err = error_of(decode_request, with_crc(frame("01 06 00 0E 00 00")), Settings(field_order="code-low"))
    assert err.kind == "code" and err.offset == 3


def test_field_order_hint():
    err = error_of(decode_request, STOP_FRAME, Settings(field_order="code-low"))
    assert "with field_order=code-high it would read as code 01, command 0xA0" in err.message


def test_hex_code_under_decimal_setting():
    err = error_of(decode_request, with_crc(frame("01 06 12 05 00 00")))
    assert err.offset == 2 and "codes_10_13=decimal" in err.message
    assert decode_request(with_crc(frame("01 06 12 05 00 00")), Settings(codes_10_13="hex")).code is ControlCode.ROTATE_POS


def test_unknown_robot_command():
    err = error_of(decode_request, with_crc(frame("01 06 01 20 00 00")))
    assert err.kind == "command" and err.offset == 3 and "0x20" in err.message


def test_out_of_range_stage():
    err = error_of(decode_request, with_crc(frame("01 06 02 05 00 00")))
    assert err.kind == "command" and err.offset == 3 and "out of range 0-3" in err.message
    err = error_of(decode_request, with_crc(frame("01 06 05 07 00 00")))
    assert "out of range 0-6" in err.message


def test_quantity_not_22():
    err = error_of(decode_request, with_crc(frame("01 01 00 00 00 08")))
    assert err.kind == "quantity" and err.offset == 5 and err.exception is ExceptionCode.ILLEGAL_DATA_VALUE
    assert "00 16" in err.message and "(8)" in err.message
    assert error_of(decode_request, with_crc(frame("01 01 00 00 01 16"))).offset == 4


def test_unknown_query():
    err = error_of(decode_request, with_crc(frame("01 01 00 04 00 16")))
    assert err.kind == "query" and err.offset == 3 and err.exception is ExceptionCode.ILLEGAL_DATA_ADDRESS
    err = error_of(decode_request, with_crc(frame("01 01 01 00 00 16")))
    assert err.offset == 2


def test_exceptions_go_only_to_this_robot():
    bad = with_crc(frame("02 06 0E 00 00 00"))
    err = error_of(decode_request, bad)
    assert err.address == 2 and err.exception is ExceptionCode.ILLEGAL_DATA_VALUE
    assert exception_reply_for(err, Settings(address=2)) == ExceptionReply(2, 6, 3)
    assert exception_reply_for(err, Settings(address=1)) is None
    broadcast = error_of(decode_request, with_crc(frame("00 06 0E 00 00 00")))
    assert exception_reply_for(broadcast, DEFAULT) is None


def test_addressed_to_robot():
    assert addressed_to_robot(1, DEFAULT) and addressed_to_robot(0, DEFAULT)
    assert not addressed_to_robot(2, DEFAULT)
    assert addressed_to_robot(7, Settings(address=7))


@given(any_settings, requests, st.data())
def test_any_corrupted_request_is_rejected_or_still_valid(settings, request, data):
    """Flip one byte anywhere: either the CRC catches it or (never) it decodes unchanged."""
    raw = bytearray(encode(request, settings))
    at = data.draw(st.integers(0, 7))
    raw[at] ^= data.draw(st.integers(1, 255))
    with pytest.raises(FrameError) as info:
        decode_request(bytes(raw), settings)
    assert 0 <= info.value.offset <= 8


@given(any_settings, st.binary(max_size=12))
def test_decoders_never_raise_anything_but_frame_error(settings, data):
    for decoder in (decode_request, decode_reply):
        try:
            decoder(data, settings)
        except FrameError as err:
            assert 0 <= err.offset <= len(data) and err.message


@given(any_settings, st.binary(min_size=6, max_size=6))
def test_any_body_with_good_crc_decodes_or_names_a_field(settings, body):
    try:
        request = decode_request(with_crc(body), settings)
    except FrameError as err:
        assert err.kind in {"function", "code", "command", "value-field", "query", "quantity"}
        assert 1 <= err.offset <= 5
        # silence only for function codes no exception reply can answer (00, 80-FF)
        assert (err.exception is not None) == (1 <= body[1] < 0x80)
    else:
        assert encode(request, settings) == with_crc(body)


@given(any_settings, st.one_of(st.binary(max_size=12), st.binary(min_size=2, max_size=10).map(with_crc)))
def test_a_refused_request_says_why_a_slave_stays_silent(settings, data):
    """`uitamr frame` read again from the bytes why the robot would stay silent (the CRC,
    the function code), which the decoder knew when it refused them; now the decoder says
    it (`silence`): for every request refused without an exception reply, and only then."""
    try:
        decode_request(data, settings)
    except FrameError as err:
        assert (err.silence is None) == (err.exception is not None)
        unanswerable = err.kind == "function" and crc_ok(data) and not 1 <= data[1] < 0x80
        assert (err.silence == "function") == unanswerable
        assert err.silence in (None, "function", "broken")


# --- bad replies ------------------------------------------------------------------------

def test_reply_from_wrong_address():
    err = error_of(decode_reply, frame("02 06 01 A0 00 00 88 14"), DEFAULT, ControlRequest(1, 1, 0xA0))
    assert err.kind == "address" and err.offset == 0


def test_reply_with_wrong_function():
    reply = encode(StatusReply(1, 0, 0))
    err = error_of(decode_reply, reply, DEFAULT, ControlRequest(1, 1, 0xA0))
    assert err.kind == "function" and err.offset == 1


def test_exception_for_another_function():
    err = error_of(decode_reply, encode(ExceptionReply(1, 6, 3)), DEFAULT, StatusRequest(1, Query.TASK))
    assert err.offset == 1 and "exception for function 06" in err.message


def test_exception_reply_length_and_code():
    assert error_of(decode_reply, frame("01 86 03 02")).kind == "length"
    err = error_of(decode_reply, with_crc(frame("01 86 63")))
    assert err.kind == "exception-code" and err.offset == 2


def test_echo_mismatch_names_the_byte():
    request = ControlRequest(1, ControlCode.ROBOT, RobotCommand.STOP)
    err = error_of(decode_reply, encode(ControlRequest(1, ControlCode.ROBOT, RobotCommand.PAUSE)), DEFAULT, request)
    assert err.kind == "echo" and err.offset == 3 and "got 80, request had A0" in err.message


def test_status_reply_byte_count_and_first_byte():
    err = error_of(decode_reply, with_crc(frame("01 01 02 00 01")))
    assert err.kind == "length" and err.offset == 7  # a 2-byte-count reply is too short
    err = error_of(decode_reply, with_crc(frame("01 01 02 00 00 01")))
    assert err.kind == "byte-count" and err.offset == 2
    err = error_of(decode_reply, with_crc(frame("01 01 04 00 00 01")))
    assert err.kind == "byte-count" and err.offset == 2
    err = error_of(decode_reply, with_crc(frame("01 01 03 01 00 01")))
    assert err.kind == "data" and err.offset == 3


def test_status_reply_error_code_and_value():
    err = error_of(decode_reply, with_crc(frame("01 01 03 00 04 00")))
    assert err.kind == "error-code" and err.offset == 4
    err = error_of(decode_reply, with_crc(frame("01 01 03 00 00 40")))
    assert err.kind == "value" and err.offset == 5 and "coil" in err.message
    err = error_of(decode_reply, with_crc(frame("01 01 03 00 00 02")), DEFAULT, StatusRequest(1, Query.BATTERY))
    assert err.kind == "value" and err.offset == 5 and "battery" in err.message


def test_status_reply_carries_query_from_request():
    reply = decode_reply(frame("01 01 03 00 00 01 FD 8E"), DEFAULT, StatusRequest(1, Query.TASK))
    assert reply == StatusReply(1, RobotError.NONE, 1, Query.TASK)


# --- encode refuses what the robot would refuse -----------------------------------------

@pytest.mark.parametrize("frame_obj, message", [
    (ControlRequest(1, 14, 0), "unknown control code"),
    (ControlRequest(1, ControlCode.ROBOT, 0x20), "unknown robot command"),
    (ControlRequest(1, ControlCode.SPEED_MAGNETIC, 4), "out of range"),
    (ControlRequest(1, ControlCode.MOVE_Y_POS, 256), "byte 0-255"),
    (ControlRequest(256, ControlCode.ROBOT, 0xA0), "address"),
    (StatusRequest(1, Query.TASK, quantity=8), "quantity must be 22"),
    (StatusRequest(1, 7), "unknown query"),
    (StatusReply(1, 9, 0), "unknown error code"),
    (StatusReply(1, 0, 5, Query.TASK), "out of range"),
    (ExceptionReply(1, 0x86, 3), "1-127"),
])
def test_encode_rejects(frame_obj, message):
    with pytest.raises(ValueError, match=message):
        encode(frame_obj, DEFAULT)


def test_encode_non_strict_builds_bad_frames_for_tests():
    data = encode(ControlRequest(1, 0x20, 0x99), DEFAULT, strict=False)
    assert data[:6] == frame("01 06 20 99 00 00") and crc_ok(data)
    data = encode(StatusRequest(1, 9, quantity=8), DEFAULT, strict=False)
    assert data[:6] == frame("01 01 00 09 00 08")
    with pytest.raises(FrameError):
        decode_request(data)


def test_function_of():
    assert function_of(ControlRequest(1, 1, 0xA0)) == 6
    assert function_of(StatusReply(1, 0, 0)) == 1
    assert function_of(ExceptionReply(1, 6, 3)) == 0x86
    with pytest.raises(TypeError):
        function_of("stop")


# --- the stop command -------------------------------------------------------------------

def test_is_stop_command():
    assert is_stop_command(ControlRequest(1, ControlCode.ROBOT, RobotCommand.STOP))
    assert is_stop_command(STOP_FRAME)
    assert not is_stop_command(ControlRequest(1, ControlCode.ROBOT, RobotCommand.PAUSE))
    manual_stop = ControlRequest(1, ControlCode.MANUAL, 0)
    assert not is_stop_command(manual_stop, Settings())
    assert is_stop_command(manual_stop, Settings(manual_stop_counts_as_stop=True))
    assert not is_stop_command(StatusRequest(1, Query.TASK))
    assert not is_stop_command(frame("01 06 01 A0 00 00 88 15"))  # bad CRC is no command
    assert is_stop_command(encode(ControlRequest(1, 1, 0xA0), Settings(field_order="code-low")),
                           Settings(field_order="code-low"))


@given(any_settings, requests)
def test_only_stop_commands_are_stop(settings, request):
    stop = isinstance(request, ControlRequest) and (
        (request.code, request.command) == (ControlCode.ROBOT, RobotCommand.STOP)
        or (settings.manual_stop_counts_as_stop and (request.code, request.command) == (ControlCode.MANUAL, 0))
    )
    assert is_stop_command(request, settings) == stop
    assert is_stop_command(encode(request, settings), settings) == stop
