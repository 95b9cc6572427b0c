"""UITAMR-RESPONSE-HANDLING: a program must notice when the robot stops answering properly.

An *episode* is a run of consecutive failed exchanges (bad CRC, exception, wrong address,
garbled, late or no reply) ended by the next properly answered one. The program may
recover silently by retrying; but when an episode lasts longer than the scenario's bound,
the program's signal (e.g. `o_bErr`) must have become true within that bound, counted
from the moment the program could first know (the end of the bad reply, or the reply
time-out when nothing came).
"""
from __future__ import annotations

from bisect import bisect_right
from collections import Counter
from dataclasses import dataclass, field

from ..durations import format_seconds
from ..evidence import RunEvidence, Violation
from ..traffic import Exchange, ReplyStatus, Traffic


@dataclass
class Episode:
    exchanges: list[Exchange] = field(default_factory=list)
    end_us: int | None = None  # None: still failing when the run ended

    @property
    def noticeable_us(self) -> int:
        first = self.exchanges[0]
        status = first.reply_status[0]
        if status in (ReplyStatus.NONE, ReplyStatus.LATE):
            return first.deadline_us
        return first.reply.t_end_us

    def summary(self) -> str:
        counts = Counter(exchange.reply_status[0].value for exchange in self.exchanges)
        return ", ".join(f"{kind} ×{count}" for kind, count in counts.items())


def episodes(traffic: Traffic) -> list[Episode]:
    found: list[Episode] = []
    current: Episode | None = None
    for exchange in traffic.exchanges:
        if exchange.answered:
            if current is not None:
                current.end_us = exchange.reply.t_end_us
                current = None
            continue
        if current is None:
            current = Episode()
            found.append(current)
        current.exchanges.append(exchange)
    return found


def check_response_handling(evidence: RunEvidence, traffic: Traffic) -> list[Violation]:
    options = evidence.options
    within = options.response_within_us
    violations = []
    spans = []  # when the signal held: [(began, stopped)], computed once for every episode
    if options.response_signal is not None:
        spans = evidence.samples.intervals(options.response_signal, evidence.end_us)
    stops = [stopped for _, stopped in spans]
    for episode in episodes(traffic):
        start = episode.noticeable_us
        bound = start + within
        end = evidence.end_us if episode.end_us is None else episode.end_us
        if end <= bound or evidence.end_us < bound:
            continue  # recovered in time (or the run ended before the bound: nothing to judge)
        first = episode.exchanges[0]
        lasted = "until the end of the run" if episode.end_us is None else f"until {format_seconds(end)}"
        if not options.outputs_visible:
            message = (
                f"the robot's replies failed from {format_seconds(start)} {lasted} "
                f"({episode.summary()}); the PLC's outputs are not on the line: check that the "
                f"program showed it (e.g. its o_bErr) within {within / 1_000_000:g} s"
            )
        elif options.response_signal is None:
            message = (
                f"the robot's replies failed from {format_seconds(start)} {lasted} "
                f"({episode.summary()}), and the scenario names no output to show it: set "
                f"[response_handling] signal in the scenario or --response-signal (e.g. \"o_bErr\")"
            )
        else:
            index = bisect_right(stops, start)  # the first span still running after `start`
            if index < len(spans) and spans[index][0] <= bound:
                continue
            message = (
                f"the robot's replies failed from {format_seconds(start)} {lasted} "
                f"({episode.summary()}), but '{options.response_signal}' did not become true "
                f"within {within / 1_000_000:g} s"
            )
        violations.append(
            Violation(
                "UITAMR-RESPONSE-HANDLING",
                start,
                message,
                first.refs(),
                first.request.origin,
            )
        )
    return violations
