"""UITAMR-PACING, UITAMR-HALF-DUPLEX and UITAMR-ONE-AT-A-TIME: when the PLC may transmit."""
from __future__ import annotations

from bisect import bisect_right
from typing import Iterator

from verifier import protocol

from ..evidence import RunEvidence, Violation
from ..traffic import Traffic, frame_ref
from .judge import Judge


def _ms(t_us: int) -> str:
    return f"{t_us / 1000:.1f} ms"


def _maybe_noise(evidence: RunEvidence, previous) -> str:
    """On a captured line (the monitor cannot tell who put a frame there) a previous
    "request" with a bad CRC may be noise or bytes at a wrong baud rate rather than the
    PLC's: the timing finding against it says so, and points at its CRC finding."""
    if evidence.options.outputs_visible or protocol.crc_ok(previous.data):
        return ""
    return (f" (the previous frame, {protocol.hex_bytes(previous.data)}, has a bad CRC: if the PLC did not "
            f"send it, it is noise on the line or a wrong baud rate - see its UITAMR-CRC finding)")


class Pacing(Judge):
    def request(self, index: int) -> Iterator[Violation]:
        if index == 0:
            return
        options, tx = self.evidence.options, self.traffic.tx
        previous, frame = tx[index - 1], tx[index]
        gap = frame.t_start_us - previous.t_start_us
        if gap + options.timing_tolerance_us <= options.min_period_us:
            yield Violation(
                "UITAMR-PACING",
                frame.t_start_us,
                f"request started {_ms(gap)} after the start of the previous request; "
                f"the period must be more than {_ms(options.min_period_us)}"
                f"{_maybe_noise(self.evidence, previous)}",
                (frame_ref(previous, self.evidence.settings), frame_ref(frame, self.evidence.settings)),
                frame.origin,
            )


class HalfDuplex(Judge):
    def __init__(self, evidence: RunEvidence, traffic: Traffic):
        super().__init__(evidence, traffic)
        self.rx_starts: list[int] = []  # of traffic.rx, as far as it has been read

    def forget(self, requests: int, robot_frames: int) -> None:
        del self.rx_starts[:robot_frames]

    def exchange(self, index: int) -> Iterator[Violation]:
        settings, traffic = self.evidence.settings, self.traffic
        self.rx_starts += [rx.t_start_us for rx in traffic.rx[len(self.rx_starts):]]
        frame = traffic.tx[index]
        start = frame.t_start_us
        judged = start + self.evidence.options.timing_tolerance_us  # host timestamps (captures): blame only what is certain
        blamed = None
        if index > 0:
            previous = traffic.exchanges[index - 1]
            reply = previous.reply
            if reply is not None and reply.t_start_us <= previous.deadline_us:
                if judged < reply.t_start_us:
                    blamed = (reply, "while the reply to the previous request was due "
                              f"(it began {_ms(reply.t_start_us - start)} later)")
                elif judged < reply.t_end_us:
                    blamed = (reply, "while the reply to the previous request was arriving")
                elif judged < reply.t_end_us + protocol.T3_5_US:
                    blamed = (reply, f"only {_ms(start - reply.t_end_us)} after the reply ended; the "
                              f"line needs {_ms(protocol.T3_5_US)} (3.5 characters) of silence")
        if blamed is None:
            rx = _last_robot_frame_before(traffic.rx, self.rx_starts, start)
            if rx is not None and judged < rx.t_end_us:
                blamed = (rx, "while a frame from the robot was arriving")
            elif rx is not None and judged < rx.t_end_us + protocol.T3_5_US:
                blamed = (rx, f"only {_ms(start - rx.t_end_us)} after a frame from the robot "
                          f"ended; the line needs {_ms(protocol.T3_5_US)} of silence")
        if blamed:
            rx, why = blamed
            yield Violation(
                "UITAMR-HALF-DUPLEX",
                start,
                f"the PLC started transmitting {why}",
                tuple(sorted((frame_ref(rx, settings, request=traffic.request_of(rx)),
                              frame_ref(frame, settings)), key=lambda ref: ref.t_us)),
                frame.origin,
            )


def _last_robot_frame_before(rx: list, starts: list[int], t_us: int):
    """The robot frame that started last at or before t_us (robot frames never overlap)."""
    index = bisect_right(starts, t_us) - 1
    return rx[index] if index >= 0 else None


class OneAtATime(Judge):
    def exchange(self, index: int) -> Iterator[Violation]:
        if index == 0:
            return
        options = self.evidence.options
        previous, current = self.traffic.exchanges[index - 1], self.traffic.exchanges[index]
        start = current.request.t_start_us
        if start + options.timing_tolerance_us >= previous.finished_us:
            return
        reply = previous.reply
        if reply is not None and reply.t_start_us <= previous.deadline_us:
            why = "before the reply to the previous request had been received"
        else:
            waited = start - previous.request.t_end_us
            why = (
                f"{_ms(waited)} after the previous request with no reply yet; wait for the "
                f"reply time-out ({_ms(options.reply_timeout_us)} after the request "
                f"ended) before sending again"
            )
        yield Violation(
            "UITAMR-ONE-AT-A-TIME",
            start,
            f"a new request started {why}{_maybe_noise(self.evidence, previous.request)}",
            previous.refs() + (frame_ref(current.request, self.evidence.settings),),
            current.request.origin,
        )
