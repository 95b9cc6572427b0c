"""Commands by name (`uitamr frame` words and scenario files) and describe()."""
from __future__ import annotations

import pytest
from hypothesis import given

from verifier.protocol import (
    CommandError,
    ControlCode,
    ControlRequest,
    Query,
    RobotCommand,
    Settings,
    StatusRequest,
    command_from_words,
    decode_frame,
    describe,
    encode,
    hex_bytes,
    words_for,
)
from verifier.protocol.catalogue import ManualMove
from verifier.protocol.strategies import requests, settings as any_settings

EXPECTED = {
    "stop": (ControlCode.ROBOT, RobotCommand.STOP),
    "pause": (ControlCode.ROBOT, RobotCommand.PAUSE),
    "run-point 7": (ControlCode.ROBOT, 7),
    "run-point 0x15": (ControlCode.ROBOT, 21),
    "seek-tape forward": (ControlCode.ROBOT, 22),
    "seek-tape backward": (ControlCode.ROBOT, 54),
    "follow-tape forward": (ControlCode.ROBOT, 23),
    "follow-tape backward": (ControlCode.ROBOT, 55),
    "follow-tape left": (ControlCode.ROBOT, 87),
    "follow-tape right": (ControlCode.ROBOT, 119),
    "rotate-on-tape left": (ControlCode.ROBOT, 24),
    "rotate-on-tape right": (ControlCode.ROBOT, 25),
    "coordinate-reset": (ControlCode.ROBOT, 192),
    "manual-mode": (ControlCode.ROBOT, 224),
    "speed trackless 0": (ControlCode.SPEED_TRACKLESS, 0),
    "speed magnetic 3": (ControlCode.SPEED_MAGNETIC, 3),
    "collision-range 2": (ControlCode.COLLISION_RANGE, 2),
    "jog stop": (ControlCode.MANUAL, ManualMove.STOP),
    "jog forward": (ControlCode.MANUAL, 1),
    "jog backward": (ControlCode.MANUAL, 2),
    "jog left": (ControlCode.MANUAL, 3),
    "jog right": (ControlCode.MANUAL, 4),
    "jog shift-left": (ControlCode.MANUAL, 5),
    "jog shift-right": (ControlCode.MANUAL, 6),
    "move x +1.5": (ControlCode.MOVE_FRONT_POS, 15),
    "move x 1.5": (ControlCode.MOVE_FRONT_POS, 15),
    "move front -0.1": (ControlCode.MOVE_FRONT_NEG, 1),
    "move rear +25.5": (ControlCode.MOVE_REAR_POS, 255),
    "move rear -2": (ControlCode.MOVE_REAR_NEG, 20),
    "move y +0.3": (ControlCode.MOVE_Y_POS, 3),
    "move y -0.3": (ControlCode.MOVE_Y_NEG, 3),
    "move x 0": (ControlCode.MOVE_FRONT_POS, 0),
    "rotate +1.57": (ControlCode.ROTATE_POS, 157),
    "rotate -0.05": (ControlCode.ROTATE_NEG, 5),
    "raw 1 160": (ControlCode.ROBOT, 160),
    "raw 0x0C 0x64": (ControlCode.ROTATE_POS, 100),
    "raw 13 255": (ControlCode.ROTATE_NEG, 255),
    "STOP": (ControlCode.ROBOT, RobotCommand.STOP),
}


@pytest.mark.parametrize("text, expected", EXPECTED.items())
def test_names(text, expected):
    request = command_from_words(text.split())
    assert isinstance(request, ControlRequest)
    assert (request.code, request.command) == expected
    assert request.address == 1


@pytest.mark.parametrize("word, query", [("task", Query.TASK), ("vehicle", Query.VEHICLE),
                                         ("speed", Query.SPEED), ("battery", Query.BATTERY)])
def test_reads(word, query):
    assert command_from_words(["read", word], address=5) == StatusRequest(5, query)


@pytest.mark.parametrize("text, message", [
    ("", "no command given"),
    ("fly", "unknown command 'fly'"),
    ("stop now", "stop takes 0 argument"),
    ("move x 30", "300 units of 0.1; one byte holds at most 255 (25.5 m)"),
    ("move x 1.55", "not a whole number of 0.1 m steps"),
    # were decimal.Overflow (abs() and the division of 1e999999) and int-to-text tracebacks
    ("move x 1e999999", "far more than 255 units of 0.1; one byte holds at most 255 (25.5 m)"),
    ("rotate -1e99999999999", "far more than 255 units of 0.01"),
    ("move x " + "9" * 5000, "far more than 255 units of 0.1"),
    # int("0x" + 5000 hex digits) is read, but no message could print it
    ("raw 0x" + "f" * 5000 + " 1", "control code must be a small whole number (decimal, or hex as 0x..), got 5002"),
    ("run-point " + "9" * 5000, "point number must be a small whole number"),
    ("move z 1", "move takes one of x|front|rear|y"),
    ("move x", "move takes 2 argument"),
    ("move x far", "must be a number"),
    ("move x nan", "must be a number"),
    ("rotate 3", "255 (2.55)"),
    ("rotate 0.001", "0.01"),
    ("speed trackless 5", "speed stage must be 0-3, got 5"),
    ("speed warp 1", "trackless|magnetic"),
    ("collision-range 4", "0-3"),
    ("jog up", "jog takes one of"),
    ("run-point 22", "point number must be 1-21"),
    ("run-point 0", "point number must be 1-21"),
    ("run-point x", "whole number"),
    ("read pressure", "read takes one of task|vehicle|speed|battery"),
    ("raw 14 0", "control code must be 1-13"),
    ("raw 1 32", "unknown robot command 0x20"),
    ("raw 2 9", "out of range 0-3"),
    ("raw 12 256", "does not fit in one byte"),
])
def test_bad_words(text, message):
    with pytest.raises(CommandError, match=message.replace("(", r"\(").replace(")", r"\)").replace("|", r"\|").replace(".", r"\.")):
        command_from_words(text.split())


@given(requests)
def test_words_for_round_trip(request):
    words = words_for(request)
    assert command_from_words(words, address=request.address) == request


@given(any_settings, requests)
def test_describe_never_fails_and_matches_bytes(settings, request):
    data = encode(request, settings)
    text = describe(request, settings)
    assert text and describe(data, settings) == text
    assert decode_frame(data, settings) == request


def test_describe_examples():
    s = Settings()
    assert describe(bytes.fromhex("01 06 01 A0 00 00 88 14"), s) == "stop (01/A0)"
    assert describe(command_from_words(["read", "task"]), s) == "read task status (query 0)"
    assert describe(command_from_words(["rotate", "+1"]), Settings(codes_10_13="hex")) == "rotate +1.00 (12/64)"
    assert describe(bytes.fromhex("01 01 03 00 00 01 FD 8E"), s) == "status reply: value 1, error 00 normal"
    assert describe(bytes.fromhex("01 86 03 02 61"), s) == "exception 03 (illegal data value) to function 06"
    assert describe(bytes.fromhex("01 06 01 A0 00 00 88 15"), s).startswith("invalid frame: byte 6: bad CRC")
    assert describe(bytes.fromhex("01 06 01 A0 00 00 88 14"), Settings(address=3)).endswith(
        "[address 1, not this robot's 3]")
    assert describe(encode(ControlRequest(0, 1, 0xA0)), s).endswith("[broadcast address 0]")


def test_describe_prefers_reply_errors_for_reply_shaped_bytes():
    text = describe(bytes.fromhex("01 01 03 00 09 00") + b"\x00\x00", Settings())
    assert "bad CRC" in text
    from verifier.protocol import with_crc
    text = describe(with_crc(bytes.fromhex("01 01 03 00 09 00")), Settings())
    assert text == "invalid frame: byte 4: unknown error code 09 (table 3: 00-03)"


def test_hex_bytes():
    assert hex_bytes(b"\x01\xab") == "01 AB"


def test_words_may_be_one_string():
    assert command_from_words("move x -2.5") == command_from_words(["move", "x", "-2.5"])
    assert command_from_words("  read   task ", address=4) == StatusRequest(4, Query.TASK)
