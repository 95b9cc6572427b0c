"""The trace read as exchanges: each request the PLC sent, and what came back.

A request's reply is the first robot frame that starts after the request ended and before
the PLC's next transmission. The reply is *in time* when it starts no later than
`reply_timeout_us` after the request ended; after that the master is entitled to have
given up (Modbus over Serial Line V1.02 §2.4.1, "response time-out").
"""
from __future__ import annotations

import enum
from bisect import bisect_left, bisect_right
from dataclasses import dataclass, field
from functools import lru_cache
from typing import Sequence

from verifier import protocol

from .evidence import FrameRef, RuleOptions, TraceFrameLike


class ReplyStatus(enum.Enum):
    OK = "ok"
    EXCEPTION = "exception"
    BAD_CRC = "bad CRC"
    WRONG_ADDRESS = "wrong address"
    GARBLED = "garbled"
    LATE = "late"
    NONE = "no reply"
    LOST = "lost at the converter"  # TCP route: the robot answered, the PLC never got it

    @property
    def failed(self) -> bool:
        return self is not ReplyStatus.OK


def describe_bytes(data: bytes, settings: protocol.Settings, direction: str, *, request=None) -> str:
    """Human meaning of a frame sent in `direction` ("tx" PLC→robot, "rx" robot→PLC).

    Replies are read against their request when it is known (so a status value is named).
    """
    if direction == "rx" and request is not None:
        try:
            return protocol.describe(protocol.decode_reply(data, settings, request), settings)
        except protocol.FrameError:
            pass
    return protocol.describe(data, settings, "request" if direction == "tx" else "reply")


def frame_ref(frame: TraceFrameLike, settings: protocol.Settings, *, request=None) -> FrameRef:
    hex_text, meaning = _shown(bytes(frame.data), settings, frame.direction, request)
    return FrameRef(
        t_us=frame.t_start_us,
        t_end_us=frame.t_end_us,
        direction=frame.direction,
        hex=hex_text,
        meaning=meaning,
        origin=frame.origin,
    )


@lru_cache(maxsize=4096)
def _shown(data: bytes, settings: protocol.Settings, direction: str, request) -> tuple[str, str]:
    """A frame's bytes in hex and its meaning, worked out once per distinct frame and
    shared by every violation that shows it (a burst's thousands of findings, too)."""
    return protocol.hex_bytes(data), describe_bytes(data, settings, direction, request=request)


# A long run repeats the same few frames thousands of times (a status poll and its
# answer): each distinct frame is decoded and judged once, and the exchanges share the
# results (frozen values) instead of holding a copy each.
@lru_cache(maxsize=4096)
def _decoded_request(data: bytes, settings: protocol.Settings):
    try:
        return protocol.decode_request(data, settings)
    except protocol.FrameError:
        return None


@lru_cache(maxsize=4096)
def _decoded_reply(data: bytes, settings: protocol.Settings, request):
    """`data` decoded as a reply to `request`, or the FrameError saying why it is not one."""
    try:
        return protocol.decode_reply(data, settings, request)
    except protocol.FrameError as exc:
        return exc


@lru_cache(maxsize=4096)
def _reply_verdict(data: bytes, settings: protocol.Settings, request) -> tuple[ReplyStatus, str]:
    """The status of an in-time reply `data` to `request` (the decoded request or None)."""
    if data and data[0] != settings.address:
        return ReplyStatus.WRONG_ADDRESS, f"reply from address {data[0]}, not {settings.address}"
    if not protocol.crc_ok(data):
        return ReplyStatus.BAD_CRC, "reply CRC does not match"
    decoded = _decoded_reply(data, settings, request)
    if isinstance(decoded, protocol.FrameError):
        return ReplyStatus.GARBLED, str(decoded)
    if isinstance(decoded, protocol.ExceptionReply):
        return ReplyStatus.EXCEPTION, protocol.describe(decoded, settings)
    return ReplyStatus.OK, "ok"


_NOT_YET = object()


@dataclass(slots=True)
class Exchange:
    """One request and the robot frames that followed it. Slotted, with its two worked-out
    values in slots of their own: a 10 h run has 100,000 of these."""

    index: int
    request: TraceFrameLike
    rx: list[TraceFrameLike]  # every robot frame until the next request
    settings: protocol.Settings
    reply_timeout_us: int
    lost_at_converter: bool = False  # the converter dropped the connection after forwarding it
    # a robot frame overlapped the request on the half-duplex line: the robot cannot have
    # read it, so no later frame is its reply (`Pairing`)
    talked_over: bool = False
    _decoded: object = field(default=_NOT_YET, init=False, repr=False, compare=False)
    _status: object = field(default=_NOT_YET, init=False, repr=False, compare=False)

    @property
    def decoded_request(self):
        """The request as the robot would read it, or None when it is not a valid request."""
        if self._decoded is _NOT_YET:
            self._decoded = _decoded_request(bytes(self.request.data), self.settings)
        return self._decoded

    @property
    def is_control(self) -> bool:
        return isinstance(self.decoded_request, protocol.ControlRequest)

    @property
    def is_status(self) -> bool:
        return isinstance(self.decoded_request, protocol.StatusRequest)

    @property
    def deadline_us(self) -> int:
        """The latest start of an in-time reply."""
        return self.request.t_end_us + self.reply_timeout_us

    @property
    def reply(self) -> TraceFrameLike | None:
        return self.rx[0] if self.rx else None

    @property
    def reply_status(self) -> tuple[ReplyStatus, str]:
        if self._status is _NOT_YET:
            self._status = self._work_out_status()
        return self._status

    def _work_out_status(self) -> tuple[ReplyStatus, str]:
        reply = self.reply
        if reply is None:
            return ReplyStatus.NONE, "no reply"
        if self.lost_at_converter:
            return ReplyStatus.LOST, ("the robot answered, but the converter had dropped the connection: "
                                      "the reply never reached the PLC")
        if reply.t_start_us > self.deadline_us:
            late_ms = (reply.t_start_us - self.request.t_end_us) / 1000
            return ReplyStatus.LATE, f"reply started {late_ms:.1f} ms after the request ended"
        return _reply_verdict(bytes(reply.data), self.settings, self.decoded_request)

    @property
    def answered(self) -> bool:
        return self.reply_status[0] is ReplyStatus.OK

    @property
    def finished_us(self) -> int:
        """When the master may start its next request: reply received, or time-out over."""
        reply = self.reply
        if reply is not None and reply.t_start_us <= self.deadline_us:
            return reply.t_end_us
        return self.deadline_us

    def refs(self) -> tuple[FrameRef, ...]:
        request = frame_ref(self.request, self.settings)
        if self.reply is None:
            return (request,)
        return (request, frame_ref(self.reply, self.settings, request=self.decoded_request))


@dataclass
class Traffic:
    exchanges: list[Exchange]
    rx_before_first_request: list[TraceFrameLike]
    rx: list[TraceFrameLike]
    tx: list[TraceFrameLike]
    # robot frames by start time -> the exchanges they joined (Pairing keeps it up to date)
    owners: dict[int, list[Exchange]] = field(default_factory=dict, repr=False)

    def request_of(self, frame: TraceFrameLike):
        """The decoded request a robot frame was paired with (None before the first request,
        or when that request is not valid), so every report describes a reply the same way."""
        for exchange in sorted(self.owners.get(frame.t_start_us, ()), key=lambda e: e.index):
            if any(f is frame for f in exchange.rx):
                return exchange.decoded_request
        return None


def _is_reply_to(frame: TraceFrameLike, exchange: Exchange) -> bool:
    request = exchange.decoded_request
    if request is None:
        return False
    return not isinstance(_decoded_reply(bytes(frame.data), exchange.settings, request), protocol.FrameError)


def converter_drops(events) -> list[int]:
    """When a converter dropped the PLC's connection after forwarding a request (TCP route
    events `converter.dropped`): the time of each."""
    return [e.t_us for e in events if e.kind == "converter.dropped"]


class Pairing:
    """Requests and robot frames paired as they come, the way a slave answers: once per
    request, in order.

    A robot frame goes to the oldest request that has ended, has no reply yet and whose
    time-out has not run out — preferring one it is a valid reply to, then one with a good
    CRC (a slave never answers a request with a bad one). A request a robot frame
    overlapped on the line (the robot was talking while it went out: `talked_over`) waits
    for nothing: the robot cannot have read it, so the robot's next frame answers a later
    request rather than making every pairing after it one off. When no request is
    waiting, it joins the latest request that ended before it (a late reply, garbage).

    Frames are given in `analyse`'s order (by start; a request before a robot frame that
    starts at the same time). A live monitor gives them as the line settles them: when
    requests never overlap (every frame starts after the one before it ended, as on a
    half-duplex line) each frame's pairing is then final as soon as it is given, and
    `settled` says how many exchanges no later frame can change.
    """

    def __init__(self, settings: protocol.Settings, options: RuleOptions):
        self.settings = settings
        self.reply_timeout_us = options.reply_timeout_us
        # host timestamps (captures): an overlap within the tolerance may be the timing's
        self._tolerance_us = options.timing_tolerance_us
        self.traffic = Traffic([], [], [], [])
        self._ends: list[int] = []  # when each request ended
        self._oldest = 0  # exchanges before this one are answered or timed out for good
        self._settled = 0
        self._given = 0  # requests given, those let go of (`forget`) included
        self._robot_frame: tuple[int, int] | None = None  # (start, end) of the latest robot frame given

    def request(self, frame: TraceFrameLike) -> None:
        traffic = self.traffic
        robot = self._robot_frame
        traffic.exchanges.append(Exchange(self._given, frame, [], self.settings, self.reply_timeout_us,
                                          talked_over=robot is not None and self._talked_over(frame, *robot)))
        self._given += 1
        traffic.tx.append(frame)
        self._ends.append(frame.t_end_us)

    def reply(self, frame: TraceFrameLike) -> None:
        """A robot frame (every request that starts before it must have been given)."""
        traffic, exchanges = self.traffic, self.traffic.exchanges
        traffic.rx.append(frame)
        t = frame.t_start_us
        if self._robot_frame is None or frame.t_end_us >= self._robot_frame[1]:
            self._robot_frame = (t, frame.t_end_us)
        count = bisect_right(self._ends, t)  # requests that ended before this frame began
        # requests given so far that overlap this frame (a live line gives the one still going
        # out when the robot began; `analyse`, which gives every request first, also those
        # that began while it was talking: `request` marks those on a live line)
        k = count
        while k < len(exchanges) and exchanges[k].request.t_start_us < frame.t_end_us:
            if self._talked_over(exchanges[k].request, t, frame.t_end_us):
                exchanges[k].talked_over = True
            k += 1
        if count == 0:
            traffic.rx_before_first_request.append(frame)
            return
        while self._oldest < count and (exchanges[self._oldest].rx or exchanges[self._oldest].deadline_us < t):
            self._oldest += 1
        waiting = [e for e in exchanges[self._oldest:count] if not e.rx and not e.talked_over and t <= e.deadline_us]
        if waiting:
            # a slave never answers a request whose CRC is wrong (MODBUS over Serial Line
            # V1.02 §2.4.1): a frame that is no valid reply to any waiting request goes to
            # the oldest one with a good CRC
            owner = next((e for e in waiting if _is_reply_to(frame, e)), None) \
                or next((e for e in waiting if protocol.crc_ok(bytes(e.request.data))), waiting[0])
        else:
            owner = exchanges[count - 1]
        owner.rx.append(frame)
        traffic.owners.setdefault(t, []).append(owner)

    def _talked_over(self, request: TraceFrameLike, robot_start_us: int, robot_end_us: int) -> bool:
        """The request and a robot frame overlapped on the line by more than the timing
        tolerance (host timestamps: less may be the timing's, as UITAMR-HALF-DUPLEX judges)."""
        overlap = min(request.t_end_us, robot_end_us) - max(request.t_start_us, robot_start_us)
        return overlap > self._tolerance_us

    def give(self, frame: TraceFrameLike) -> None:
        """The next frame in `analyse`'s order: a request ("tx") or a robot frame ("rx");
        a frame whose direction is not known is not paired."""
        if frame.direction == "tx":
            self.request(frame)
        elif frame.direction == "rx":
            self.reply(frame)

    def forget(self, count: int) -> int:
        """Let go of the first `count` exchanges and of the robot frames that started before
        the last one that began at or before the first request kept (a rule judging that
        request still looks back to it); returns how many robot frames went. Only for
        exchanges that are settled, judged and not the latest to have ended before any frame
        still to come (the one a late robot frame would join): `Stream` says which."""
        if count <= 0:
            return 0
        traffic = self.traffic
        first_kept = traffic.exchanges[count].request.t_start_us
        starts = [frame.t_start_us for frame in traffic.rx]
        gone = max(0, bisect_right(starts, first_kept) - 1)
        for frame in traffic.rx[:gone]:
            traffic.owners.pop(frame.t_start_us, None)
        del traffic.rx[:gone]
        del traffic.exchanges[:count], traffic.tx[:count], self._ends[:count]
        self._oldest = max(0, self._oldest - count)
        self._settled = max(0, self._settled - count)
        return gone

    def ended_before(self, t_us: int) -> int:
        """How many requests ended at or before `t_us` (requests never overlap each other)."""
        return bisect_right(self._ends, t_us)

    def settled(self, frontier_us: int) -> int:
        """How many exchanges, from the first, are final when no frame still to come starts
        before `frontier_us`: each has its reply, or its time-out ran out before the frontier
        and the next request ended (so no late reply can become its first robot frame)."""
        exchanges, ends = self.traffic.exchanges, self._ends
        k = self._settled
        while k < len(exchanges):
            if not exchanges[k].rx and (frontier_us <= exchanges[k].deadline_us or k + 1 == len(exchanges)
                                        or ends[k + 1] > frontier_us):
                break
            k += 1
        self._settled = k
        return k


def analyse(trace: Sequence[TraceFrameLike], settings: protocol.Settings, options: RuleOptions,
            dropped_at: Sequence[int] = ()) -> Traffic:
    """The whole trace paired (`Pairing`), every request known before the first reply.

    `dropped_at`: times a converter dropped the connection (`converter_drops`); the first
    request at or after each is one whose reply the PLC never got (ReplyStatus.LOST).
    """
    frames = sorted(trace, key=lambda f: (f.t_start_us, f.direction != "tx"))
    pairing = Pairing(settings, options)
    for frame in frames:
        if frame.direction == "tx":
            pairing.request(frame)
    for frame in frames:
        if frame.direction == "rx":
            pairing.reply(frame)
    exchanges = pairing.traffic.exchanges
    starts = [e.request.t_start_us for e in exchanges]
    for t in dropped_at:
        k = bisect_left(starts, t)
        if k < len(exchanges):
            exchanges[k].lost_at_converter = True
    return pairing.traffic
