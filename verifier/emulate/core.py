"""The robot on the wall clock: frames in, scheduled replies out, and the live log.

Transport-free: ``ports`` feeds it the frames its assemblers cut and writes the replies
when they fall due. Robot time is microseconds since the emulator started (monotonic).
"""
from __future__ import annotations

import time
from collections import Counter
from dataclasses import dataclass
from typing import Callable

from verifier.amr import Robot
from verifier.emulate.assembler import Dropped, ReceivedFrame
from verifier.protocol.codec import decode_reply, decode_request, hex_bytes
from verifier.protocol.stream import ROBOT_LINE, garbled, garbled_note
from verifier.protocol.describe import describe
from verifier.protocol.frames import FrameError, Request
from verifier.protocol.timing import T3_5_US


@dataclass(frozen=True)
class Outgoing:
    """Reply bytes to write once the wall clock reaches ``due_us``."""

    due_us: int
    data: bytes
    request: Request | None = None  # what it answers, to describe the reply in the log


class Emulator:
    """Hands received frames to the robot and logs every frame and robot event.

    ``t3_5_us`` is the line's frame gap (3.5 characters at its speed): no reply starts
    sooner after its request, whatever the turnaround, because a slave cannot know the
    request has ended before that silence (Modbus over Serial Line V1.02 §2.5.1.1) - the
    same floor the verifier's line (``verifier.link.line``) puts under the turnaround.
    ``read_at`` is the speed and framing the bytes are read at ("9600 8N1"; over TCP, the
    converter's line), which the summary names when no frame has a good CRC.
    """

    def __init__(self, robot: Robot, log: Callable[[str], None],
                 clock_ns: Callable[[], int] = time.monotonic_ns, t3_5_us: int = T3_5_US,
                 read_at: str = ROBOT_LINE) -> None:
        self.robot = robot
        self.t3_5_us = t3_5_us
        self.read_at = read_at
        self._log = log
        self._clock_ns = clock_ns
        self._t0_ns = clock_ns()
        self._events_seen = 0
        self.stats: Counter[str] = Counter()

    def now_us(self) -> int:
        return (self._clock_ns() - self._t0_ns) // 1000

    # ---- traffic -------------------------------------------------------------------------

    def handle(self, item: ReceivedFrame | Dropped, peer: str = "") -> Outgoing | None:
        """A frame (or a dropped flood) from a port; the reply to send, if any."""
        where = f" [{peer}]" if peer else ""
        if isinstance(item, Dropped):
            self.stats["dropped bytes"] += item.data_len
            self.line(item.t_us, "!!", f"{item.reason}{where}")
            return None
        self.stats["frames in"] += 1
        if garbled(item.data):
            self.stats["garbled"] += 1
        settings = self.robot.settings
        self.line(item.t_last_us, "<-", f"{hex_bytes(item.data)}  "
                  f"{describe(item.data, settings, 'request')}{where}")
        t = max(item.t_last_us, self.robot.now_us)
        reply = self.robot.on_request(item.data, t)
        self._robot_events()
        if reply is None or not reply.data:
            self.stats["no reply"] += 1
            return None
        try:
            request = decode_request(item.data, settings)
        except FrameError:
            request = None
        return Outgoing(t + max(reply.delay_us, self.t3_5_us), reply.data, request)

    def sent(self, reply: Outgoing, t_us: int, peer: str = "") -> None:
        self.stats["replies out"] += 1
        where = f" [{peer}]" if peer else ""
        settings = self.robot.settings
        try:
            meaning = describe(decode_reply(reply.data, settings, reply.request), settings)
        except FrameError as err:
            meaning = f"invalid reply: {err}"
        self.line(t_us, "->", f"{hex_bytes(reply.data)}  {meaning}{where}")

    def not_sent(self, count: int) -> None:
        """``count`` replies were due to a peer that went away, or when the emulator stopped."""
        self.stats["not sent"] += count

    def tick(self) -> None:
        """Let robot time pass (tasks finish, timed faults fire) and log what happened."""
        self.robot.advance(max(self.now_us(), self.robot.now_us))
        self._robot_events()

    # ---- log -------------------------------------------------------------------------------

    def note(self, text: str) -> None:
        self.line(self.now_us(), "--", text)

    def line(self, t_us: int, mark: str, text: str) -> None:
        self._log(f"{t_us / 1e6:10.3f} s  {mark} {text}")

    def _robot_events(self) -> None:
        events = self.robot.events
        for event in events[self._events_seen:]:
            if event.kind == "fault":
                self.stats["faults"] += 1
            self.line(event.t_us, "**", f"{event.kind}: {event.message}")
        self._events_seen = len(events)

    def summary(self) -> str:
        """One line; frames in = replies out + unanswered + replies not sent (that part only
        when some were not: a client gone, or the stop, before they fell due)."""
        s = self.stats
        unsent = s["not sent"]
        not_sent = f", {counted(unsent, 'reply', 'replies')} not sent" if unsent else ""
        return (f"uitamr emulate: stopped after {self.now_us() / 1e6:.1f} s: "
                f"{counted(s['frames in'], 'frame', 'frames')} in, {counted(s['replies out'], 'reply', 'replies')} out, "
                f"{s['no reply']} unanswered{not_sent}, {counted(s['faults'], 'fault event', 'fault events')}, "
                f"{counted(s['dropped bytes'], 'flood byte', 'flood bytes')} dropped; robot {self.robot.mode}, "
                f"error {int(self.robot.error):02d}{self._garbled()}")

    def _garbled(self) -> str:
        """What the summary adds when every frame was garbled (`stream.garbled`: no good CRC, nor
        the protocol's shape): `stream.garbled_note`, in the words `uitamr monitor` uses; else
        "". A PLC that sends well-formed frames with a wrong CRC has its own log line (byte 6:
        bad CRC)."""
        frames = self.stats["frames in"]
        if not frames or self.stats["garbled"] < frames:
            return ""
        return f"; {garbled_note(frames, self.read_at)}"


def counted(n: int, one: str, many: str) -> str:
    """'1 frame', '2 frames', '0 frames': the counts of the emulator's log lines."""
    return f"{n} {one if n == 1 else many}"
