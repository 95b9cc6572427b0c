"""A monitoring session: chunks in, classified frames and the verifier's findings out.

The rules are `uitamr verify`'s own (`verifier.verify.rules.check_all` over a
`RunEvidence`); only the evidence differs: frames timed by the host instead of the
simulator, no PLC variables. `check` re-judges the whole capture and returns the findings
it has not returned before, so a live view can print each once; `result` is the final
judgement, in the shape every report of `uitamr verify` reads.
"""
from __future__ import annotations

from dataclasses import dataclass, field, replace

from verifier import protocol
from verifier.verify.evidence import RuleOptions, RunEvidence, Violation
from verifier.verify.result import ScenarioResult, TraceRecord
from verifier.verify.rules import check_all
from verifier.verify.traffic import analyse

from .capture import Chunk
from .classify import Classifier
from .framer import Framer, LineTiming

POWER_ON_RULE = "UITAMR-POWERON-STOP"


@dataclass
class CaptureInfo:
    """What the reports say about where the bytes came from."""

    name: str
    source: str  # "/dev/ttyUSB0", "tcp 192.168.0.50:4001", "capture.txt"
    channel: str = "rs485"  # rs485 / tcp / capture
    notes: list[str] = field(default_factory=list)


class MonitorSession:
    def __init__(self, info: CaptureInfo, settings: protocol.Settings = protocol.DEFAULT_SETTINGS,
                 options: RuleOptions = RuleOptions(), timing: LineTiming = LineTiming(),
                 from_power_on: bool = True):
        self.info = info
        self.settings = settings
        self.timing = timing
        self.options = replace(options, timing_tolerance_us=timing.tolerance_us, outputs_visible=False)
        self.from_power_on = from_power_on
        self.framer = Framer(timing)
        self.classifier = Classifier(settings, self.options.reply_timeout_us, timing.tolerance_us)
        self.chunks: list[Chunk] = []
        self.frames: list[TraceRecord] = []
        self._origin_us: int | None = None  # host time of the first byte: t = 0 in reports
        self._reported: set[tuple[str, int]] = set()
        self.last_us = 0

    # --- input ---------------------------------------------------------------------------
    def feed(self, chunk: Chunk) -> list[TraceRecord]:
        """Take the next chunk (host times in µs, any origin); the frames it completed."""
        if self._origin_us is None:
            self._origin_us = (chunk.t_start_us if chunk.t_start_us is not None
                               else chunk.t_us - self.timing.frame_us(len(chunk.data)))
        local = replace(chunk, t_us=chunk.t_us - self._origin_us,
                        t_start_us=None if chunk.t_start_us is None else chunk.t_start_us - self._origin_us)
        self.chunks.append(local)
        self.last_us = max(self.last_us, local.t_us)
        return self._take(self.framer.feed(local))

    def poll(self, host_us: int) -> list[TraceRecord]:
        """Frames ended by silence up to host time `host_us`."""
        if self._origin_us is None:
            return []
        now = host_us - self._origin_us
        self.last_us = max(self.last_us, now)
        return self._take(self.framer.poll(now))

    def close(self) -> list[TraceRecord]:
        return self._take(self.framer.flush())

    def _take(self, frames) -> list[TraceRecord]:
        records = []
        for frame in frames:
            direction = self.classifier.direction(frame)
            records.append(TraceRecord(frame.t_start_us, frame.t_end_us, direction, frame.data))
        self.frames += records
        return records

    # --- judgement -----------------------------------------------------------------------
    def violations(self, end_us: int | None = None) -> dict[str, list[Violation]]:
        end = self.last_us if end_us is None else end_us
        evidence = RunEvidence(self.settings, self.frames, end, (), options=self.options)
        found = check_all(evidence, analyse(self.frames, self.settings, self.options))
        if not self.from_power_on:
            found[POWER_ON_RULE] = []
        return found

    def check(self) -> list[Violation]:
        """Findings not returned by an earlier call, in time order."""
        new = []
        for violations in self.violations().values():
            for violation in violations:
                key = (violation.rule, violation.t_us)
                if key not in self._reported:
                    self._reported.add(key)
                    new.append(violation)
        return sorted(new, key=lambda v: (v.t_us, v.rule))

    def result(self) -> ScenarioResult:
        end = self.last_us
        notes = list(self.info.notes)
        notes.append(f"frames timed by the host; timing rules allow {self.timing.tolerance_us / 1000:g} ms "
                     "for the adapter's latency (--tolerance)")
        if not self.from_power_on:
            notes.append(f"the capture began after power-on: {POWER_ON_RULE} is not judged")
        if not self.frames:
            notes.append("no bytes were seen on the line")
        return ScenarioResult(
            name=self.info.name,
            file=self.info.source,
            description=f"traffic captured on {self.info.source}",
            program=None,
            platform="line",
            channel=self.info.channel,
            sources=[],
            duration_us=end,
            scan_us=0,
            seed=0,
            settings=self.settings,
            min_period_us=self.options.min_period_us,
            reply_timeout_us=self.options.reply_timeout_us,
            trace=list(self.frames),
            violations=self.violations(end),
            ended_us=end,
            notes=notes,
        )
