"""UITAMR Modbus RTU protocol: the single source of truth for frames, CRC and commands.

Everything another part of the toolkit needs to know about the robot's protocol is
imported from here; docs/protocol.md explains it for people.

- ``crc``: CRC-16/MODBUS.            - ``settings``: the manual's [choice]s.
- ``catalogue``: codes and commands.  - ``frames``: frame dataclasses and FrameError.
- ``codec``: encode / decode.         - ``stream``: split a byte stream into frames.
- ``describe``: text for people.      - ``names``: commands by name (CLI, scenarios).
- ``timing``: byte times, t1.5/t3.5, pacing.
"""
from verifier.protocol.catalogue import (
    FC_READ_COILS,
    FC_WRITE_SINGLE_REGISTER,
    STATUS_QUANTITY,
    ControlCode,
    ExceptionCode,
    ManualMove,
    Query,
    RobotCommand,
    RobotError,
    command_problem,
    command_title,
    logical_code,
    logical_query,
    value_problem,
    wire_code,
    wire_query,
)
from verifier.protocol.codec import (
    STOP_FRAME,
    addressed_to_robot,
    answerable_function,
    decode_reply,
    decode_request,
    encode,
    exception_reply_for,
    function_of,
    hex_bytes,
    is_stop_command,
)
from verifier.protocol.crc import crc16, crc_ok, with_crc
from verifier.protocol.describe import decode_frame, describe
from verifier.protocol.explain import Field, explain, explain_table
from verifier.protocol.frames import (
    ControlReply,
    ControlRequest,
    ExceptionReply,
    FrameError,
    StatusReply,
    StatusRequest,
)
from verifier.protocol.names import CommandError, command_from_words, words_for
from verifier.protocol.settings import DEFAULT_SETTINGS, Settings
from verifier.protocol.stream import FrameSplitter, frame_length, split_frames
from verifier.protocol.timing import (
    BYTE_TIME_EXACT_US,
    BYTE_TIME_US,
    DEFAULT_ATTEMPTS,
    DEFAULT_REPLY_TIMEOUT_US,
    MIN_PERIOD_US,
    RECOMMENDED_PERIOD_US,
    T1_5_US,
    T3_5_US,
    frame_time_us,
    splits_at_pauses,
)

__all__ = [name for name in dir() if not name.startswith("_")]
