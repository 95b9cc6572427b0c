"""UITAMR-RESPONSE-HANDLING: a program must notice when the robot stops answering properly.

An *episode* is a run of consecutive failed exchanges (bad CRC, exception, wrong address,
garbled, late or no reply) ended by the next properly answered one. The program may
recover silently by retrying; but when an episode lasts longer than the scenario's bound,
the program's signal (e.g. `o_bErr`) must have become true within that bound, counted
from the moment the program could first know (the end of the bad reply, or the reply
time-out when nothing came).
"""
from __future__ import annotations

from collections import Counter
from dataclasses import dataclass, field
from typing import Iterator

from ..durations import format_seconds
from ..evidence import RunEvidence, Violation
from ..traffic import Exchange, ReplyStatus, Traffic
from .judge import Judge

#: an overdue exchange's kind while a late reply may still come (Episode.counts)
NO_REPLY_SO_FAR = "no reply so far"
#: what to look at on site for each kind of failure (docs/commissioning.md §5); no reply: _on_site
_ON_SITE = {
    ReplyStatus.BAD_CRC.value: "the line for noise: the shield, a termination at both ends, GND joined",
    ReplyStatus.GARBLED.value: "the line for noise: the shield, a termination at both ends, GND joined",
    ReplyStatus.LATE.value: "the robot's or a converter's delay against the PLC's reply time-out",
    ReplyStatus.WRONG_ADDRESS.value: "the robot's address setting against the PLC's requests",
    ReplyStatus.EXCEPTION.value: "why the robot refused the requests: the exception code in the replies",
}


@dataclass
class Episode:
    """Failed exchanges in a row: the first, and how many of each kind of failure (a robot
    that stops answering for hours makes one episode of thousands of exchanges)."""

    first: Exchange
    counts: Counter = field(default_factory=Counter)
    end_us: int | None = None  # None: still failing when the run ended

    def add(self, exchange: Exchange) -> None:
        self.counts[exchange.reply_status[0].value] += 1

    @property
    def noticeable_us(self) -> int:
        first = self.first
        if first.reply is None:
            return first.deadline_us  # no reply (yet): the time-out is when it shows
        status = first.reply_status[0]
        if status in (ReplyStatus.NONE, ReplyStatus.LATE):
            return first.deadline_us
        return first.reply.t_end_us

    def summary(self) -> str:
        return ", ".join(f"{kind} ×{count}" for kind, count in self.counts.items())


class ResponseHandling(Judge):
    def __init__(self, evidence: RunEvidence, traffic: Traffic):
        super().__init__(evidence, traffic)
        options = evidence.options
        # when the signal held (kept up to date while a run is judged as it goes)
        self.signal = None if options.response_signal is None else evidence.samples.spans(options.response_signal)
        self.current: Episode | None = None  # the episode the latest exchange is in
        self._told: int | None = None  # the first exchange of the episode `provisional` spoke of

    def exchange(self, index: int) -> Iterator[Violation]:
        exchange = self.traffic.exchanges[index]
        if exchange.answered:
            if self.current is not None:
                episode, self.current = self.current, None
                episode.end_us = exchange.reply.t_end_us
                yield from self._judge(episode, self.evidence.end_us)
            return
        if self.current is None:
            self.current = Episode(exchange)
        self.current.add(exchange)

    def finish(self) -> Iterator[Violation]:
        if self.current is not None:
            yield from self._judge(self.current, self.evidence.end_us)

    def provisional(self, end_us: int, overdue: Exchange | None = None) -> Iterator[Violation]:
        """Replies failing for longer than the bound, still going on: said once per episode.
        An overdue exchange (Judge.provisional) begins an episode when none is under way,
        counted as "no reply so far": a late reply may still join it (the final words then
        say "late")."""
        episode = self.current
        if episode is None and overdue is not None:
            episode = Episode(overdue)
            episode.counts[NO_REPLY_SO_FAR] += 1
        if episode is not None and episode.first.index != self._told:
            for violation in self._judge(episode, end_us):
                self._told = episode.first.index
                yield violation

    def _on_site(self, episode: Episode) -> str:
        """What to look at on site for the failures a line shows (docs/commissioning.md §5)."""
        hints = []
        for kind in episode.counts:
            if kind in (ReplyStatus.NONE.value, NO_REPLY_SO_FAR):
                hint = (f"why the robot does not answer: its power, its address (the requests go to "
                        f"slave {self.evidence.settings.address}), the pair's wiring and polarity (A, B, GND) "
                        f"and its line settings")
            else:
                hint = _ON_SITE.get(kind, "the route between the PLC and the robot")
            if hint not in hints:
                hints.append(hint)
        return "; ".join(hints)

    def _judge(self, episode: Episode, run_end_us: int) -> Iterator[Violation]:
        """The episode's violation, if the run ended at `run_end_us` (at or after the end of a
        closed episode: an episode is judged when it closes or when the run ends)."""
        options = self.evidence.options
        within = options.response_within_us
        start = episode.noticeable_us
        bound = start + within
        end = run_end_us if episode.end_us is None else episode.end_us
        if end <= bound or run_end_us < bound:
            return  # recovered in time (or the run ended before the bound: nothing to judge)
        first = episode.first
        lasted = "until the end of the run" if episode.end_us is None else f"until {format_seconds(end)}"
        if not options.outputs_visible:
            message = (
                f"the robot's replies failed from {format_seconds(start)} {lasted} "
                f"({episode.summary()}); the PLC's outputs are not on the line: check that the "
                f"program showed it (e.g. its o_bErr) within {within / 1_000_000:g} s; on site, "
                f"check {self._on_site(episode)}"
            )
        elif options.response_signal is None:
            message = (
                f"the robot's replies failed from {format_seconds(start)} {lasted} "
                f"({episode.summary()}), and the scenario names no output to show it: set "
                f"[response_handling] signal in the scenario or --response-signal "
                + (f"(the program has no o_bErr; its FB instances have {options.response_signal_hint})"
                   if options.response_signal_hint else "(e.g. \"o_bErr\")")
            )
        else:
            began = self.signal.first_running_after(start)
            if began is not None and began <= bound:
                return
            message = (
                f"the robot's replies failed from {format_seconds(start)} {lasted} "
                f"({episode.summary()}), but '{options.response_signal}' did not become true "
                f"within {within / 1_000_000:g} s"
            )
        yield Violation(
            "UITAMR-RESPONSE-HANDLING",
            start,
            message,
            first.refs(),
            first.request.origin,
        )
