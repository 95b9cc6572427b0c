"""UITAMR-CRC and UITAMR-FORMAT: every frame the PLC sends, byte by byte."""
from __future__ import annotations

from bisect import bisect_left, bisect_right
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

    def gaps_inside(self, frame) -> list:
        events = self.evidence.events
        if len(events) > self._read:
            times, found = self.gaps
            for event in events[self._read:]:
                if getattr(event, "kind", "") == "gap":  # they come in time order
                    times.append(event.t_us)
                    found.append(event)
            self._read = len(events)
        return _gaps_inside(frame, self.gaps)


def _run_together(frame, gaps: list) -> tuple[tuple[int, int], ...] | None:
    """((k, silence in µs), ...) a pause, when `frame` is requests sent with less than t3.5
    between them, so that the line made one frame of them: up to each pause (its first k
    bytes), a whole request with a good CRC, and more bytes follow the last. None otherwise,
    and when the frame's times allow more than one such split."""
    if not gaps:
        return None
    data = bytes(frame.data)
    # from the frame's times, as every report keeps them (a run judged as a whole has the
    # events without the bytes before each pause): protocol.splits_at_pauses
    found = [way for way in protocol.splits_at_pauses(frame.t_start_us, frame.t_end_us, len(data),
                                                      [gap.t_us for gap in gaps])
             if all(_request_ends(data, way[i - 1][0] if i else 0, k) for i, (k, _) in enumerate(way))]
    return found[0] if len(found) == 1 else None


def _request_ends(data: bytes, start: int, end: int) -> bool:
    """Whether data[start:end] is a whole frame with a good CRC (an address, a function
    code and the CRC at least)."""
    return end - start >= 4 and protocol.crc_ok(data[start:end])


_COUNTS = ("two", "three", "four", "five", "six", "seven", "eight", "nine", "ten")
_ORDINALS = ("first", "second", "third", "fourth", "fifth", "sixth", "seventh", "eighth", "ninth", "tenth")


def _count(n: int, words: tuple[str, ...], first: int) -> str:
    return words[n - first] if n - first < len(words) else str(n)


def _parts(data: bytes, split: tuple[tuple[int, int], ...]) -> list[bytes]:
    bounds = [0] + [k for k, _ in split] + [len(data)]
    return [data[a:b] for a, b in zip(bounds, bounds[1:])]


def _together_text(data: bytes, split: tuple[tuple[int, int], ...]) -> str:
    parts = _parts(data, split)
    first_silence, later = split[0][1], split[1:]
    text = (f"{_count(len(parts), _COUNTS, 2)} requests ran together: {protocol.hex_bytes(parts[1])} followed "
            f"{protocol.hex_bytes(parts[0])} after a silence of {first_silence / 1000:.3f} ms")
    for part, (_, silence) in zip(parts[2:], later):
        text += f", {protocol.hex_bytes(part)} followed that after {silence / 1000:.3f} ms"
    each = "each " if later else ""
    return (f"{text}, {each}less than t3.5 = {protocol.T3_5_US / 1000:.2f} ms, so the robot takes them for one "
            "frame and discards it")


class Crc(_GapReader):
    def request(self, index: int) -> Iterator[Violation]:
        frame = self.traffic.tx[index]
        data = bytes(frame.data)
        message = _crc_problem(data)
        if message is not None:
            together = _run_together(frame, self.gaps_inside(frame))
            if together is not None:
                # judge each request on its own: the CRC "of the first 14 bytes" is no one's;
                # those before the last pause have good ones (else no split)
                last = _crc_problem(_parts(data, together)[-1])
                if last is None:
                    return  # every CRC is right: UITAMR-FORMAT reports the requests run together
                which = _count(len(together) + 1, _ORDINALS, 1)
                message = f"the {which} of {_together_text(data, together)}; its {last}"
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
        gaps = self.gaps_inside(frame)
        together = _run_together(frame, gaps) if problem is not None else None
        if together is not None:
            problem = (f"{_together_text(bytes(frame.data), together)}: leave at least t3.5 of silence "
                       "between two requests (and wait for the reply, or its time-out, before the next)")
        elif gaps and problem is None:
            problem = (
                f"{gaps[0].message}; a Modbus RTU frame must be sent as one continuous stream "
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
        sent, robot = request.address, settings.address
        return (f"byte 0: addressed to slave {sent}, the robot is slave {robot}: for a robot at {sent} set "
                f"address = {sent} under [protocol] in the scenario (--address {sent} for monitor and replay); "
                f"else make the program send to {robot} (the engine's i_wAddress)")
    return None


def _gaps_inside(frame, gaps: tuple[list[int], list]) -> list:
    """The line's "gap" events inside this PLC frame, one a pause the PLC made in mid-frame
    (found by bisection, so a long run stays linear)."""
    times, found = gaps
    first = bisect_right(times, frame.t_start_us)
    last = bisect_left(times, frame.t_end_us, lo=first)
    return found[first:last]
