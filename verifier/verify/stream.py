"""Judging a run as it goes, for a run that keeps no frames (`Keep(frames=False)`).

Every ten virtual seconds the runner hands over the frames the line has settled
(`Line.take_settled`): they are paired (`Pairing`), the rules judge each request and each
settled exchange once (`Judgement`), the expectations about exchanges take them in order
(`watch_exchanges`), and the exchanges and robot frames that nothing reads again are let
go of. What stays is bounded: the last few exchanges, the findings, the frame counts, and
the samples of the labels the expectations and the response signal read. At the end
`finish` judges the rest exactly as a whole run is judged (tests/test_verify_stream.py:
the same findings and verdicts on every bundled scenario and on random ones).
A run whose frames `--trace` or `--html` lists writes them as trace lines to a file while it
goes (`spool_folder`; report_trace completes the lines once the run is judged, and the page
reads the frames it draws from them).
"""
from __future__ import annotations

import os
import tempfile
from contextlib import contextmanager
from typing import Any, Sequence, TextIO

from verifier import protocol
from verifier.textfile import UNENCODABLE

from . import spool
from .evidence import RuleOptions, RunEvidence, Samples, Violation
from .expectations import Expectation, ExpectationResult, verdict, watch_exchanges
from .report_trace import spool_lines
from .result import TraceRecord, UnusableInput
from .rules import Judgement
from .traffic import Pairing

# the run's end is not known while it goes; any time after every frame serves until then
# (an episode of failed replies is judged when it closes, before the end)
_OPEN_END_US = 2**62
COMPACT_AT = 1024  # exchanges judged and let go of in one step (slicing lists costs their length)
SHARED_FRAMES = 4096  # distinct frames whose bytes equal frames share (garbage makes many)


class Stream:
    def __init__(self, settings: protocol.Settings, options: RuleOptions, samples: Samples,
                 expectations: Sequence[Expectation], relative_origin, spool_folder: str | None = None,
                 name: str = "", duration_from_option: bool = False):
        """`spool_folder` (Keep.frames_to_file): the frames' trace lines go to a file there
        as they are given (`trace_file`, complete after `finish`); the folder's owner
        removes it. `name`: the scenario's, for the trace lines. `duration_from_option`:
        --duration set the run's end (RunEvidence's, for the expectations' messages)."""
        self.settings = settings
        self.name = name
        self._spool_folder = spool_folder
        self.spool: TextIO | None = None
        self.trace_file: str | None = None
        if spool_folder is not None:
            with self._writing():
                handle, self.trace_file = tempfile.mkstemp(prefix=spool.PREFIX, suffix=".part", dir=spool_folder)
                self.spool = os.fdopen(handle, "w", encoding="utf-8", errors=UNENCODABLE)
        self.pairing = Pairing(settings, options)
        self.evidence = RunEvidence(settings, (), _OPEN_END_US, [], samples, options,
                                    duration_from_option=duration_from_option)
        self.judgement = Judgement(self.evidence, self.pairing.traffic)
        self.expectations = list(expectations)
        self.watches = [watch_exchanges(expectation, settings) for expectation in self.expectations]
        self._watching = [watch for watch in self.watches if watch is not None]
        self._given = 0  # exchanges (of those kept) given to the watches
        self._drops: list[int] = []  # when a converter dropped the PLC's connection
        self._drops_applied = 0
        self._origin = relative_origin
        self._cwd = os.getcwd()
        self._shared: dict[bytes, bytes] = {}
        self.tx_count = 0
        self.rx_count = 0

    def take(self, frames: list, frontier_us: int, events: Sequence[Any]) -> None:
        """The line's settled frames (in trace order) and the events the rules read that
        happened since the last call (the line's "gap" events and the converter's drops,
        each kind in time order); no frame still to come starts before `frontier_us`."""
        self._events(events)
        with self._writing():
            self._give(frames)
        pairing, judgement = self.pairing, self.judgement
        settled = pairing.settled(frontier_us)
        judgement.advance(settled)
        self._watch(settled)
        # each rule looks back one request or exchange; a late robot frame joins the latest
        # request that ended before it
        done = min(settled, judgement.exchanges, judgement.requests, pairing.ended_before(frontier_us)) - 1
        if done >= COMPACT_AT:
            robot_frames = pairing.forget(done)
            judgement.forget(done, robot_frames)
            self._given -= done

    def finish(self, frames: list, end_us: int, stopped_early: bool,
               events: Sequence[Any]) -> tuple[dict[str, list[Violation]], list[ExpectationResult]]:
        """The rest of the run's frames (each starting before `end_us`) and events (as
        `take`); every rule's violations and every expectation's result, as `check_all`
        and `judge` give them."""
        self._events(events)
        with self._writing():
            self._give(frames)
            if self.spool is not None:
                self.spool.close()  # a full disk shows when the last lines are flushed
        self.evidence.end_us = end_us
        self.evidence.stopped_early = stopped_early
        self.judgement.finish()
        self._watch(len(self.pairing.traffic.exchanges))
        outcomes = [verdict(expectation, self.evidence, watch)
                    for expectation, watch in zip(self.expectations, self.watches)]
        return self.judgement.violations(), outcomes

    @contextmanager
    def _writing(self):
        """The spool is the one file a stream writes: what the disk refuses is unusable input
        (exit 2) that names the folder, not a traceback."""
        try:
            yield
        except OSError as exc:
            raise UnusableInput(f"cannot write the run's frames in {self._spool_folder}: {exc.strerror or exc}") from None

    def _events(self, events: Sequence[Any]) -> None:
        self.evidence.events.extend(events)  # the format rule reads the gaps as they are added
        self._drops += [e.t_us for e in events if e.kind == "converter.dropped"]

    def _give(self, frames: list) -> None:
        if len(self._shared) > SHARED_FRAMES:
            self._shared.clear()
        pairing, shared, cwd, origin = self.pairing, self._shared, self._cwd, self._origin
        records = []
        for frame in frames:
            data = bytes(frame.data)
            record = TraceRecord(frame.t_start_us, frame.t_end_us, frame.direction, shared.setdefault(data, data),
                                 frame.origin and origin(frame.origin, cwd))
            records.append(record)
            pairing.give(record)
            if record.direction == "tx":
                self.tx_count += 1
                self._mark_lost(record.t_start_us)
            else:
                self.rx_count += 1
        if self.spool is not None and records:
            # a robot frame's pairing is final once given: nothing later changes its request
            self.spool.writelines(spool_lines(self.name, records, self.settings, pairing.traffic.request_of))

    def _mark_lost(self, start_us: int) -> None:
        """The first request at or after a converter drop is one whose reply the PLC never
        got (as `analyse` marks it); every drop before this request started is known."""
        drops = self._drops
        while self._drops_applied < len(drops) and drops[self._drops_applied] <= start_us:
            self.pairing.traffic.exchanges[-1].lost_at_converter = True
            self._drops_applied += 1

    def _watch(self, settled: int) -> None:
        exchanges = self.pairing.traffic.exchanges
        for exchange in exchanges[self._given:settled]:
            for watch in self._watching:
                watch.exchange(exchange)
        self._given = max(self._given, settled)
