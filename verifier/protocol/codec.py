"""Bytes <-> frames for the robot's two function codes and Modbus exception replies.

``encode`` builds a complete RTU frame (CRC included). ``decode_request`` and
``decode_reply`` accept only frames the manual allows and otherwise raise ``FrameError``
naming the first wrong byte and what a Modbus slave would answer (silence or an exception
code), following "MODBUS over Serial Line V1.02" §2.4 / Modbus Application Protocol
V1.1b3 §7: a frame with a bad CRC or for another address is ignored; an unknown
function code gets exception 01; an illegal address gets 02; an illegal value gets 03.
"""
from __future__ import annotations

from verifier.protocol.catalogue import (
    is_member,
    EXCEPTION_FLAG,
    FC_READ_COILS,
    FC_WRITE_SINGLE_REGISTER,
    FUNCTION_CODES,
    MAX_COILS,
    STATUS_BYTE_COUNT,
    STATUS_QUANTITY,
    ControlCode,
    ExceptionCode,
    ManualMove,
    Query,
    RobotCommand,
    RobotError,
    command_problem,
    logical_code,
    logical_query,
    value_problem,
    wire_code,
    wire_query,
)
from verifier.protocol.crc import crc16, crc_bytes, frame_crc, with_crc
from verifier.protocol.frames import (
    ControlReply,
    ControlRequest,
    ExceptionReply,
    Frame,
    FrameError,
    StatusReply,
    StatusRequest,
)
from verifier.protocol.settings import DEFAULT_SETTINGS, Settings

REQUEST_LENGTH = 8  # FC06 and FC01 requests
CONTROL_REPLY_LENGTH = 8  # FC06 echo
STATUS_REPLY_LENGTH = 8  # FC01: addr 01 03 00 ERR VAL CRC CRC
EXCEPTION_REPLY_LENGTH = 5
REPLY_LENGTHS = {FC_WRITE_SINGLE_REGISTER: CONTROL_REPLY_LENGTH, FC_READ_COILS: STATUS_REPLY_LENGTH}
#: the longest frame any Modbus RTU line carries (Modbus over Serial Line V1.02 §2.5.1: an
#: RTU ADU is at most 256 bytes): a longer run of bytes without a silence is noise
MAX_FRAME = 256

FUNCTION_NAMES = {FC_READ_COILS: "FC01 (read coils)", FC_WRITE_SINGLE_REGISTER: "FC06 (write single register)"}

ILLEGAL_FUNCTION = ExceptionCode.ILLEGAL_FUNCTION
ILLEGAL_ADDRESS = ExceptionCode.ILLEGAL_DATA_ADDRESS
ILLEGAL_VALUE = ExceptionCode.ILLEGAL_DATA_VALUE


def hex_bytes(data: bytes) -> str:
    """``b'\\x01\\x06'`` -> ``'01 06'``: the way frames are printed everywhere."""
    return " ".join(f"{b:02X}" for b in data)


def packed_words(data: bytes) -> list[int]:
    """Two bytes per 16-bit word, low byte first, as RS2 and the QJ71C24N hold a frame in
    their buffers; an odd last byte gets a 00 high byte."""
    return [data[i] | (data[i + 1] << 8 if i + 1 < len(data) else 0) for i in range(0, len(data), 2)]


def hex_words(data: bytes) -> str:
    """``b'\x01\x06\x01\xa0'`` -> ``'H0601 HA001'``: a frame as a PLC buffer's words,
    written as a GX Works device monitor shows them (`uitamr frame --words`)."""
    return " ".join(f"H{word:04X}" for word in packed_words(data))


def function_of(frame: Frame) -> int:
    """The function code byte a frame carries (0x81/0x86 for exception replies)."""
    if isinstance(frame, (ControlRequest, ControlReply)):
        return FC_WRITE_SINGLE_REGISTER
    if isinstance(frame, (StatusRequest, StatusReply)):
        return FC_READ_COILS
    if isinstance(frame, ExceptionReply):
        return frame.function | EXCEPTION_FLAG
    raise TypeError(f"not a UITAMR frame: {frame!r}")


# --- encode -----------------------------------------------------------------------------

def encode(frame: Frame, settings: Settings = DEFAULT_SETTINGS, *, strict: bool = True) -> bytes:
    """The complete RTU frame (with CRC) for ``frame`` under ``settings``.

    With ``strict`` (the default) a frame outside the catalogue raises ValueError; with
    ``strict=False`` any byte values are sent as given (to build bad frames for tests).
    """
    _check_byte("address", frame.address)
    if isinstance(frame, (ControlRequest, ControlReply)):
        field = _control_field(frame, settings, strict)
        return with_crc(bytes((frame.address, FC_WRITE_SINGLE_REGISTER)) + field + b"\x00\x00")
    if isinstance(frame, StatusRequest):
        return with_crc(_status_request_body(frame, settings, strict))
    if isinstance(frame, StatusReply):
        _check_byte("error code", frame.error)
        _check_byte("value", frame.value)
        if strict:
            _check_status_reply(frame)
        return with_crc(bytes((frame.address, FC_READ_COILS, STATUS_BYTE_COUNT, 0, frame.error, frame.value)))
    if isinstance(frame, ExceptionReply):
        if not 1 <= frame.function <= 0x7F:
            raise ValueError(f"exception reply function must be 1-127, got {frame.function}")
        _check_byte("exception code", frame.exception_code)
        return with_crc(bytes((frame.address, frame.function | EXCEPTION_FLAG, frame.exception_code)))
    raise TypeError(f"not a UITAMR frame: {frame!r}")


def _check_byte(name: str, value: int) -> None:
    if not isinstance(value, int) or not 0 <= value <= 0xFF:
        raise ValueError(f"{name} must be a byte 0-255, got {value!r}")


def _control_field(frame: ControlRequest | ControlReply, settings: Settings, strict: bool) -> bytes:
    _check_byte("command", frame.command)
    if isinstance(frame.code, ControlCode):
        code_byte = wire_code(frame.code, settings)
    elif strict:
        raise ValueError(f"unknown control code {frame.code}")
    else:
        _check_byte("control code", frame.code)
        code_byte = frame.code
    if strict and (problem := command_problem(frame.code, frame.command)):
        raise ValueError(problem)
    if settings.field_order == "code-high":
        return bytes((code_byte, frame.command))
    return bytes((frame.command, code_byte))


def _status_request_body(frame: StatusRequest, settings: Settings, strict: bool) -> bytes:
    if not 0 <= frame.quantity <= 0xFFFF:
        raise ValueError(f"quantity must be 0-65535, got {frame.quantity}")
    if strict and frame.quantity != STATUS_QUANTITY:
        raise ValueError(f"quantity must be {STATUS_QUANTITY}, got {frame.quantity}")
    if is_member(Query, frame.query):
        parameter = wire_query(frame.query, settings)
    elif strict:
        raise ValueError(f"unknown query {frame.query!r} (0-3)")
    else:
        parameter = frame.query
    if not 0 <= parameter <= 0xFFFF:
        raise ValueError(f"query parameter must be 0-65535, got {parameter}")
    return bytes((frame.address, FC_READ_COILS)) + parameter.to_bytes(2, "big") + frame.quantity.to_bytes(2, "big")


def _check_status_reply(frame: StatusReply) -> None:
    if not is_member(RobotError, frame.error):
        raise ValueError(f"unknown error code {frame.error} (0-3)")
    if frame.query is not None and (problem := value_problem(frame.query, frame.value)):
        raise ValueError(problem)
    if frame.value > 0x3F:
        raise ValueError(f"value {frame.value} does not fit in the last 6 of the 22 coils")


# --- shared checks ----------------------------------------------------------------------

def _check_length(data: bytes, expected: int, what: str, address: int, function: int) -> None:
    n = len(data)
    if n < expected:
        raise FrameError(
            f"too short for {what}: {n} bytes, expected {expected}",
            n, kind="length", address=address, function=function, silence="broken",
        )
    if n > expected:
        raise FrameError(
            f"too long for {what}: {n} bytes, expected {expected}",
            expected, kind="length", address=address, function=function, silence="broken",
        )


def _check_crc(data: bytes, address: int, function: int) -> None:
    expected = crc16(data[:-2])
    got = frame_crc(data)
    if expected != got:
        raise FrameError(
            f"bad CRC: expected {hex_bytes(crc_bytes(expected))} (CRC 0x{expected:04X}), "
            f"got {hex_bytes(crc_bytes(got))} (CRC 0x{got:04X})",
            len(data) - 2, kind="crc", address=address, function=function, silence="broken",
        )


def _head(data: bytes, what: str) -> tuple[int, int]:
    if len(data) < 2:
        raise FrameError(
            f"too short for {what}: {len(data)} bytes, need at least the address and function code",
            len(data), kind="length", address=data[0] if data else None, silence="broken",
        )
    return data[0], data[1]


def _decode_control_field(
    data: bytes, settings: Settings, exception: ExceptionCode | None
) -> tuple[ControlCode, int]:
    """Code and command of an FC06 frame whose length and CRC are already good."""
    address, function = data[0], data[1]
    code_at, command_at = (2, 3) if settings.field_order == "code-high" else (3, 2)

    def fail(message: str, offset: int, kind: str) -> FrameError:
        return FrameError(
            message + _other_order_hint(data, settings), offset,
            kind=kind, exception=exception, address=address, function=function,
        )

    try:
        code = logical_code(data[code_at], settings)
    except ValueError as exc:
        raise fail(f"{exc} (control code byte, field_order={settings.field_order})", code_at, "code") from None
    command = data[command_at]
    if problem := command_problem(code, command):
        raise fail(problem, command_at, "command")
    if data[4] or data[5]:
        offset = 4 if data[4] else 5
        raise FrameError(
            f"value field must be 00 00, got {hex_bytes(data[4:6])}", offset,
            kind="value-field", exception=exception, address=address, function=function,
        )
    return code, command


def _other_order_hint(data: bytes, settings: Settings) -> str:
    """Say so when the bytes would be valid with the other field order."""
    other = "code-low" if settings.field_order == "code-high" else "code-high"
    code_at, command_at = (2, 3) if other == "code-high" else (3, 2)
    flipped = Settings(
        address=settings.address, field_order=other, codes_10_13=settings.codes_10_13,
        status_order=settings.status_order, manual_stop_counts_as_stop=settings.manual_stop_counts_as_stop,
    )
    try:
        code = logical_code(data[code_at], flipped)
    except ValueError:
        return ""
    if command_problem(code, data[command_at]):
        return ""
    return f"; with field_order={other} it would read as code {int(code):02d}, command 0x{data[command_at]:02X}"


# --- decode requests --------------------------------------------------------------------

def decode_request(data: bytes, settings: Settings = DEFAULT_SETTINGS) -> ControlRequest | StatusRequest:
    """Decode a master->robot frame; FrameError names the first wrong byte."""
    data = bytes(data)
    address, function = _head(data, "a request")
    if function not in FUNCTION_CODES:
        _unknown_function(data, address, function)
    what = f"an {FUNCTION_NAMES[function]} request"
    _check_length(data, REQUEST_LENGTH, what, address, function)
    _check_crc(data, address, function)
    if function == FC_WRITE_SINGLE_REGISTER:
        code, command = _decode_control_field(data, settings, ILLEGAL_VALUE)
        return ControlRequest(address, code, command)
    return _decode_status_request(data, settings)


def _unknown_function(data: bytes, address: int, function: int) -> None:
    known = "the robot knows 01 (read coils) and 06 (write single register)"
    if len(data) >= 4 and crc16(data[:-2]) == frame_crc(data):
        if not answerable_function(function):
            raise FrameError(
                f"function code 0x{function:02X} is not one a master sends (00 is not a Modbus function "
                "code, 80-FF are exception replies)", 1, kind="function", address=address, function=function,
                silence="function",
            )
        raise FrameError(
            f"unknown function code 0x{function:02X} ({known})", 1,
            kind="function", exception=ILLEGAL_FUNCTION, address=address, function=function,
        )
    raise FrameError(
        f"unknown function code 0x{function:02X} ({known}); the CRC over the {len(data)} bytes "
        "does not match either, so a slave stays silent",
        1, kind="function", address=address, function=function, silence="broken",
    )


def _decode_status_request(data: bytes, settings: Settings) -> StatusRequest:
    address, function = data[0], data[1]
    quantity = int.from_bytes(data[4:6], "big")
    # Modbus checks the quantity against 1-2000 before the address (Modbus Application
    # Protocol V1.1b3 §6.1, the Read Coils state diagram): outside that, 03 whatever the address
    if not 1 <= quantity <= MAX_COILS:
        raise _bad_quantity(data, quantity)
    if data[2]:
        raise FrameError(
            f"query parameter high byte must be 00, got {data[2]:02X}", 2,
            kind="query", exception=ILLEGAL_ADDRESS, address=address, function=function,
        )
    try:
        query = logical_query(data[3], settings)
    except ValueError as exc:
        raise FrameError(
            str(exc), 3, kind="query", exception=ILLEGAL_ADDRESS, address=address, function=function,
        ) from None
    if quantity != STATUS_QUANTITY:
        raise _bad_quantity(data, quantity)
    return StatusRequest(address, query)


def _bad_quantity(data: bytes, quantity: int) -> FrameError:
    return FrameError(
        f"quantity must be 00 16 (22 coils), got {hex_bytes(data[4:6])} ({quantity})", 4 if data[4] else 5,
        kind="quantity", exception=ILLEGAL_VALUE, address=data[0], function=data[1],
    )


# --- decode replies ---------------------------------------------------------------------

def decode_reply(
    data: bytes,
    settings: Settings = DEFAULT_SETTINGS,
    request: ControlRequest | StatusRequest | None = None,
) -> ControlReply | StatusReply | ExceptionReply:
    """Decode a robot->master frame; with ``request`` also check it answers that request."""
    data = bytes(data)
    address, function = _head(data, "a reply")
    if request is not None and address != request.address:
        raise FrameError(
            f"reply from address {address} to a request for address {request.address}", 0,
            kind="address", address=address, function=function,
        )
    expected_function = None if request is None else function_of(request)
    if function & EXCEPTION_FLAG:
        return _decode_exception(data, function, expected_function)
    if function not in FUNCTION_CODES:
        raise FrameError(
            f"unknown function code 0x{function:02X} in a reply (01, 06, or 81/86 for an exception)",
            1, kind="function", address=address, function=function,
        )
    if expected_function is not None and function != expected_function:
        raise FrameError(
            f"reply has function {function:02X} but the request was function {expected_function:02X}",
            1, kind="function", address=address, function=function,
        )
    _check_length(data, REPLY_LENGTHS[function], f"an {FUNCTION_NAMES[function]} reply", address, function)
    _check_crc(data, address, function)
    if function == FC_WRITE_SINGLE_REGISTER:
        if request is not None:
            _check_echo(data, encode(request, settings, strict=False))
        code, command = _decode_control_field(data, settings, None)
        return ControlReply(address, code, command)
    query = None if request is None else request.query
    return _decode_status_reply(data, query)


def _decode_exception(data: bytes, function: int, expected_function: int | None) -> ExceptionReply:
    address = data[0]
    plain = function & ~EXCEPTION_FLAG
    _check_length(data, EXCEPTION_REPLY_LENGTH, "an exception reply", address, function)
    _check_crc(data, address, function)
    if expected_function is not None and plain != expected_function:
        raise FrameError(
            f"exception for function {plain:02X} but the request was function {expected_function:02X}",
            1, kind="function", address=address, function=function,
        )
    code = data[2]
    if not is_member(ExceptionCode, code):
        raise FrameError(
            f"unknown Modbus exception code {code:02X}", 2,
            kind="exception-code", address=address, function=function,
        )
    return ExceptionReply(address, plain, code)


def _check_echo(data: bytes, request_bytes: bytes) -> None:
    for offset in range(2, 6):
        if data[offset] != request_bytes[offset]:
            raise FrameError(
                f"FC06 reply does not echo the request: got {data[offset]:02X}, request had "
                f"{request_bytes[offset]:02X}",
                offset, kind="echo", address=data[0], function=data[1],
            )


def _decode_status_reply(data: bytes, query) -> StatusReply:
    address, function = data[0], data[1]

    def fail(message: str, offset: int, kind: str) -> FrameError:
        return FrameError(message, offset, kind=kind, address=address, function=function)

    if data[2] != STATUS_BYTE_COUNT:
        raise fail(f"byte count must be 03 (22 coils), got {data[2]:02X}", 2, "byte-count")
    if data[3]:
        raise fail(f"first data byte must be 00, got {data[3]:02X}", 3, "data")
    error, value = data[4], data[5]
    if not is_member(RobotError, error):
        raise fail(f"unknown error code {error:02X} (table 3: 00-03)", 4, "error-code")
    if value > 0x3F:
        raise fail(
            f"value {value:02X} sets bits above coil 22 (only the low 6 bits of the last byte are coils)",
            5, "value",
        )
    if query is not None and (problem := value_problem(query, value)):
        raise fail(problem, 5, "value")
    return StatusReply(address, error, value, query)


# --- meaning ----------------------------------------------------------------------------

def is_stop_command(request: ControlRequest | bytes, settings: Settings = DEFAULT_SETTINGS) -> bool:
    """True for the stop command (01/A0), and for manual stop 05/00 if the settings say so."""
    if isinstance(request, (bytes, bytearray, memoryview)):
        try:
            request = decode_request(bytes(request), settings)
        except FrameError:
            return False
    if not isinstance(request, ControlRequest):
        return False
    if request.code == ControlCode.ROBOT and request.command == RobotCommand.STOP:
        return True
    return (
        settings.manual_stop_counts_as_stop
        and request.code == ControlCode.MANUAL
        and request.command == ManualMove.STOP
    )


def addressed_to_robot(address: int, settings: Settings = DEFAULT_SETTINGS) -> bool:
    """Whether a request with this address byte is for the robot (broadcast 0 included).

    Modbus serial line: a slave acts on its own address and on broadcast 0, answers only
    its own address, and ignores every other address without a word.
    """
    return address in (0, settings.address)


def answerable_function(function: int) -> bool:
    """Whether an exception reply can answer this function code: not 00 (no Modbus function
    code) nor 80-FF (exception replies themselves; 80 | 80 is 80 again), Modbus Application
    Protocol V1.1b3 §4.1. A request with one of those gets silence."""
    return 1 <= function < EXCEPTION_FLAG


def exception_reply_for(error: FrameError, settings: Settings = DEFAULT_SETTINGS) -> ExceptionReply | None:
    """The exception reply a Modbus slave sends for a bad request, or None for silence.

    Silence when the frame is broken (length, CRC), addressed to another slave, or
    broadcast (a slave never answers a broadcast).
    """
    if (error.exception is None or error.address != settings.address or error.function is None
            or not answerable_function(error.function)):
        return None
    return ExceptionReply(error.address, error.function & ~EXCEPTION_FLAG, error.exception)


STOP_FRAME = encode(ControlRequest(1, ControlCode.ROBOT, RobotCommand.STOP))
