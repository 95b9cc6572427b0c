"""Human text for frames: what a person reading a trace or a ladder rung needs to see."""
from __future__ import annotations

from verifier.protocol.catalogue import (
    ERROR_TITLES,
    EXCEPTION_FLAG,
    EXCEPTION_TITLES,
    FC_READ_COILS,
    STATUS_BYTE_COUNT,
    QUERY_TITLES,
    QUERY_VALUES,
    ControlCode,
    RobotError,
    command_title,
    wire_code,
    wire_query,
)
from verifier.protocol.codec import (EXCEPTION_REPLY_LENGTH, REQUEST_LENGTH, decode_reply, decode_request, hex_bytes,
                                     hex_words)
from verifier.protocol.crc import crc16, crc_bytes
from verifier.protocol.frames import (
    ControlReply,
    ControlRequest,
    ExceptionReply,
    Frame,
    FrameError,
    StatusReply,
    StatusRequest,
)
from verifier.protocol.settings import DEFAULT_SETTINGS, SLAVE_ADDRESSES, Settings
from verifier.protocol.stream import Direction


def describe(
    frame_or_bytes: Frame | bytes,
    settings: Settings = DEFAULT_SETTINGS,
    direction: Direction | None = None,
) -> str:
    """One line of plain English, e.g. ``"stop (01/A0)"`` or ``"task status: running"``.

    Bytes are decoded first (as a request, then as a reply, unless ``direction`` says
    which); bytes that decode as neither give ``"invalid frame: byte N: ..."``.
    """
    if isinstance(frame_or_bytes, (bytes, bytearray, memoryview)):
        try:
            frame_or_bytes = decode_frame(bytes(frame_or_bytes), settings, direction)
        except FrameError as exc:
            hint = modbus_tcp_hint(bytes(frame_or_bytes), settings)
            return f"invalid frame: {exc}" + (f"; {hint}" if hint else "")
    return _describe_frame(frame_or_bytes, settings)


def modbus_tcp_hint(data: bytes, settings: Settings = DEFAULT_SETTINGS) -> str:
    """'this is a Modbus TCP frame ...' when `data` is a whole MBAP frame (protocol id 0,
    its length field matching): a master, PLC or converter set to Modbus TCP where the
    robot's route carries Modbus RTU inside TCP (docs/tcp-converter.md). '' otherwise. At
    least 9 bytes (an exception reply: unit, function, code): an 8-byte "MBAP frame" would
    be a function code without data, and is an RTU frame of this protocol."""
    if len(data) < 9 or data[2:4] != b"\x00\x00" or int.from_bytes(data[4:6], "big") != len(data) - 6:
        return ""
    from verifier.protocol.crc import with_crc

    rtu = with_crc(data[6:])
    try:
        meaning = f"; as RTU: {_describe_frame(decode_frame(rtu, settings), settings)}"
    except FrameError:
        meaning = ""
    return (f"this is a Modbus TCP frame (MBAP header {data[:6].hex(' ').upper()}, unit {data[6]}{meaning}): "
            "the robot's route carries Modbus RTU frames with their CRC inside TCP: set the master or the "
            "converter to RTU over TCP (transparent mode), not Modbus TCP (docs/tcp-converter.md)")


def frame_kind(frame: Frame) -> str:
    """"FC06 request", "FC01 reply", "exception reply", ...: what a decoded frame is."""
    if isinstance(frame, ControlRequest):
        return "FC06 request"
    if isinstance(frame, StatusRequest):
        return "FC01 request"
    if isinstance(frame, ControlReply):
        return "FC06 reply"
    if isinstance(frame, StatusReply):
        return "FC01 reply"
    if isinstance(frame, ExceptionReply):
        return "exception reply"
    return "frame"


def who_answers(request: ControlRequest | StatusRequest) -> str | None:
    """Who answers a valid request: a broadcast (address 0) or a reserved address (248-255)
    gets no reply from any slave; an FC06 request's normal reply echoes it."""
    if request.address == 0 and isinstance(request, StatusRequest):
        # Modbus over Serial Line V1.02 §2.1: "broadcast requests are necessarily writing commands"
        return "(broadcast: no robot replies, so a read to address 0 returns nothing; Modbus broadcasts only writes)"
    if request.address == 0:
        return "(broadcast: every robot on the line acts on it, none replies)"
    if request.address not in SLAVE_ADDRESSES:
        return (f"(address {request.address} is reserved: Modbus slave addresses are "
                f"{SLAVE_ADDRESSES.start}-{SLAVE_ADDRESSES.stop - 1}, so no robot replies; the robot's default is 1)")
    if isinstance(request, ControlRequest):
        return "(a normal reply echoes these 8 bytes)"
    return None


def paste_hint(data: bytes, error: FrameError, settings: Settings = DEFAULT_SETTINGS,
               direction: Direction | None = None,
               request: ControlRequest | StatusRequest | None = None) -> str | None:
    """What a frame copied from a terminal or a logic analyser most likely went through: its
    CRC bytes swapped (high byte first), a PLC buffer's words read high byte first, or a
    whole frame with one stray byte before or after it. Each said only "bad CRC" or "too
    long" without the fix. `request`: the bytes are its reply."""
    def decoded(part: bytes) -> Frame:
        return decode_reply(part, settings, request) if request is not None else decode_frame(part, settings, direction)

    if error.kind == "crc" and len(data) >= 4:
        expected = crc_bytes(crc16(data[:-2]))
        if data[-2:] == expected[::-1] and data[-2] != data[-1]:
            return (f"the CRC bytes are swapped: Modbus RTU sends the CRC low byte first "
                    f"({hex_bytes(expected)}), not {hex_bytes(data[-2:])}; a send buffer that "
                    "holds the CRC word high byte first sends them this way")
    if len(data) % 2 == 0 and len(data) >= 4:
        # `0601 A001 0000 1488`: a send buffer's registers read off a monitor, each word high
        # byte first as a number is written; the frame is their bytes low byte first
        swapped = bytes(b for i in range(0, len(data), 2) for b in (data[i + 1], data[i]))
        try:
            frame = decoded(swapped)
        except FrameError:
            frame = None
        if frame is not None:
            return (f"read as 16-bit words, low byte first (as RS2 and the QJ71C24N hold a frame), these are "
                    f"{frame_kind(frame)}: {describe(frame, settings)}: give them as {hex_words(swapped)}, or as "
                    f"the bytes {hex_bytes(swapped)}")
    if error.kind == "length" and error.offset < len(data):  # too long
        for start, end, where in ((0, error.offset, "after"), (1, len(data), "before")):
            try:
                frame = decoded(data[start:end])
            except FrameError:
                continue
            stray = data[end:] if where == "after" else data[:1]
            at = f"byte {end}" if where == "after" else "byte 0"
            return (f"bytes {start}-{end - 1} are a whole frame, {frame_kind(frame)}: {describe(frame, settings)}, "
                    f"CRC ok; {hex_bytes(stray)} {where} it ({at}{' on' if len(stray) > 1 else ''}) is extra: "
                    "a second frame run together with it, or a stray byte of the line")
    return None


def decode_frame(data: bytes, settings: Settings = DEFAULT_SETTINGS, direction: Direction | None = None) -> Frame:
    """Decode as ``direction`` says, or as a request and then as a reply.

    When neither works the request's error is raised, except for frames that can only be
    replies (exception replies, FC01 replies), whose reply error is the useful one.
    """
    if direction == "request":
        return decode_request(data, settings)
    if direction == "reply":
        return decode_reply(data, settings)
    try:
        return decode_request(data, settings)
    except FrameError as request_error:
        try:
            return decode_reply(data, settings)
        except FrameError as reply_error:
            if looks_like_reply(data):
                raise reply_error from None
            raise request_error from None


def looks_like_reply(data: bytes) -> bool:
    """Bytes only a robot sends: an exception reply, or FC01 with byte count 03."""
    return len(data) >= 3 and bool(data[1] & EXCEPTION_FLAG
                                   or (data[1] == FC_READ_COILS and data[2] == STATUS_BYTE_COUNT))


def side_by_content(data: bytes) -> str | None:
    """"rx" or "tx" where a whole frame's content alone says which side sent it, whatever
    the turn on the line; None where only the turn can tell (an FC06 reply echoes its
    request). An exception reply (5 bytes, the function code with EXCEPTION_FLAG) comes
    only from a slave (Modbus Application Protocol V1.1b3 §7); an 8-byte FC01 frame whose
    third byte is not the byte count 03 is no reply of the robot's (22 coils: 01 01 03, 3
    bytes, CRC) but a request, however wrong its query or quantity."""
    if len(data) < 3:
        return None
    if data[1] & EXCEPTION_FLAG and len(data) == EXCEPTION_REPLY_LENGTH:
        return "rx"
    if data[1] == FC_READ_COILS and len(data) == REQUEST_LENGTH and data[2] != STATUS_BYTE_COUNT:
        return "tx"
    return None


def _address_note(address: int, settings: Settings) -> str:
    if address == settings.address:
        return ""
    if address == 0:
        return " [broadcast address 0]"
    return f" [address {address}, not this robot's {settings.address}]"


def _control_text(frame: ControlRequest | ControlReply, settings: Settings) -> str:
    if isinstance(frame.code, ControlCode):
        return f"{command_title(frame.code, frame.command)} ({wire_code(frame.code, settings):02X}/{frame.command:02X})"
    return f"unknown control code {frame.code} ({frame.command:02X})"


def _describe_frame(frame: Frame, settings: Settings) -> str:
    note = _address_note(frame.address, settings)
    if isinstance(frame, ControlRequest):
        return _control_text(frame, settings) + note
    if isinstance(frame, ControlReply):
        return "echo: " + _control_text(frame, settings) + note
    if isinstance(frame, StatusRequest):
        if frame.query in QUERY_TITLES:
            return f"read {QUERY_TITLES[frame.query]} (query {wire_query(frame.query, settings)})" + note
        return f"read unknown query {frame.query}" + note
    if isinstance(frame, StatusReply):
        return _status_reply_text(frame) + note
    if isinstance(frame, ExceptionReply):
        title = EXCEPTION_TITLES.get(frame.exception_code, "unknown exception")
        return f"exception {int(frame.exception_code):02X} ({title}) to function {frame.function:02X}" + note
    raise TypeError(f"not a UITAMR frame: {frame!r}")


def _status_reply_text(frame: StatusReply) -> str:
    if isinstance(frame.error, RobotError):
        error = f"error {int(frame.error):02X} {ERROR_TITLES[frame.error]}"
    else:
        error = f"unknown error {frame.error:02X}"
    if frame.query is None:
        return f"status reply: value {frame.value}, {error}"
    meaning = QUERY_VALUES[frame.query].get(frame.value, "out of range")
    return f"{QUERY_TITLES[frame.query]}: {meaning} ({frame.value}), {error}"
