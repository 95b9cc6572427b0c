"""Request or reply: which side of the line sent a frame.

A passive monitor on a two-wire RS-485 line sees both sides on the same pair. Content
tells them apart for FC01 (a request carries query and quantity, a reply a byte count)
but not for FC06, whose normal reply echoes the request byte for byte. The master/slave
turn decides then: the robot only speaks after a request, within the reply time-out, and
answers each request once (Modbus over Serial Line V1.02 §2.4.1).
"""
from __future__ import annotations

from verifier import protocol
from verifier.protocol.codec import REQUEST_LENGTH
from verifier.protocol.describe import side_by_content

from .framer import Frame


def _looks_like_request(data: bytes, settings: protocol.Settings) -> bool:
    """A request by its shape (the CRC aside: a request with a bad CRC is still one)."""
    if len(data) != REQUEST_LENGTH:
        return False
    try:
        protocol.decode_request(protocol.with_crc(data[:-2]), settings)
    except protocol.FrameError:
        return False
    return True


class Classifier:
    def __init__(self, settings: protocol.Settings, reply_timeout_us: int, tolerance_us: int = 0):
        self.settings = settings
        self.reply_timeout_us = reply_timeout_us
        self.tolerance_us = tolerance_us
        self._waiting: Frame | None = None  # the request whose reply may still come
        self._waiting_decoded = None

    def direction(self, frame: Frame) -> str:
        """"tx" (PLC to robot) or "rx" (robot to PLC) for the next frame on the line."""
        if frame.direction is not None:
            direction = frame.direction
        else:
            direction = self._guess(frame)
        if direction == "tx":
            self._waiting = frame
            try:
                self._waiting_decoded = protocol.decode_request(frame.data, self.settings)
            except protocol.FrameError:
                self._waiting_decoded = None
        else:
            self._waiting = None  # answered; the request stays known for late replies
        return direction

    def _is_reply(self, frame: Frame) -> bool:
        if self._waiting_decoded is None:
            return False
        try:
            protocol.decode_reply(frame.data, self.settings, self._waiting_decoded)
        except protocol.FrameError:
            return False
        return True

    def _guess(self, frame: Frame) -> str:
        by_content = side_by_content(frame.data)
        if by_content is not None:
            return by_content
        waiting = self._waiting
        deadline = None if waiting is None else waiting.t_end_us + self.reply_timeout_us + self.tolerance_us
        if waiting is None or frame.t_start_us > deadline:
            # nobody is waiting for a reply, so only the master may speak - unless the frame
            # cannot be a request and answers the latest one (a late or a second reply); an
            # FC06 frame equal to the request is the master's retry
            if not _looks_like_request(frame.data, self.settings) and self._is_reply(frame):
                return "rx"
            return "tx"
        if self._is_reply(frame):
            return "rx"
        if frame.data[:6] == waiting.data[:6]:
            return "rx"  # the FC06 echo with a bad CRC, or a repeated frame the robot echoed
        if _looks_like_request(frame.data, self.settings) and frame.data[0] == self.settings.address:
            return "tx"  # the master did not wait for the reply (another address: a bad reply)
        return "rx"  # something came back, broken
