"""Cutting the bytes a real port delivers into request frames, on the wall clock.

Modbus RTU ends a frame after 3.5 characters of silence (3.65 ms at 9600). On a real bench
the bytes pass through USB adapters, pty pairs or TCP converters that deliver them in
chunks with their own delays (an FTDI adapter waits up to its 16 ms latency timer), so a
literal t3.5 on arrival times would cut frames apart. The assembler therefore:

* completes a frame **at once** when the bytes so far are a whole request with a good CRC:
  FC01/FC06 by this protocol's lengths (``verifier.protocol.stream``), other standard
  function codes by pymodbus's request decoders (so a master's FC03 gets its exception 01
  without waiting); several requests back to back are cut apart the same way;
* otherwise waits for ``silence_us`` without a byte (default 20 ms, ``--frame-gap-ms``) and
  hands over whatever came as one frame - the robot then applies the Modbus rules (bad CRC:
  silence; unknown function code with a good CRC: exception 01);
* drops a run of more than 256 bytes without a silence (the longest Modbus RTU frame) as a
  flood, and everything after it until the line falls silent - or until a whole good
  request arrives after at least t3.5 of quiet (below), which ends the flood there.

* remembers where a chunk arrived after at least t3.5 of quiet (3.65 ms at 9600): if the
  bytes from there on make a whole request with a good CRC, that request is cut off and
  answered and the bytes before it go to the robot as a frame of their own (which it
  ignores) - the Modbus rule that t3.5 of silence ends a frame, without waiting for the
  longer wall-clock silence.

So noise glued to a request costs that request (as on a real line), and the first valid
request after a t3.5 silence is answered. (pymodbus 3.16's RTU framer, by contrast, has no
timing at all: a noise byte before a request loses the request, and an unknown function
code stays in its buffer and swallows the next request.)
"""
from __future__ import annotations

from dataclasses import dataclass

from pymodbus.pdu import DecodePDU

from verifier.protocol.codec import MAX_FRAME
from verifier.protocol.crc import crc_ok
from verifier.protocol.stream import frame_length
from verifier.protocol.timing import T3_5_US

DEFAULT_SILENCE_US = 20_000
_MODBUS_REQUESTS = DecodePDU(is_server=True)


def request_length(head: bytes) -> int | None:
    """Length of the request frame starting with ``head``, when it can be known yet."""
    if len(head) < 2:
        return None
    length = frame_length(head[:2], "request")
    if length is not None:
        return length
    try:
        pdu_class = _MODBUS_REQUESTS.lookupPduClass(head)
        return pdu_class.calculateRtuFrameSize(head) if pdu_class is not None else None
    except Exception:  # noqa: BLE001 - third-party decoder fed with line noise must never stop us
        return None  # not enough bytes yet to know, or not a standard request


@dataclass(frozen=True)
class ReceivedFrame:
    """Bytes taken as one request: when the first and last of them arrived, and why it ended."""

    data: bytes
    t_first_us: int
    t_last_us: int
    ended_by: str  # "length" (whole request, good CRC) or "silence"


@dataclass(frozen=True)
class Dropped:
    """Bytes thrown away as a flood."""

    data_len: int
    t_us: int
    reason: str


class RequestAssembler:
    """Feed it bytes with their arrival times; it returns frames (and floods dropped)."""

    def __init__(self, silence_us: int = DEFAULT_SILENCE_US, max_frame: int = MAX_FRAME,
                 t3_5_us: int = T3_5_US) -> None:
        if silence_us <= 0:
            raise ValueError("silence must be positive")
        self.silence_us = silence_us
        self.t3_5_us = min(t3_5_us, silence_us)
        self._boundaries: list[tuple[int, int, int]] = []  # (offset, first µs, previous last µs)
        self.max_frame = max_frame
        self._buffer = bytearray()
        self._first_us = 0
        self._last_us = 0
        self._flooding = False
        self._flood_bytes = 0
        self._flood_started = 0
        self._flood_tail: bytearray | None = None  # bytes of a flood since its last t3.5 quiet
        self._flood_tail_us = 0  # when the first of them arrived

    @property
    def pending(self) -> bytes:
        return bytes(self._buffer)

    def discard(self) -> bytes:
        """Throw away what waits for a silence (the peer went away); returns those bytes.
        The tail of a flood being dropped is not kept, so it is not returned either."""
        left = bytes(self._buffer)
        self._clear()
        self._flooding, self._flood_tail = False, None
        return left

    def deadline_us(self) -> int | None:
        """When :meth:`poll` can next complete something (None: nothing waits)."""
        if self._buffer or self._flooding:
            return self._last_us + self.silence_us
        return None

    def feed(self, data: bytes, t_us: int) -> list[ReceivedFrame | Dropped]:
        """Bytes that arrived together at ``t_us``."""
        out: list[ReceivedFrame | Dropped] = self.poll(t_us)
        quiet_before = bool(data) and t_us - self._last_us >= self.t3_5_us
        if self._buffer and quiet_before:
            self._boundaries.append((len(self._buffer), t_us, self._last_us))
        if self._flooding and quiet_before:
            self._flood_tail, self._flood_tail_us = bytearray(), t_us
        for byte in data:
            if self._flooding:
                self._flood_bytes += 1
                self._last_us = t_us
                out += self._request_ending_flood(byte, t_us)
                continue
            if not self._buffer:
                self._first_us = t_us
            self._buffer.append(byte)
            self._last_us = t_us
            if len(self._buffer) > self.max_frame:
                self._flooding, self._flood_tail = True, None
                self._flood_bytes = len(self._buffer)
                self._flood_started = self._first_us
                self._clear()
                continue
            out += self._whole_request(t_us)
        return out

    def _whole_request(self, t_us: int) -> list[ReceivedFrame]:
        """The buffer, or its tail after a t3.5 quiet, when it is a whole good request."""
        starts = [(0, self._first_us, 0)] + self._boundaries
        for offset, first_us, previous_last_us in reversed(starts):
            tail = bytes(self._buffer[offset:])
            length = request_length(tail)
            if length is None or len(tail) != length or not crc_ok(tail):
                continue
            found = []
            if offset:
                found.append(ReceivedFrame(bytes(self._buffer[:offset]), self._first_us,
                                           previous_last_us, "silence"))
            found.append(ReceivedFrame(tail, first_us, t_us, "length"))
            self._clear()
            return found
        return []

    def _request_ending_flood(self, byte: int, t_us: int) -> list[ReceivedFrame | Dropped]:
        """t3.5 of silence ends a flood as it ends any frame: a whole good request made of the
        bytes since the flood's last quiet is answered, and the flood before it dropped."""
        tail = self._flood_tail
        if tail is None:
            return []
        tail.append(byte)
        length = request_length(bytes(tail))
        if (length is not None and len(tail) > length) or len(tail) > self.max_frame:
            self._flood_tail = None  # no request: the flood goes on
            return []
        if len(tail) != length or not crc_ok(tail):
            return []
        dropped = self._flood_bytes - len(tail)
        self._flooding, self._flood_tail = False, None
        return [Dropped(dropped, self._flood_started, self._flood_reason(dropped)),
                ReceivedFrame(bytes(tail), self._flood_tail_us, t_us, "length")]

    def _flood_reason(self, count: int) -> str:
        return (f"{count} bytes without a silence (more than {self.max_frame}, "
                "the longest Modbus RTU frame): dropped")

    def _clear(self) -> None:
        self._buffer.clear()
        self._boundaries.clear()

    def poll(self, t_us: int) -> list[ReceivedFrame | Dropped]:
        """Complete what a silence since the last byte has ended, as of ``t_us``."""
        if t_us - self._last_us < self.silence_us:
            return []
        if self._flooding:
            self._flooding, self._flood_tail = False, None
            return [Dropped(self._flood_bytes, self._flood_started, self._flood_reason(self._flood_bytes))]
        if not self._buffer:
            return []
        frame = ReceivedFrame(bytes(self._buffer), self._first_us, self._last_us, "silence")
        self._clear()
        return [frame]
