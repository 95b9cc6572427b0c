"""Cut a byte stream into frames by function code.

Every frame on this line has a fixed length once its function code is known: requests
(FC01, FC06) are 8 bytes, normal replies 8, exception replies (function | 0x80) 5. Real
RTU framing also uses the 3.5-character silence (the link model does that); this helper
is for streams without timing (TCP carrying raw RTU, captured logs, tests).
"""
from __future__ import annotations

from typing import Literal

from verifier.protocol.catalogue import EXCEPTION_FLAG, FUNCTION_CODES
from verifier.protocol.codec import EXCEPTION_REPLY_LENGTH, REPLY_LENGTHS, REQUEST_LENGTH
from verifier.protocol.crc import crc_ok

Direction = Literal["request", "reply"]


def frame_length(head: bytes, direction: Direction) -> int | None:
    """Length of the frame that starts with ``head`` (needs 2 bytes), or None if unknown.

    None means either fewer than two bytes are known yet or the function code is not one
    of this protocol's, so the frame's end can only be found by the line's silence.
    """
    if direction not in ("request", "reply"):
        raise ValueError(f"direction must be 'request' or 'reply', got {direction!r}")
    if len(head) < 2:
        return None
    function = head[1]
    if direction == "reply" and function & EXCEPTION_FLAG:
        return EXCEPTION_REPLY_LENGTH
    if function not in FUNCTION_CODES:
        return None
    return REQUEST_LENGTH if direction == "request" else REPLY_LENGTHS[function]


def frame_length_either_side(head: bytes) -> int | None:
    """The frame length ``head`` implies when the side that sent it is not known (a
    receive-only tap): an exception reply of a known function, or a function code whose
    requests and replies are equally long; None otherwise."""
    if len(head) < 2:
        return None
    function = head[1]
    if function & EXCEPTION_FLAG:
        return frame_length(head, "reply") if function & ~EXCEPTION_FLAG in FUNCTION_CODES else None
    request, reply = frame_length(head, "request"), frame_length(head, "reply")
    return request if request == reply else None


def garbled(frame: bytes) -> bool:
    """True when ``frame`` has no good CRC and is not even one of this protocol's frames by
    its length (`frame_length_either_side`: 8 bytes of function 01 or 06, or an exception's
    5): bytes read at another speed or parity than they were sent, or off a swapped pair,
    rather than a frame whose CRC its sender computed wrong (or sent high byte first)."""
    return not crc_ok(frame) and frame_length_either_side(frame) != len(frame)


#: the robot's serial line (its manual: 9600 baud, 8 data bits, no parity, 1 stop bit)
ROBOT_LINE = "9600 8N1"


def garbled_note(frames: int, line: str) -> str:
    """What `uitamr monitor`, `uitamr replay` and the emulator's summary say when every one
    of `frames` frames is `garbled`: the bytes were read at another speed or parity than the
    sender's (a PLC at 19200 read at 9600 gives half its bytes, none a frame) or off a
    swapped pair. The findings are CRC and FORMAT, whose advice points at the PLC's frame
    builder; this says to look at the line first. `line`: the speed and framing the bytes
    were read at ("9600 8N1"), named beside the robot's when it is another."""
    robots = "" if line == ROBOT_LINE else f" (the robot's is {ROBOT_LINE})"
    return (f"not one of the {frames} frame(s) has a good CRC: the line is probably at another speed or "
            f"parity than the {line} it was read at{robots}, or A and B are swapped; check those before "
            "the PLC's CRC routine and frame builder")


def split_frames(data: bytes, direction: Direction) -> tuple[list[bytes], bytes]:
    """Complete frames at the start of ``data`` and the bytes left over.

    The leftover is an incomplete frame, or starts with an unknown function code (its
    length cannot be known: end it with ``FrameSplitter.flush`` at the next silence).
    """
    frames: list[bytes] = []
    start = 0
    while True:
        length = frame_length(data[start:start + 2], direction)
        if length is None or len(data) - start < length:
            return frames, bytes(data[start:])
        frames.append(bytes(data[start:start + length]))
        start += length


class FrameSplitter:
    """Incremental ``split_frames``: ``feed`` bytes as they arrive, get whole frames back."""

    def __init__(self, direction: Direction) -> None:
        frame_length(b"", direction)  # validates the direction
        self.direction: Direction = direction
        self._pending = b""

    @property
    def pending(self) -> bytes:
        """Bytes received that do not yet make a whole frame."""
        return self._pending

    def feed(self, data: bytes) -> list[bytes]:
        frames, self._pending = split_frames(self._pending + bytes(data), self.direction)
        return frames

    def flush(self) -> bytes:
        """End of frame by silence: hand back (and forget) the incomplete bytes."""
        rest, self._pending = self._pending, b""
        return rest
