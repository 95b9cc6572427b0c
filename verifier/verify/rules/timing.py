"""UITAMR-PACING, UITAMR-HALF-DUPLEX and UITAMR-ONE-AT-A-TIME: when the PLC may transmit."""
from __future__ import annotations

from bisect import bisect_right

from verifier import protocol

from ..evidence import RunEvidence, Violation
from ..traffic import Traffic, frame_ref


def _ms(t_us: int) -> str:
    return f"{t_us / 1000:.1f} ms"


def check_pacing(evidence: RunEvidence, traffic: Traffic) -> list[Violation]:
    minimum = evidence.options.min_period_us
    tolerance = evidence.options.timing_tolerance_us
    violations = []
    for previous, frame in zip(traffic.tx, traffic.tx[1:]):
        gap = frame.t_start_us - previous.t_start_us
        if gap + tolerance <= minimum:
            violations.append(
                Violation(
                    "UITAMR-PACING",
                    frame.t_start_us,
                    f"request started {_ms(gap)} after the start of the previous request; "
                    f"the period must be more than {_ms(minimum)}",
                    (frame_ref(previous, evidence.settings), frame_ref(frame, evidence.settings)),
                    frame.origin,
                )
            )
    return violations


def check_half_duplex(evidence: RunEvidence, traffic: Traffic) -> list[Violation]:
    settings = evidence.settings
    violations = []
    rx_starts = [rx.t_start_us for rx in traffic.rx]
    tolerance = evidence.options.timing_tolerance_us
    for position, frame in enumerate(traffic.tx):
        start = frame.t_start_us
        judged = start + tolerance  # host timestamps (captures): blame only what is certain
        blamed = None
        if position > 0:
            previous = traffic.exchanges[position - 1]
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
            rx = _last_robot_frame_before(traffic.rx, rx_starts, start)
            if rx is not None and judged < rx.t_end_us:
                blamed = (rx, "while a frame from the robot was arriving")
            elif rx is not None and judged < rx.t_end_us + protocol.T3_5_US:
                blamed = (rx, f"only {_ms(start - rx.t_end_us)} after a frame from the robot "
                          f"ended; the line needs {_ms(protocol.T3_5_US)} of silence")
        if blamed:
            rx, why = blamed
            violations.append(
                Violation(
                    "UITAMR-HALF-DUPLEX",
                    start,
                    f"the PLC started transmitting {why}",
                    tuple(sorted((frame_ref(rx, settings, request=traffic.request_of(rx)),
                                  frame_ref(frame, settings)), key=lambda ref: ref.t_us)),
                    frame.origin,
                )
            )
    return violations


def _last_robot_frame_before(rx: list, starts: list[int], t_us: int):
    """The robot frame that started last at or before t_us (robot frames never overlap)."""
    index = bisect_right(starts, t_us) - 1
    return rx[index] if index >= 0 else None


def check_one_at_a_time(evidence: RunEvidence, traffic: Traffic) -> list[Violation]:
    settings = evidence.settings
    violations = []
    tolerance = evidence.options.timing_tolerance_us
    for previous, current in zip(traffic.exchanges, traffic.exchanges[1:]):
        start = current.request.t_start_us
        if start + tolerance >= previous.finished_us:
            continue
        reply = previous.reply
        if reply is not None and reply.t_start_us <= previous.deadline_us:
            why = "before the reply to the previous request had been received"
        else:
            waited = start - previous.request.t_end_us
            why = (
                f"{_ms(waited)} after the previous request with no reply yet; wait for the "
                f"reply time-out ({_ms(evidence.options.reply_timeout_us)} after the request "
                f"ended) before sending again"
            )
        violations.append(
            Violation(
                "UITAMR-ONE-AT-A-TIME",
                start,
                f"a new request started {why}",
                previous.refs() + (frame_ref(current.request, settings),),
                current.request.origin,
            )
        )
    return violations
