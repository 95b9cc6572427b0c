"""UITAMR-CRC and UITAMR-FORMAT: every frame the PLC sends, byte by byte."""
from __future__ import annotations

from bisect import bisect_right
from functools import lru_cache
from typing import Iterator

from verifier import protocol

from ..evidence import RunEvidence, Violation
from ..traffic import Traffic, frame_ref
from .judge import Judge


class _GapReader(Judge):
    """A judge that reads the line's "gap" events (a silence over t1.5 inside a PLC frame)
    as they come, to tell where a frame was paused in."""

    def __init__(self, evidence: RunEvidence, traffic: Traffic):
        super().__init__(evidence, traffic)
        self.gaps: tuple[list[int], list] = ([], [])  # the "gap" events read so far, and their times
        self._read = 0  # events read (a run judged as it goes appends them as they happen)

    def gap_inside(self, frame):
        events = self.evidence.events
        if len(events) > self._read:
            times, found = self.gaps
            for event in events[self._read:]:
                if getattr(event, "kind", "") == "gap":  # they come in time order
                    times.append(event.t_us)
                    found.append(event)
            self._read = len(events)
        return _gap_inside(frame, self.gaps)


def _run_together(frame, gap) -> tuple[int, int] | None:
    """(k, silence in µs) when `frame` is two requests sent with less than t3.5 between
    them, so that the line made one frame of them: its first k bytes, up to the pause, are a
    whole request with a good CRC, and more bytes follow. None otherwise."""
    if gap is None:
        return None
    data = bytes(frame.data)
    # from the frame's times, as every report keeps them (a run judged as a whole has the
    # events without the bytes before the pause): the silence is what the frame took beyond
    # its bytes, and the bytes before it are those sent before the pause began
    silence = frame.t_end_us - frame.t_start_us - protocol.frame_time_us(len(data))
    k = round((gap.t_us - frame.t_start_us - silence) / protocol.BYTE_TIME_EXACT_US)
    if not 4 <= k < len(data) or not protocol.crc_ok(data[:k]):
        return None
    return k, gap.t_us - (frame.t_start_us + protocol.frame_time_us(k))


def _together_text(data: bytes, k: int, silence_us: int) -> str:
    return (f"two requests ran together: {protocol.hex_bytes(data[k:])} followed {protocol.hex_bytes(data[:k])} "
            f"after a silence of {silence_us / 1000:.3f} ms, less than t3.5 = {protocol.T3_5_US / 1000:.2f} ms, so "
            "the robot takes them for one frame and discards it")


class Crc(_GapReader):
    def request(self, index: int) -> Iterator[Violation]:
        frame = self.traffic.tx[index]
        data = bytes(frame.data)
        message = _crc_problem(data)
        if message is not None:
            together = _run_together(frame, self.gap_inside(frame))
            if together is not None:
                # judge each request on its own: the CRC "of the first 14 bytes" is no one's
                k, silence = together
                second = _crc_problem(data[k:])
                if second is None:
                    return  # both CRCs are right: UITAMR-FORMAT reports the two run together
                message = f"the second of {_together_text(data, k, silence)}; its {second}"
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


class Format(_GapReader):
    """Judge the layout of each request; a bad CRC is UITAMR-CRC's business, not this rule's."""

    def request(self, index: int) -> Iterator[Violation]:
        frame = self.traffic.tx[index]
        problem = _layout_problem(bytes(frame.data), self.evidence.settings)
        gap = self.gap_inside(frame)
        together = _run_together(frame, gap) if problem is not None else None
        if together is not None:
            k, silence = together
            problem = (f"{_together_text(bytes(frame.data), k, silence)}: leave at least t3.5 of silence "
                       "between two requests (and wait for the reply, or its time-out, before the next)")
        elif gap is not None and problem is None:
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
