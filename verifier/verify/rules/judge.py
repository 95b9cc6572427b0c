"""How a rule reads the traffic: in order, one request or exchange at a time.

A rule is a `Judge` that keeps what it needs of the past (the previous request, the last
control command, the episode of failed replies it is in) and says, for each request or
exchange in turn, what that one breaks. `uitamr verify` hands it the whole run at once;
`uitamr monitor` hands it the line as it settles (`Pairing.settled`), so a long session
judges each frame once instead of the whole capture again and again - with the same
findings, in the same order.
"""
from __future__ import annotations

from typing import Iterable

from ..evidence import RunEvidence, Violation
from ..traffic import Exchange, Traffic


class Judge:
    def __init__(self, evidence: RunEvidence, traffic: Traffic):
        self.evidence = evidence
        self.traffic = traffic

    def request(self, index: int) -> Iterable[Violation]:
        """Request `index` (traffic.tx) is known; the requests before it have been judged."""
        return ()

    def exchange(self, index: int) -> Iterable[Violation]:
        """Exchange `index` is settled (its reply, or its time-out, is known, and so is every
        robot frame that started before its request did); the exchanges before it have been
        judged."""
        return ()

    def forget(self, requests: int, robot_frames: int) -> None:
        """The traffic let go of its first `requests` requests (and exchanges) and
        `robot_frames` robot frames: indexes from now on count from what is left. Only a
        judge that keeps positions in the traffic's lists has anything to do."""

    def finish(self) -> Iterable[Violation]:
        """The run ended at evidence.end_us, every exchange judged."""
        return ()

    def provisional(self, end_us: int, overdue: Exchange | None = None) -> Iterable[Violation]:
        """Early word, for a live view, of a violation still going on that `finish` would
        report if the run ended at `end_us` (replies failing for too long); said once.
        `overdue`: the first exchange not settled, when its reply can no longer come in
        time (its pairing is not final, but it failed: late or not at all)."""
        return ()
