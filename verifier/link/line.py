"""A virtual RS-485 line at 9600 8N1, half duplex, between the PLC and the robot model.

Time is virtual (integer µs); nothing sleeps. The PLC side calls :meth:`Line.send` and
:meth:`Line.receive_until` with non-decreasing times; the line works out, byte by byte,
what each side hears and when.

Semantics (Modbus over Serial Line V1.02, §2.5.1.1):

* **Bytes take time.** A character is ``bits_per_char`` bits (10 for 8N1): 1041.67 µs at
  9600 bit/s. Byte *k* of a send starting at *s* occupies [s + k·T, s + (k+1)·T), rounded
  to whole µs without drift. A byte reaches the receiver when its stop bit ends.
* **Sending while still sending** (the PLC's UART is busy): the new bytes follow back to
  back, with no gap, exactly as a UART transmit buffer does - so they join the frame
  being sent unless t3.5 of silence separates them.
* **Frames end after t3.5 of silence.** The robot receives a frame once no byte has
  started within t3.5 after its last byte.
* **A gap over t1.5 inside a frame** marks the frame broken: a ``gap`` event, and at its
  end the whole frame is ``discarded`` (the robot never sees it, so it does not answer).
* **Turnaround.** The robot answers ``Reply.delay_us`` after the end of the request's last
  byte, but never before t3.5 has passed (a slave cannot know the frame ended earlier).
  The robot's own replies never overlap each other: a second reply waits for the first.
* **Collisions.** Both sides transmitting at once is a ``collision`` event with its time
  and both frames. The robot's receiver is off while it transmits, so PLC bytes sent
  during a reply are lost to it (the rest of that PLC frame arrives broken and is
  discarded). ASSUMPTION (half-duplex 2-wire ports, e.g. FX3U-485-BD in 2-wire mode):
  the PLC does not receive while it transmits, so robot bytes that overlap a PLC
  transmission never reach the PLC.

The line drives the robot's clock: do not call ``robot.advance`` yourself while a line
owns the robot; call :meth:`Line.advance` and then read ``line.robot``.
The PLC's endpoint (:meth:`Line.send`, :meth:`Line.receive_until`) runs the robot only
as far as a request needs: the robot never transmits on its own, so it catches up at the
next request or :meth:`Line.advance`, through the same task and fault times. On a quiet
line (no byte under way, no frame waiting for its t3.5, nothing due for the PLC before
``t_us``) ``receive_until`` only moves the line's clock. That keeps the PLC's per-scan
poll cheap. Contract for callers (the simulated PLC's serial port uses it to skip the
call on every scan): for ``now_us <= t_us < quiet_until_us`` (integer ``t_us``),
``receive_until(t_us)`` returns no bytes and only sets ``now_us = t_us``.
"""
from __future__ import annotations

import bisect
from collections import deque
from dataclasses import dataclass, field

from verifier.amr.robot import Robot
from verifier.link.trace import RX, TX, LineEvent, TraceFrame
from verifier.protocol.codec import hex_bytes
from verifier.protocol.timing import BAUD, BITS_PER_CHAR, gap_limit_us, silence_us


@dataclass(frozen=True)
class LineConfig:
    """Line speed and the Modbus silences.

    ``t1_5_us``/``t3_5_us`` default to 1.5 and 3.5 character times; above 19200 bit/s
    Modbus fixes them at 750 µs and 1750 µs (Modbus over Serial Line V1.02 §2.5.1.1).
    """

    baud: int = BAUD
    bits_per_char: int = BITS_PER_CHAR
    t1_5_us: int | None = None
    t3_5_us: int | None = None

    def __post_init__(self) -> None:
        if not isinstance(self.baud, int) or self.baud <= 0:
            raise ValueError(f"baud must be a positive whole number, got {self.baud!r}")
        if not isinstance(self.bits_per_char, int) or not 7 <= self.bits_per_char <= 12:
            raise ValueError(f"bits_per_char must be 7-12, got {self.bits_per_char!r}")

    def offset_us(self, k: int) -> int:
        """Start of character ``k`` after the start of character 0 (no rounding drift)."""
        scaled = k * self.bits_per_char * 1_000_000
        return (scaled + self.baud // 2) // self.baud

    @property
    def byte_time_us(self) -> int:
        return self.offset_us(1)

    @property
    def gap_limit_us(self) -> int:
        """t1.5: the longest silence allowed inside a frame."""
        if self.t1_5_us is not None:
            return self.t1_5_us
        return gap_limit_us(self.baud, self.bits_per_char)

    @property
    def frame_gap_us(self) -> int:
        """t3.5: the silence that ends a frame."""
        if self.t3_5_us is not None:
            return self.t3_5_us
        return silence_us(self.baud, self.bits_per_char)


_NEVER = float("inf")


@dataclass(slots=True)
class _Byte:
    start: int
    end: int
    value: int
    lost: bool = False  # never reaches the other side (collision)
    unreadable: str | None = None  # why the robot's receiver cannot read it (another line format)


@dataclass(slots=True)
class _Transmission:
    """One send() call or one robot reply: the unit a collision event names."""

    start: int
    end: int
    data: bytes
    origin: str | None = None
    bytes_: list[_Byte] = field(default_factory=list)
    # the replies it collided with, themselves (an id() could be reused once a reply is let go)
    collided_with: list["_Transmission"] = field(default_factory=list)


@dataclass(slots=True)
class _OpenFrame:
    """The trace frame being built from PLC sends (t3.5 of silence closes it)."""

    start: int
    end: int
    data: bytearray
    origin: str | None


class Line:
    """The virtual half-duplex line; see the module docstring for what it models."""

    def __init__(self, robot: Robot, config: LineConfig | None = None) -> None:
        self.robot = robot
        self.config = config if config is not None else LineConfig()
        self.now_us = 0
        self._t15 = self.config.gap_limit_us
        self._t35 = self.config.frame_gap_us
        self._plc_queue: deque[_Byte] = deque()  # PLC bytes the robot has yet to hear
        self._plc_free_us = 0
        self._plc_sends: list[_Transmission] = []
        self._replies: list[_Transmission] = []
        self._robot_free_us = 0
        self._to_plc: deque[_Byte] = deque()
        self._frame: list[_Byte] = []
        self._frame_broken: str | None = None
        self._frame_paused = False  # the frame was broken by a pause (not by a collision)
        self._tx_frames: list[_OpenFrame] = []
        self._rx_frames: list[TraceFrame] = []
        self._events: list[LineEvent] = []
        # before this time nothing can happen on the line (see the module docstring)
        self.quiet_until_us: int | float = 0
        self._offsets = [0]  # offset_us(k), computed once per k
        self.settled_until_us = 0  # see take_settled
        # the "gap" events (a pause inside a PLC frame) as they happen, which is in time
        # order: what the format rule reads of the events while a run is judged as it goes
        self.gaps: list[LineEvent] = []

    # ---- the PLC's endpoint ----------------------------------------------------------------

    #: `send` takes ``unreadable``: the simulated PLC's serial port tells a frame sent at
    #: another line format than the robot's (verifier.sim.serial.SerialChannel)
    accepts_unreadable = True

    def send(self, data: bytes, t_us: int, origin: str | None = None, unreadable: str | None = None) -> int:
        """The PLC starts transmitting ``data`` at ``t_us`` (after anything it is still
        sending). Returns when the last byte's stop bit ends. ``unreadable`` says why the
        robot's receiver cannot read these bytes (the PLC's port runs at another speed or
        character format): they are on the line as sent, but the robot discards the frame."""
        data = bytes(data)
        self._check_time(t_us, "send")
        self._work_until(t_us)
        if not data:
            return max(t_us, self._plc_free_us)
        start = max(t_us, self._plc_free_us)
        send = _Transmission(start, 0, data, origin, self._on_line(start, data))
        if unreadable is not None:
            for byte in send.bytes_:
                byte.unreadable = unreadable
        self._plc_queue.extend(send.bytes_)
        send.end = send.bytes_[-1].end
        self._plc_free_us = send.end
        self._plc_sends.append(send)
        self._trace_tx(send)
        for reply in self._replies_overlapping(send.start, send.end):
            self._collide(send, reply)
        self._forget_past()
        self.quiet_until_us = self._next_change_us()
        return send.end

    def receive_until(self, t_us: int) -> list[tuple[int, int]]:
        """(byte value, arrival µs) of the robot's bytes that reached the PLC since the last
        call, up to ``t_us``. Bytes lost in a collision are not delivered."""
        if self.now_us <= t_us < self.quiet_until_us and type(t_us) is int:
            self.now_us = t_us  # a quiet line: nothing to work out (see the module docstring)
            return []
        self._check_time(t_us, "receive_until")
        self._work_until(t_us)
        received = []
        while self._to_plc and self._to_plc[0].end <= t_us:
            byte = self._to_plc.popleft()
            if not byte.lost:
                received.append((byte.value, byte.end))
        self.quiet_until_us = self._next_change_us()
        return received

    def advance(self, t_us: int) -> None:
        """Work out everything that happens on the line up to ``t_us`` and bring the robot's
        clock there (to the end of the frame it is still hearing, if any)."""
        self._check_time(t_us, "advance")
        self._work_until(t_us)
        self.robot.advance(self._frame[-1].end if self._frame else t_us)

    def _work_until(self, t_us: int) -> None:
        """The line up to ``t_us``: bytes heard, frames completed and answered. The robot
        runs only as far as a request needs (see the module docstring)."""
        queue = self._plc_queue
        while queue and queue[0].end <= t_us:
            byte = queue.popleft()
            if self._frame and byte.start - self._frame[-1].end >= self._t35:
                self._complete_frame()
            self._hear(byte)
        if self._frame:
            quiet_from = self._frame[-1].end + self._t35
            if quiet_from <= t_us and (not queue or queue[0].start >= quiet_from):
                self._complete_frame()
        self.now_us = t_us
        self.quiet_until_us = self._next_change_us()

    def _next_change_us(self) -> int | float:
        """The first time at which the line has something to work out: a PLC byte reaching
        the robot, an open frame's t3.5, a robot byte reaching the PLC (infinity: none)."""
        first = _NEVER
        if self._plc_queue:
            first = self._plc_queue[0].end
        if self._frame and self._frame[-1].end + self._t35 < first:
            first = self._frame[-1].end + self._t35
        if self._to_plc and self._to_plc[0].end < first:
            first = self._to_plc[0].end
        return first

    # ---- what happened ---------------------------------------------------------------------

    @property
    def trace(self) -> list[TraceFrame]:
        """Every frame scheduled so far, both directions, in order of start time.

        A PLC frame appears as soon as it is sent (later back-to-back sends extend it); a
        reply appears once the robot has the request (t3.5 after the request ended).
        """
        frames = [TraceFrame(f.start, f.end, TX, bytes(f.data), f.origin) for f in self._tx_frames]
        frames += self._rx_frames
        frames.sort(key=lambda f: (f.t_start_us, f.direction == RX))
        return frames

    def hand_over_trace(self) -> list[TraceFrame]:
        """`trace`, for a caller done with the line: the line lets go of its frames (an hour
        of traffic is tens of thousands of them, not to be held twice); later frames are
        recorded afresh."""
        frames = self.trace
        self._tx_frames, self._rx_frames = [], []
        return frames

    def take_settled(self) -> list[TraceFrame]:
        """The frames at the head of `trace` that nothing still to come on the line can
        change or precede, handed over (the line lets go of them): each ended t3.5 or more
        before the line's clock, so a PLC frame can no longer grow, and every frame still
        to come starts later (a PLC send starts at the clock or after; a reply, t3.5 after
        a request the robot has not yet heard in full). In `trace` order; `trace` then
        starts at the first frame not handed over, and no frame still to come starts
        before `settled_until_us`."""
        limit = self.now_us - self._t35
        frames = self.trace
        count = 0
        while count < len(frames) and frames[count].t_end_us <= limit:
            count += 1
        taken = frames[:count]
        self.settled_until_us = min(self.now_us, frames[count].t_start_us) if count < len(frames) else self.now_us
        tx = sum(1 for f in taken if f.direction == TX)
        del self._tx_frames[:tx]
        del self._rx_frames[:count - tx]
        return taken

    @property
    def events(self) -> list[LineEvent]:
        """Line events and the robot's own events (kind ``robot.<kind>``), in time order."""
        merged = list(self._events)
        merged += [LineEvent(e.t_us, f"robot.{e.kind}", e.message) for e in self.robot.events]
        merged.sort(key=lambda e: e.t_us)
        return merged

    def event_lists(self) -> tuple[list[LineEvent], list]:
        """The line's own events and its robot's (`robot.events`), as held: a caller that
        lists only some of them may thin these lists (verifier.verify.events_shown)."""
        return self._events, self.robot.events

    # ---- the robot's receiver --------------------------------------------------------------

    def _hear(self, byte: _Byte) -> None:
        if self._robot_transmitting(byte.start, byte.end):
            byte.lost = True
            if self._frame_broken is None:
                self._frame_broken = "bytes sent while the robot was transmitting were lost"
        elif self._frame and byte.start - self._frame[-1].end > self._t15:
            gap = byte.start - self._frame[-1].end
            first = self._frame_broken is None
            if first:
                self._frame_broken = (f"a gap of {gap / 1000:.3f} ms inside the frame "
                                      f"(more than t1.5 = {self._t15 / 1000:.3f} ms)")
                self._frame_paused = True
            # every pause, not the first only (the format rule splits requests run together at
            # each); none in a frame that lost bytes to a collision first, as before. The bytes
            # before it with the first only: a program pausing after every byte of a long
            # frame would otherwise copy the frame once a byte
            if self._frame_paused:
                self._event(byte.start, "gap",
                            f"silence of {gap / 1000:.3f} ms between bytes of one frame "
                            f"(more than t1.5 = {self._t15 / 1000:.3f} ms): the robot will discard it",
                            (bytes(b.value for b in self._frame),) if first else ())
        if byte.unreadable is not None and self._frame_broken is None:
            self._frame_broken = byte.unreadable
        self._frame.append(byte)

    def _complete_frame(self) -> None:
        frame, broken = self._frame, self._frame_broken
        self._frame, self._frame_broken, self._frame_paused = [], None, False
        data = bytes([b.value for b in frame])
        end = frame[-1].end
        if broken is not None:
            self._event(end, "discarded", f"frame {hex_bytes(data)} discarded by the robot: {broken}",
                        (data,))
            return
        self.robot.advance(end)
        reply = self.robot.on_request(data, end, start_us=frame[0].start)
        if reply is None or not reply.data:
            return
        start = max(end + max(reply.delay_us, self._t35), self._robot_free_us)
        tx = _Transmission(start, 0, bytes(reply.data))
        tx.bytes_ = self._on_line(start, tx.data)
        self._to_plc.extend(tx.bytes_)
        tx.end = tx.bytes_[-1].end
        self._robot_free_us = tx.end
        self._replies.append(tx)
        self._rx_frames.append(TraceFrame(tx.start, tx.end, RX, tx.data))
        for send in self._sends_overlapping(tx.start, tx.end):
            self._collide(send, tx)

    def _robot_transmitting(self, start: int, end: int) -> bool:
        for reply in reversed(self._replies):
            if reply.end <= start:
                return False  # replies are in time order and never overlap each other
            if reply.start < end:
                return True
        return False

    def _on_line(self, start: int, data: bytes) -> list[_Byte]:
        """The characters of `data` sent back to back from `start` (byte k occupies
        [start + offset(k), start + offset(k + 1)))."""
        offsets = self._offsets
        while len(offsets) <= len(data):
            offsets.append(self.config.offset_us(len(offsets)))
        return [_Byte(start + offsets[k], start + offsets[k + 1], value) for k, value in enumerate(data)]

    # ---- collisions --------------------------------------------------------------------------

    def _replies_overlapping(self, start: int, end: int):
        for reply in reversed(self._replies):
            if reply.end <= start:
                break  # replies are in time order and never overlap each other
            if reply.start < end:
                yield reply

    def _sends_overlapping(self, start: int, end: int):
        for send in reversed(self._plc_sends):
            if send.end <= start:
                break  # sends are in time order and never overlap each other
            if send.start < end:
                yield send

    def _forget_past(self) -> None:
        """Let go of transmissions no future overlap test can reach (an hour of traffic
        kept them all, with their bytes: hundreds of thousands of objects for Python's
        garbage collector to walk again and again).  Every later test starts at or after
        ``horizon`` (the line's clock, the bytes still to be heard or completed) and scans
        back from the newest transmission, stopping at the first one that ended by its
        start: keeping the newest one that ended by ``horizon`` and everything after it
        leaves every answer the same."""
        horizon = self.now_us
        if self._plc_queue and self._plc_queue[0].start < horizon:
            horizon = self._plc_queue[0].start
        if self._frame and self._frame[0].start < horizon:
            horizon = self._frame[0].start
        for done in (self._replies, self._plc_sends):
            k = len(done) - 1
            while k > 0 and done[k].end > horizon:
                k -= 1
            if k > 0:
                del done[:k]

    def _collide(self, send: _Transmission, reply: _Transmission) -> None:
        if any(seen is reply for seen in send.collided_with):
            return
        send.collided_with.append(reply)
        for byte in reply.bytes_:
            if byte.start < send.end and byte.end > send.start:
                byte.lost = True
        t = max(send.start, reply.start)
        where = f" (sent by {send.origin})" if send.origin else ""
        self._event(t, "collision",
                    f"both sides transmitting at {t / 1e6:.6f} s: PLC frame {hex_bytes(send.data)}{where} "
                    f"overlaps robot reply {hex_bytes(reply.data)}",
                    (send.data, reply.data))

    # ---- trace and housekeeping --------------------------------------------------------------

    def _trace_tx(self, send: _Transmission) -> None:
        last = self._tx_frames[-1] if self._tx_frames else None
        if last is not None and send.start - last.end < self._t35:
            last.data += send.data
            last.end = send.end
        else:
            self._tx_frames.append(_OpenFrame(send.start, send.end, bytearray(send.data), send.origin))

    def _event(self, t_us: int, kind: str, message: str, frames: tuple[bytes, ...] = ()) -> None:
        event = LineEvent(t_us, kind, message, frames)
        bisect.insort(self._events, event, key=lambda e: e.t_us)
        if kind == "gap":
            self.gaps.append(event)

    def _check_time(self, t_us: int, what: str) -> None:
        if not isinstance(t_us, int):
            raise TypeError(f"{what}: time must be integer microseconds, got {t_us!r}")
        if t_us < self.now_us:
            raise ValueError(f"{what} at {t_us} µs: the line is already at {self.now_us} µs "
                             "(virtual time only moves forward)")
