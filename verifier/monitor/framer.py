"""Bytes as the host received them, cut into RTU frames.

On the wire a frame ends with 3.5 characters of silence. The host does not see the wire:
a USB adapter hands bytes over in chunks, after its latency timer (FTDI: 16 ms by
default) or when its buffer fills, so one frame may come in two chunks with a "gap"
between them and a request and its reply may come in one chunk. The framer therefore
cuts by content first — every frame of this protocol is 8 bytes, an exception reply 5,
known from the function code — and by silence only where content cannot tell: a gap ends
a frame of unknown length when it exceeds t3.5, and a frame of known length that is still
incomplete only when it exceeds t3.5 plus the host's timing tolerance; so does a lone
byte, whose length its function code, the next byte, will tell (the latency timer may run
out one byte into a frame).

Times: a chunk's bytes are taken to have arrived back to back, the last one when the read
returned, so a frame starts one frame-time before the chunk that completes it (or at its
first chunk's estimated start when it came in several).

With a tolerance of 0 the host's times are taken as exact (a capture with the wire's
timing): frames end by the t3.5 silence alone, exactly as Modbus RTU defines them.
"""
from __future__ import annotations

from dataclasses import dataclass

from verifier.protocol import timing as line_timing
from verifier.protocol.codec import MAX_FRAME
from verifier.protocol.stream import frame_length_either_side

from .capture import Chunk

#: default host timing tolerance: above an FTDI adapter's default 16 ms latency timer
DEFAULT_TOLERANCE_US = 20_000


@dataclass(frozen=True)
class LineTiming:
    """The line's character timing (9600 8N1 unless told otherwise) and the host's
    tolerance for where it cannot see gaps."""

    baud: int = line_timing.BAUD
    bits_per_char: int = line_timing.BITS_PER_CHAR
    tolerance_us: int = DEFAULT_TOLERANCE_US

    @property
    def silence_us(self) -> int:
        """t3.5 (for baud rates above 19200 the standard fixes it at 1.75 ms)."""
        return line_timing.silence_us(self.baud, self.bits_per_char)

    def frame_us(self, length: int) -> int:
        return line_timing.frame_time_us(length, self.baud, self.bits_per_char)


@dataclass(frozen=True)
class Frame:
    t_start_us: int
    t_end_us: int
    data: bytes
    direction: str | None = None  # known only when the capture said it


class Framer:
    def __init__(self, timing: LineTiming = LineTiming()):
        self.timing = timing
        self._buffer = bytearray()
        self._arrivals: list[int] = []  # estimated arrival (end) of each buffered byte
        self._last_us: int | None = None  # arrival of the latest byte
        self._previous_end_us: int | None = None  # end of the latest frame

    @property
    def pending(self) -> bytes:
        return bytes(self._buffer)

    def feed(self, chunk: Chunk) -> list[Frame]:
        """The frames this chunk completes (a silence before it may end a pending one)."""
        if chunk.direction is not None:  # a frame of a trace: whole, direction known
            out = self.flush()
            start = chunk.t_start_us
            if start is None:  # a tx/rx line of a plain capture: it lasted its length
                start = chunk.t_us - self.timing.frame_us(len(chunk.data))
                if self._previous_end_us is not None:
                    start = max(start, self._previous_end_us)
            self._previous_end_us = self._last_us = chunk.t_us
            return out + [Frame(start, chunk.t_us, bytes(chunk.data), chunk.direction)]
        out: list[Frame] = []
        count = len(chunk.data)
        arrivals = [chunk.t_us - self.timing.frame_us(count - 1 - i) for i in range(count)]
        if self._last_us is not None:  # bytes arrive in order
            arrivals = [max(t, self._last_us) for t in arrivals]
        if self._buffer and self._silence_ends_frame(arrivals[0] - self.timing.frame_us(1)):
            out += self.flush()
        self._buffer += chunk.data
        self._arrivals += arrivals
        self._last_us = arrivals[-1]
        out += self._cut()
        return out

    def poll(self, now_us: int) -> list[Frame]:
        """Frames ended by the silence up to `now_us` (live use: call when no bytes came)."""
        if self._buffer and self._silence_ends_frame(now_us):
            return self.flush()
        return []

    def flush(self) -> list[Frame]:
        """The pending bytes as a frame (at the end of a capture, or after a silence)."""
        if not self._buffer:
            return []
        frame = self._frame(0, len(self._buffer))
        self._drop(len(self._buffer))
        return [frame]

    def finish(self) -> tuple[list[Frame], bytes]:
        """At the end of the capture: (the pending bytes as a frame, b""), or ([], the
        pending bytes) when they begin a frame of known length but stop short of it: the
        end of the capture cut that frame, the PLC did not send it short."""
        pending = self.pending
        length = frame_length_either_side(pending)
        if length is not None and len(pending) < length:
            self._drop(len(pending))
            return [], pending
        return self.flush(), b""

    def _frame(self, at: int, length: int) -> Frame:
        """`length` buffered bytes from `at` on as a frame: it ends when its last byte arrived
        and lasted its length at the line's speed, but began no earlier than its first byte
        arrived (a pty or a fast adapter delivers faster than the line) nor before the frame
        before it ended, and the first frame not before 0, the session's first byte: the
        first byte's arrival, estimated from its chunk's time in whole µs, less one byte's
        time could come out 1 µs before it, and a trace refuses a negative time (a monitor's
        trace its own replay refused). The caller drops the bytes (`_drop`) once it has cut
        its frames."""
        data = bytes(self._buffer[at:at + length])
        first, end = self._arrivals[at], self._arrivals[at + length - 1]
        start = max(end - self.timing.frame_us(length), first - self.timing.frame_us(1),
                    0 if self._previous_end_us is None else self._previous_end_us)
        self._previous_end_us = end
        return Frame(start, end, data)

    def _drop(self, count: int) -> None:
        """Forget the first `count` buffered bytes: once per chunk, not once per frame (a
        list loses its first items by moving all the others: a chunk of a whole capture on
        one line took time in the square of its length)."""
        del self._buffer[:count]
        del self._arrivals[:count]

    def _silence_ends_frame(self, t_us: int) -> bool:
        gap = t_us - (self._last_us if self._last_us is not None else t_us)
        length = frame_length_either_side(self._buffer)
        undecided = len(self._buffer) < 2 or (  # one byte: its frame's length is not known yet
            length is not None and (len(self._buffer) < length or len(self._buffer) == length + 1))
        if undecided:  # a frame, or the next frame's first byte, still incomplete
            return gap >= self.timing.silence_us + self.timing.tolerance_us
        return gap >= self.timing.silence_us

    def _cut(self) -> list[Frame]:
        """Whole frames at the front of the buffer, by their known length, where the
        content shows where one frame ends: the bytes after it begin another frame of this
        protocol. A frame followed by bytes that begin none (a robot appending garbage to a
        reply, noise) is not cut: it ends at the silence, as on the wire. A frame of known
        length with nothing after it yet is complete at once, unless the host's times are
        exact (no tolerance): then frames end by the t3.5 silence alone, as Modbus RTU
        defines them."""
        out: list[Frame] = []
        exact = self.timing.tolerance_us == 0
        buffer, at = self._buffer, 0  # the frames cut so far end at `at`
        while True:
            length = frame_length_either_side(buffer[at:at + 2])
            left = len(buffer) - at
            if length is not None and left == length and not exact:
                out.append(self._frame(at, length))
                at += length
                continue
            whole = length is not None and left >= length
            if not whole or frame_length_either_side(buffer[at + length:at + length + 2]) is None:
                if left >= MAX_FRAME:  # noise with no frame in it: let it go
                    out.append(self._frame(at, left))
                    at += left
                self._drop(at)
                return out
            out.append(self._frame(at, length))
            at += length
