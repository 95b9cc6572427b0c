"""UITAMR-CRC and UITAMR-FORMAT: every frame the PLC sends, byte by byte."""
from __future__ import annotations

from bisect import bisect_right
from functools import lru_cache
from typing import Iterator

from verifier import protocol

from ..evidence import RunEvidence, Violation
from ..traffic import Traffic, frame_ref
from .judge import Judge


class Crc(Judge):
    def request(self, index: int) -> Iterator[Violation]:
        frame = self.traffic.tx[index]
        message = _crc_problem(bytes(frame.data))
        if message is not None:
            ref = frame_ref(frame, self.evidence.settings)
            yield Violation("UITAMR-CRC", frame.t_start_us, message, (ref,), frame.origin)


@lru_cache(maxsize=4096)
def _crc_problem(data: bytes) -> str | None:
    """What is wrong with the CRC of request `data`, or None (once per distinct frame: a
    long run repeats the same few requests thousands of times)."""
    if protocol.crc_ok(data):
        return None
    if len(data) < 3:
        return f"a {len(data)}-byte frame is too short to carry a CRC"
    expected = protocol.with_crc(data[:-2])[-2:]
    got = protocol.hex_bytes(data[-2:])
    message = (
        f"CRC bytes are {got}, expected {protocol.hex_bytes(expected)} "
        f"(CRC-16/MODBUS of the first {len(data) - 2} bytes, low byte first)"
    )
    if data[-2:] == expected[::-1]:
        message += " — the two CRC bytes are swapped: send the low byte first"
    return message


class Format(Judge):
    """Judge the layout of each request; a bad CRC is UITAMR-CRC's business, not this rule's."""

    def __init__(self, evidence: RunEvidence, traffic: Traffic):
        super().__init__(evidence, traffic)
        self.gaps: tuple[list[int], list] = ([], [])  # the "gap" events read so far, and their times
        self._read = 0  # events read (a run judged as it goes appends them as they happen)

    def request(self, index: int) -> Iterator[Violation]:
        events = self.evidence.events
        if len(events) > self._read:
            times, found = self.gaps
            for event in events[self._read:]:
                if getattr(event, "kind", "") == "gap":  # they come in time order
                    times.append(event.t_us)
                    found.append(event)
            self._read = len(events)
        frame = self.traffic.tx[index]
        problem = _layout_problem(bytes(frame.data), self.evidence.settings)
        gap = _gap_inside(frame, self.gaps)
        if gap is not None and problem is None:
            problem = (
                f"{gap.message}; a Modbus RTU frame must be sent as one continuous stream "
                f"(at most t1.5 = {protocol.T1_5_US / 1000:.2f} ms between bytes)"
            )
        if problem:
            yield Violation("UITAMR-FORMAT", frame.t_start_us, problem,
                            (frame_ref(frame, self.evidence.settings),), frame.origin)


@lru_cache(maxsize=4096)
def _layout_problem(data: bytes, settings: protocol.Settings) -> str | None:
    """What is wrong with the layout of request `data` (its CRC taken as right), or None;
    worked out once per distinct frame."""
    if len(data) >= 4 and not protocol.crc_ok(data):  # address, function code and the CRC at least
        data = protocol.with_crc(data[:-2])
    try:
        request = protocol.decode_request(data, settings)
    except protocol.FrameError as exc:
        return str(exc)
    if request.address != settings.address:
        return f"byte 0: addressed to slave {request.address}, the robot is slave {settings.address}"
    return None


def _gap_inside(frame, gaps: tuple[list[int], list]):
    """The line's "gap" event inside this PLC frame, if the PLC paused in mid-frame (the
    first one after the frame's start: a bisection, so a long run stays linear)."""
    times, found = gaps
    index = bisect_right(times, frame.t_start_us)
    if index < len(times) and times[index] < frame.t_end_us:
        return found[index]
    return None
